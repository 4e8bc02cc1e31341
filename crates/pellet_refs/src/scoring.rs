//! Scores: a simulated profile against a radial correlation or an
//! experimental profile, and beds' bulk porosity against a bulk
//! correlation. Pure functions; the `compare` tool reads the files and
//! writes the reports.
//!
//! Outside a correlation's validity range a score is still computed, but
//! `valid` is false and `notes` says why; gates must skip such scores, and
//! scores against grade C correlations (`gated` false).

use serde::Serialize;

use crate::bulk::{BulkCorrelation, Extras, Formula};
use crate::metrics::{cross_section_mean_of, error_metrics, interpolate, relative_error, ErrorMetrics};
use crate::radial::{EpsBSource, RadialCorrelation};
use crate::{Grade, NDefinition, RefError, Shape};

pub use crate::score::{Score, METRICS};

/// The pellet length that scales the wall distance z = (R − r)/length.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ZUnit {
    /// The nominal pellet diameter dp (the radial correlations' unit).
    Dp,
    /// The volume-equivalent sphere diameter dpv.
    Dpv,
}

impl ZUnit {
    /// `dp` or `dpv`.
    pub fn name(self) -> &'static str {
        match self {
            ZUnit::Dp => "dp",
            ZUnit::Dpv => "dpv",
        }
    }
}

/// A radial void-fraction profile: ε at wall distances z (ascending).
#[derive(Clone, Debug, PartialEq)]
pub struct Profile {
    /// Wall distance (R − r) in units of `z_unit`.
    pub z: Vec<f64>,
    /// Void fraction at each z.
    pub eps: Vec<f64>,
    /// What z is measured in.
    pub z_unit: ZUnit,
}

/// What is known of one bed (a voidprof summary, or flags).
#[derive(Clone, Debug, PartialEq)]
pub struct Bed {
    /// Where the numbers come from, for reports (a file name).
    pub source: String,
    /// Pellet shape.
    pub shape: Shape,
    /// Tube-average porosity of the simulated bed.
    pub bulk_porosity: Option<f64>,
    /// N = D/dp.
    pub n_dp: Option<f64>,
    /// N = D/dpv (for spheres equal to `n_dp`).
    pub n_dpv: Option<f64>,
    /// Rings: inner over outer diameter.
    pub ring_di_do: Option<f64>,
    /// Wadell sphericity φ (for spheres 1 when not given).
    pub sphericity: Option<f64>,
}

impl Bed {
    /// N as `definition` says, if known.
    pub fn n(&self, definition: NDefinition) -> Option<f64> {
        match definition {
            NDefinition::DOverDp => self.n_dp,
            NDefinition::DOverDpv => self.n_dpv.or(if self.shape == Shape::Sphere { self.n_dp } else { None }),
            // dpv³ scales with the solid volume: the envelope's is the ring's over (1 − (di/do)²).
            NDefinition::DOverDpvEnvelope => Some(self.n_dpv? * (1.0 - self.ring_di_do?.powi(2)).cbrt()),
        }
    }

    /// The pellet properties formulas need besides N.
    pub fn extras(&self) -> Extras {
        let sphere = if self.shape == Shape::Sphere { Some(1.0) } else { None };
        Extras { di_over_do: self.ring_di_do, sphericity: self.sphericity.or(sphere) }
    }

    /// N in the unit that scales a profile's z.
    pub fn n_for(&self, unit: ZUnit) -> Option<f64> {
        self.n(match unit {
            ZUnit::Dp => NDefinition::DOverDp,
            ZUnit::Dpv => NDefinition::DOverDpv,
        })
    }
}

/// Which ε_b to feed a radial correlation that takes one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum EpsBChoice {
    /// Fit ε_b so that the profile's cross-section mean equals this bulk
    /// porosity (the default: ε_b is the voidage far from the wall, not the
    /// tube average).
    Fitted {
        /// The bed's bulk porosity to match.
        bulk_porosity: f64,
    },
    /// Use this value as given.
    Given(f64),
}

