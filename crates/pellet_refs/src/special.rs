//! Special functions the correlations need.

/// The Bessel function of the first kind of order zero, J₀(x).
///
/// Computed from Bessel's integral J₀(x) = (1/π)∫₀^π cos(x sin θ) dθ with
/// the midpoint rule: the integrand is smooth and periodic, so the rule
/// converges exponentially once the number of nodes exceeds about |x|/2;
/// 256 nodes give full double precision for |x| ≲ 300, far beyond the
/// arguments of Mueller's profile (a·z < 30). A power series would lose
/// about |x|/ln 10 digits to cancellation at the same arguments.
pub fn bessel_j0(x: f64) -> f64 {
    const NODES: usize = 256;
    let h = std::f64::consts::PI / NODES as f64;
    (0..NODES).map(|k| (x * ((k as f64 + 0.5) * h).sin()).cos()).sum::<f64>() / NODES as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn j0_matches_tabulated_values() {
        // Abramowitz & Stegun table 9.1 and the first zeros of J0.
        assert_eq!(bessel_j0(0.0), 1.0);
        assert!((bessel_j0(1.0) - 0.765_197_686_557_966_6).abs() < 1e-14);
        assert!((bessel_j0(10.0) - -0.245_935_764_451_348_3).abs() < 1e-14);
        assert!(bessel_j0(2.404_825_557_695_773).abs() < 1e-14);
        assert!((bessel_j0(25.0) - 0.096_266_783_275_958_2).abs() < 1e-13);
    }
}
