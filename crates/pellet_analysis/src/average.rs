//! The mean profile of repeated beds and its spread (the paper averages triplicates).

use pellet_geom::math::Real;

use crate::profile::VoidProfile;
use crate::AnalysisError;

/// Point-wise statistics of several radial profiles on the same grid.
#[derive(Clone, Debug, PartialEq)]
pub struct ProfileStats {
    /// Tube radius R (m).
    pub tube_radius: Real,
    /// Radii (m), ascending.
    pub radius: Vec<Real>,
    /// Mean ε(r).
    pub mean: Vec<Real>,
    /// Sample standard deviation of ε(r) (0 for a single profile).
    pub std: Vec<Real>,
    /// Smallest ε(r) among the profiles.
    pub min: Vec<Real>,
    /// Largest ε(r) among the profiles.
    pub max: Vec<Real>,
    /// Number of profiles.
    pub count: usize,
}

/// Mean, standard deviation and range of `profiles`, which must share the
/// tube and the radial grid.
pub fn average_profiles(profiles: &[VoidProfile]) -> Result<ProfileStats, AnalysisError> {
    let first = profiles.first().ok_or_else(|| AnalysisError::Mismatch("no profiles".into()))?;
    for (k, p) in profiles.iter().enumerate().skip(1) {
        let same = p.radius.len() == first.radius.len()
            && p.radius.iter().zip(&first.radius).all(|(a, b)| (a - b).abs() <= 1e-9 * first.tube_radius);
        if !same || (p.tube_radius - first.tube_radius).abs() > 1e-9 * first.tube_radius {
            return Err(AnalysisError::Mismatch(format!(
                "bed {} has tube diameter {} mm and {} radii, bed 1 has {} mm and {} radii; \
                 average beds of the same tube and pellet",
                k + 1,
                2e3 * p.tube_radius,
                p.radius.len(),
                2e3 * first.tube_radius,
                first.radius.len()
            )));
        }
    }
    let n = profiles.len() as Real;
    let m = first.radius.len();
    let column = |i: usize| profiles.iter().map(move |p| p.void_fraction[i]);
    let mean: Vec<Real> = (0..m).map(|i| column(i).sum::<Real>() / n).collect();
    let std = (0..m)
        .map(|i| {
            if profiles.len() < 2 {
                return 0.0;
            }
            (column(i).map(|v| (v - mean[i]).powi(2)).sum::<Real>() / (n - 1.0)).sqrt()
        })
        .collect();
    Ok(ProfileStats {
        tube_radius: first.tube_radius,
        radius: first.radius.clone(),
        mean,
        std,
        min: (0..m).map(|i| column(i).fold(Real::INFINITY, Real::min)).collect(),
        max: (0..m).map(|i| column(i).fold(Real::NEG_INFINITY, Real::max)).collect(),
        count: profiles.len(),
    })
}