/// The ε_b whose profile `corr(z; ε_b)` has `bulk_porosity` as its mean
/// over the whole cross-section of a tube of N = `n` (z in dp, the axis at
/// z = N/2). The forms are affine in ε_b, so two evaluations solve it;
/// `None` when ε_b has no effect (N so small the wall zone fills the tube).
pub fn fit_eps_b(corr: &RadialCorrelation, n: f64, bulk_porosity: f64) -> Option<f64> {
    let mean = |eps_b: f64| cross_section_mean_of(|z| (corr.eval)(z, n, eps_b), n / 2.0);
    let (m0, m1) = (mean(0.0), mean(1.0));
    let slope = m1 - m0;
    (slope.abs() > 1e-9).then(|| (bulk_porosity - m0) / slope)
}

/// How a profile scored against one reference.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ProfileScore {
    /// Canonical name, or `exp:FILE` for experimental data.
    pub reference: String,
    /// Label for plots.
    pub label: String,
    /// Citation (empty for experimental data).
    pub citation: String,
    /// Grade; `None` for experimental data.
    pub grade: Option<Grade>,
    /// Whether gates use this score (not grade C).
    pub gated: bool,
    /// False when the bed lies outside the reference's validity range.
    pub valid: bool,
    /// Why it is not valid, and other caveats.
    pub notes: Vec<String>,
    /// What z is measured in.
    pub z_unit: ZUnit,
    /// Smallest z scored.
    pub z_min: f64,
    /// Largest z scored.
    pub z_max: f64,
    /// The error measures (reference as prediction of the simulation, or
    /// simulation as prediction of the experiment).
    #[serde(flatten)]
    pub metrics: ErrorMetrics,
    /// The ε_b used, if the reference takes one.
    pub eps_b: Option<f64>,
    /// `fitted`, `given` or `own` (the correlation's ε_b(N)).
    pub eps_b_method: Option<String>,
    /// N used (in the z unit), if known.
    #[serde(rename = "N")]
    pub n: Option<f64>,
}

/// A radial correlation evaluated for one bed.
#[derive(Clone, Debug, PartialEq)]
pub struct RadialCurve {
    /// ε at each z asked for.
    pub eps: Vec<f64>,
    /// The ε_b used.
    pub eps_b: Option<f64>,
    /// How ε_b was chosen: `fitted`, `given` or `own`.
    pub eps_b_method: Option<&'static str>,
}

/// Evaluates `corr` at z for the given N and ε_b choice.
pub fn radial_curve(
    corr: &RadialCorrelation,
    z: &[f64],
    n: Option<f64>,
    eps_b: EpsBChoice,
) -> Result<RadialCurve, RefError> {
    let missing = |what: &str| RefError::Missing { reference: corr.name.into(), what: what.into() };
    let (eps_b_used, method, n_used) = match (corr.eps_b, eps_b) {
        (EpsBSource::OwnFromN, _) => {
            let n = n.ok_or_else(|| missing("N (give the tube and pellet diameters, or a summary)"))?;
            (Some(crate::radial::mueller_1992_eps_b(n)), Some("own"), n)
        }
        (EpsBSource::Parameter, EpsBChoice::Given(v)) => (Some(v), Some("given"), n.unwrap_or(f64::NAN)),
        (EpsBSource::Parameter, EpsBChoice::Fitted { bulk_porosity }) => {
            let n =
                n.ok_or_else(|| missing("N to fit ε_b (give the tube and pellet diameters, or use a given ε_b)"))?;
            let fitted = fit_eps_b(corr, n, bulk_porosity)
                .ok_or_else(|| missing("a tube wide enough to fit ε_b (use a given ε_b)"))?;
            (Some(fitted), Some("fitted"), n)
        }
    };
    let eps = z.iter().map(|&zi| (corr.eval)(zi, n_used, eps_b_used.unwrap_or(f64::NAN))).collect();
    Ok(RadialCurve { eps, eps_b: eps_b_used, eps_b_method: method })
}

/// Scores a simulated profile against a radial correlation.
///
/// Points with z < 0 or beyond the axis (z > N/2, when N is known) are not
/// scored. Returns `Ok(None)` when no point remains.
pub fn score_radial(
    corr: &RadialCorrelation,
    profile: &Profile,
    bed: &Bed,
    eps_b: EpsBChoice,
) -> Result<Option<ProfileScore>, RefError> {
    let n = bed.n_for(profile.z_unit);
    let z_end = n.map_or(f64::INFINITY, |n| n / 2.0);
    let (z, eps): (Vec<f64>, Vec<f64>) =
        profile.z.iter().zip(&profile.eps).filter(|(z, _)| **z >= 0.0 && **z <= z_end).map(|(z, e)| (*z, *e)).unzip();
    let curve = radial_curve(corr, &z, n, eps_b)?;
    let Some(metrics) = error_metrics(&eps, &curve.eps) else { return Ok(None) };
    let mut notes = Vec::new();
    let mut valid = true;
    if bed.shape != Shape::Sphere {
        valid = false;
        notes.push(format!("correlation for spheres; the bed is of {}s", bed.shape.name()));
    }
    if profile.z_unit != ZUnit::Dp {
        notes.push("z scaled by dpv, while the correlation is defined with dp".into());
    }
    match n {
        Some(n) if !corr.n_range.contains(n) => {
            valid = false;
            notes.push(format!("N = {n:.3} outside {}", corr.n_range.describe("N")));
        }
        None if corr.n_range.min > 1.0 => {
            valid = false;
            notes.push(format!("N unknown; valid for {}", corr.n_range.describe("N")));
        }
        _ => {}
    }
    if corr.grade == Grade::C {
        notes.push("grade C (unverified coefficients): shown, not gated".into());
    }
    Ok(Some(ProfileScore {
        reference: corr.name.into(),
        label: corr.label.into(),
        citation: corr.citation.into(),
        grade: Some(corr.grade),
        gated: corr.grade.is_gated(),
        valid,
        notes,
        z_unit: profile.z_unit,
        z_min: z[0],
        z_max: z[z.len() - 1],
        metrics,
        eps_b: curve.eps_b,
        eps_b_method: curve.eps_b_method.map(String::from),
        n,
    }))
}

/// Scores a simulated profile as a prediction of experimental points
/// (`exp_z` in the profile's unit), interpolating the simulation at the
/// data's abscissae. Points outside the simulated range are not scored
/// (noted). `Ok(None)` when no point lies inside.
pub fn score_experimental(name: &str, sim: &Profile, exp_z: &[f64], exp_eps: &[f64]) -> Option<ProfileScore> {
    let mut z = Vec::new();
    let mut observed = Vec::new();
    let mut predicted = Vec::new();
    for (&zi, &ei) in exp_z.iter().zip(exp_eps) {
        if let Some(s) = interpolate(&sim.z, &sim.eps, zi) {
            z.push(zi);
            observed.push(ei);
            predicted.push(s);
        }
    }
    let metrics = error_metrics(&observed, &predicted)?;
    let mut notes = Vec::new();
    let outside = exp_z.len() - z.len();
    if outside > 0 {
        notes.push(format!("{outside} of {} data points outside the simulated range, not scored", exp_z.len()));
    }
    Some(ProfileScore {
        reference: format!("exp:{name}"),
        label: format!("experiment {name}"),
        citation: String::new(),
        grade: None,
        gated: true,
        valid: true,
        notes,
        z_unit: sim.z_unit,
        z_min: z.iter().copied().fold(f64::INFINITY, f64::min),
        z_max: z.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        metrics,
        eps_b: None,
        eps_b_method: None,
        n: None,
    })
}

/// One bed scored against a bulk correlation.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BulkBedScore {
    /// The bed's source (file name).
    pub source: String,
    /// N as the correlation defines it.
    #[serde(rename = "N")]
    pub n: f64,
    /// The bed's bulk porosity.
    pub simulated: f64,
    /// The correlation's value.
    pub predicted: f64,
    /// (simulated − predicted)/predicted, signed fraction.
    pub relative_error: f64,
    /// False outside the validity range, or for another shape.
    pub valid: bool,
}

/// Beds' bulk porosity against one bulk correlation.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BulkScore {
    /// Canonical name.
    pub reference: String,
    /// Label for plots.
    pub label: String,
    /// Citation.
    pub citation: String,
    /// Grade.
    pub grade: Grade,
    /// Whether gates use this score (not grade C).
    pub gated: bool,
    /// How its N is defined.
    pub n_definition: &'static str,
    /// False when no bed lies inside the validity range (then the numbers
    /// below are over all beds).
    pub valid: bool,
    /// Caveats and why beds are out of range.
    pub notes: Vec<String>,
    /// The worst bed's (largest |relative error|, among valid beds if any)
    /// bulk porosity.
    pub simulated: f64,
    /// The correlation's value for that bed.
    pub predicted: f64,
    /// That bed's signed relative error.
    pub relative_error: f64,
    /// Maximum relative error: max |relative error| over the valid beds
    /// (over all if none is valid).
    pub mre: f64,
    /// Every bed.
    pub beds: Vec<BulkBedScore>,
}

/// Scores the beds' bulk porosity against `corr`. Every bed needs its bulk
/// porosity and the N the correlation uses (rings: also di/do).
pub fn score_bulk(corr: &BulkCorrelation, beds: &[Bed]) -> Result<BulkScore, RefError> {
    let missing = |what: String| RefError::Missing { reference: corr.name.into(), what };
    let mut notes = Vec::new();
    let mut scored = Vec::new();
    for bed in beds {
        let simulated = bed.bulk_porosity.ok_or_else(|| missing(format!("the bulk porosity of {}", bed.source)))?;
        let n = bed
            .n(corr.n_definition)
            .ok_or_else(|| missing(format!("{} for {} ({})", corr.n_definition.formula(), bed.source, needs(corr))))?;
        let extras = bed.extras();
        let predicted = corr.predict(n, &extras).ok_or_else(|| {
            missing(match corr.formula {
                Formula::Sphericity => format!("the sphericity φ of the pellets in {}", bed.source),
                _ => format!("di/do of the rings in {}", bed.source),
            })
        })?;
        let mut valid = true;
        if bed.shape != corr.shape {
            valid = false;
            notes.push(format!("{}: correlation for {}s, bed of {}s", bed.source, corr.shape.name(), bed.shape.name()));
        }
        if !corr.n_range.contains(n) {
            valid = false;
            notes.push(format!("{}: N = {n:.3} outside {}", bed.source, corr.n_range.describe("N")));
        }
        if let (Formula::Sphericity, Some(phi)) = (&corr.formula, extras.sphericity) {
            if !(phi > 0.42 && phi < 1.0) {
                valid = false;
                notes.push(format!("{}: φ = {phi:.3} outside 0.42 < φ < 1", bed.source));
            }
        }
        scored.push(BulkBedScore {
            source: bed.source.clone(),
            n,
            simulated,
            predicted,
            relative_error: relative_error(simulated, predicted),
            valid,
        });
    }
    let any_valid = scored.iter().any(|b| b.valid);
    let worst = scored
        .iter()
        .filter(|b| b.valid || !any_valid)
        .max_by(|a, b| a.relative_error.abs().total_cmp(&b.relative_error.abs()))
        .ok_or_else(|| missing("at least one bed".into()))?
        .clone();
    if corr.grade == Grade::C {
        notes.push("grade C (unverified): shown, not gated".into());
    }
    if !corr.note.is_empty() {
        notes.push(corr.note.into());
    }
    Ok(BulkScore {
        reference: corr.name.into(),
        label: corr.label.into(),
        citation: corr.citation.into(),
        grade: corr.grade,
        gated: corr.grade.is_gated(),
        n_definition: corr.n_definition.formula(),
        valid: any_valid,
        notes,
        simulated: worst.simulated,
        predicted: worst.predicted,
        relative_error: worst.relative_error,
        mre: worst.relative_error.abs(),
        beds: scored,
    })
}

fn needs(corr: &BulkCorrelation) -> &'static str {
    match corr.n_definition {
        NDefinition::DOverDp => "give the tube and pellet diameters",
        NDefinition::DOverDpv => "give N_dpv in the summary, or dpv",
        NDefinition::DOverDpvEnvelope => "give N_dpv and the rings' di/do",
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::radial::RADIAL;

    fn radial(name: &str) -> &'static RadialCorrelation {
        RADIAL.iter().find(|c| c.name == name).unwrap()
    }

    #[test]
    fn fitted_eps_b_reproduces_the_bulk_porosity() {
        for name in ["de-klerk-2003", "cohen-metzner-1981", "martin-1978", "bey-eigenberger-1997"] {
            let c = radial(name);
            let eps_b = fit_eps_b(c, 8.0, 0.42).unwrap();
            let mean = cross_section_mean_of(|z| (c.eval)(z, 8.0, eps_b), 4.0);
            assert!((mean - 0.42).abs() < 1e-9, "{name}: {mean}");
            // The wall zone is looser than the core, so ε_b < tube average.
            assert!(eps_b < 0.42, "{name}: {eps_b}");
        }
    }

    #[test]
    fn a_profile_equal_to_the_correlation_scores_perfectly() {
        let c = radial("de-klerk-2003");
        let z: Vec<f64> = (0..=300).map(|i| i as f64 * 0.01).collect();
        let eps = z.iter().map(|&z| crate::radial::de_klerk_2003(z, 0.38)).collect();
        let profile = Profile { z, eps, z_unit: ZUnit::Dp };
        let bed = Bed {
            source: "t".into(),
            shape: Shape::Sphere,
            bulk_porosity: None,
            n_dp: Some(8.0),
            n_dpv: None,
            ring_di_do: None,
            sphericity: None,
        };
        let s = score_radial(c, &profile, &bed, EpsBChoice::Given(0.38)).unwrap().unwrap();
        assert_eq!((s.metrics.rmse, s.metrics.max_abs_error, s.valid), (0.0, 0.0, true));
        assert_eq!((s.z_min, s.z_max, s.metrics.points), (0.0, 3.0, 301));
        let cyl = Bed { shape: Shape::Cylinder, ..bed };
        let s = score_radial(c, &profile, &cyl, EpsBChoice::Given(0.38)).unwrap().unwrap();
        assert!(!s.valid && s.notes[0].contains("spheres"), "{:?}", s.notes);
    }

    #[test]
    fn bulk_scores_flag_beds_out_of_range_and_take_the_worst_valid_one() {
        let foumeny = crate::bulk::BULK.iter().find(|c| c.name == "foumeny-1993").unwrap();
        let bed = |source: &str, n: f64, eps: f64| Bed {
            source: source.into(),
            shape: Shape::Sphere,
            bulk_porosity: Some(eps),
            n_dp: Some(n),
            n_dpv: None,
            ring_di_do: None,
            sphericity: None,
        };
        let p5 = crate::bulk::foumeny_1993_spheres(5.0);
        let p10 = crate::bulk::foumeny_1993_spheres(10.0);
        let beds = [bed("a", 5.0, p5 * 1.02), bed("b", 10.0, p10 * 0.95), bed("c", 30.0, 0.9)];
        let s = score_bulk(foumeny, &beds).unwrap();
        assert!(s.valid);
        assert!(!s.beds[2].valid && s.notes.iter().any(|n| n.contains("c: N = 30")), "{:?}", s.notes);
        assert!((s.mre - 0.05).abs() < 1e-12 && (s.relative_error + 0.05).abs() < 1e-12);
        assert_eq!(s.predicted, p10);
    }
}
