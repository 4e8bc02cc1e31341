//! Error measures between an observed and a predicted series, and the few
//! numerical helpers the scores need.

use serde::Serialize;

/// How far a prediction is from observations, over the same points.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ErrorMetrics {
    /// Number of points.
    pub points: usize,
    /// Root-mean-square error, √(Σ(p − o)²/n).
    pub rmse: f64,
    /// Coefficient of determination 1 − Σ(o − p)²/Σ(o − ō)², of the
    /// prediction p as a model of the observations o; `None` when the
    /// observations are constant (Σ(o − ō)² = 0), where it is undefined.
    pub r2: Option<f64>,
    /// Mean absolute error, Σ|p − o|/n.
    pub mae: f64,
    /// Largest |p − o|.
    pub max_abs_error: f64,
}

/// The metrics of `predicted` against `observed`; `None` for no points.
///
/// # Panics
/// If the two slices differ in length.
pub fn error_metrics(observed: &[f64], predicted: &[f64]) -> Option<ErrorMetrics> {
    assert_eq!(observed.len(), predicted.len(), "observed and predicted differ in length");
    let n = observed.len();
    if n == 0 {
        return None;
    }
    let nf = n as f64;
    let mean = observed.iter().sum::<f64>() / nf;
    let mut ss_res = 0.0;
    let mut ss_tot = 0.0;
    let mut abs_sum = 0.0;
    let mut abs_max: f64 = 0.0;
    for (&o, &p) in observed.iter().zip(predicted) {
        let d = p - o;
        ss_res += d * d;
        ss_tot += (o - mean) * (o - mean);
        abs_sum += d.abs();
        abs_max = abs_max.max(d.abs());
    }
    Some(ErrorMetrics {
        points: n,
        rmse: (ss_res / nf).sqrt(),
        r2: (ss_tot > 0.0).then(|| 1.0 - ss_res / ss_tot),
        mae: abs_sum / nf,
        max_abs_error: abs_max,
    })
}

/// Signed relative error (simulated − predicted)/predicted, as a fraction.
pub fn relative_error(simulated: f64, predicted: f64) -> f64 {
    (simulated - predicted) / predicted
}

/// Linear interpolation of the samples (xs ascending) at `x`; `None`
/// outside the sampled interval `xs[0]..=xs[last]`, where extrapolating would invent data.
pub fn interpolate(xs: &[f64], ys: &[f64], x: f64) -> Option<f64> {
    let (first, last) = (*xs.first()?, *xs.last()?);
    if !(x >= first && x <= last) {
        return None;
    }
    let i = xs.partition_point(|&v| v <= x);
    if i == 0 {
        return Some(ys[0]);
    }
    if i >= xs.len() {
        return Some(ys[xs.len() - 1]);
    }
    let (x0, x1, y0, y1) = (xs[i - 1], xs[i], ys[i - 1], ys[i]);
    if x1 == x0 {
        return Some(y0);
    }
    Some(y0 + (y1 - y0) * (x - x0) / (x1 - x0))
}

/// Area-weighted (cross-section) mean of a radial profile sampled at wall
/// distances `z` (ascending, in units of the length that makes `n_half` the
/// tube radius): ∫ε(r) r dr / ∫r dr over the sampled annulus, r = n_half − z,
/// by the trapezoidal rule. `None` for fewer than two samples or no area.
pub fn cross_section_mean(z: &[f64], eps: &[f64], n_half: f64) -> Option<f64> {
    if z.len() < 2 || z.len() != eps.len() {
        return None;
    }
    let mut num = 0.0;
    let mut den = 0.0;
    for i in 1..z.len() {
        let (r0, r1) = (n_half - z[i - 1], n_half - z[i]);
        // Trapezoid of ε·r and of r over [r1, r0] (r decreases as z grows).
        let dr = r0 - r1;
        num += 0.5 * (eps[i - 1] * r0 + eps[i] * r1) * dr;
        den += 0.5 * (r0 + r1) * dr;
    }
    (den > 0.0).then(|| num / den)
}

/// Cross-section mean of a function ε(z) over the whole tube, z from the
/// wall (0) to the axis (`n_half` = N/2 in dp), by Simpson's rule in r.
pub fn cross_section_mean_of(f: impl Fn(f64) -> f64, n_half: f64) -> f64 {
    // Even, and fine enough for the kinks of piecewise forms to cost < 1e-7.
    const STEPS: usize = 20_000;
    let h = n_half / STEPS as f64;
    let mut sum = 0.0;
    for i in 0..=STEPS {
        let r = i as f64 * h;
        let w = if i == 0 || i == STEPS {
            1.0
        } else if i % 2 == 1 {
            4.0
        } else {
            2.0
        };
        sum += w * f(n_half - r) * r;
    }
    // ∫ r dr over [0, R] = R²/2.
    (sum * h / 3.0) / (0.5 * n_half * n_half)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn metrics_of_a_hand_computed_case() {
        // errors p − o: +0.1, −0.2, +0.1, 0.0
        let o = [0.4, 0.5, 0.3, 0.4];
        let p = [0.5, 0.3, 0.4, 0.4];
        let m = error_metrics(&o, &p).unwrap();
        assert_eq!(m.points, 4);
        // Σd² = 0.01 + 0.04 + 0.01 = 0.06; /4 = 0.015
        assert!((m.rmse - 0.015f64.sqrt()).abs() < 1e-15);
        assert!((m.mae - 0.1).abs() < 1e-15);
        assert!((m.max_abs_error - 0.2).abs() < 1e-15);
        // ō = 0.4; Σ(o − ō)² = 0 + 0.01 + 0.01 + 0 = 0.02; r² = 1 − 0.06/0.02 = −2
        assert!((m.r2.unwrap() - -2.0).abs() < 1e-12);
    }

    #[test]
    fn perfect_prediction_and_constant_observations() {
        let m = error_metrics(&[0.1, 0.2, 0.3], &[0.1, 0.2, 0.3]).unwrap();
        assert_eq!((m.rmse, m.mae, m.max_abs_error, m.r2), (0.0, 0.0, 0.0, Some(1.0)));
        assert_eq!(error_metrics(&[0.4, 0.4], &[0.3, 0.5]).unwrap().r2, None);
        assert_eq!(error_metrics(&[], &[]), None);
    }

    #[test]
    fn relative_error_is_signed() {
        assert!((relative_error(0.44, 0.40) - 0.1).abs() < 1e-12);
        assert!((relative_error(0.36, 0.40) - -0.1).abs() < 1e-12);
    }

    #[test]
    fn interpolation_inside_and_outside() {
        let xs = [0.0, 1.0, 3.0];
        let ys = [1.0, 0.0, 1.0];
        assert_eq!(interpolate(&xs, &ys, 0.5), Some(0.5));
        assert_eq!(interpolate(&xs, &ys, 2.0), Some(0.5));
        assert_eq!(interpolate(&xs, &ys, 3.0), Some(1.0));
        assert_eq!(interpolate(&xs, &ys, 0.0), Some(1.0));
        assert_eq!(interpolate(&xs, &ys, 3.5), None);
        assert_eq!(interpolate(&xs, &ys, -0.1), None);
        assert_eq!(interpolate(&xs, &ys, f64::NAN), None);
    }

    #[test]
    fn cross_section_means_weight_by_radius() {
        // Constant profiles average to themselves.
        let z: Vec<f64> = (0..=50).map(|i| i as f64 * 0.1).collect();
        let eps = vec![0.4; z.len()];
        assert!((cross_section_mean(&z, &eps, 5.0).unwrap() - 0.4).abs() < 1e-12);
        // ε = 1 in the outer half-radius ring, 0 inside: area fraction 3/4.
        let f = |z: f64| if z < 1.0 { 1.0 } else { 0.0 };
        assert!((cross_section_mean_of(f, 2.0) - 0.75).abs() < 1e-3);
        // ε linear in r (ε = r/R): mean = ∫r² dr/∫r dr / R = 2/3.
        let g = |z: f64| (3.0 - z) / 3.0;
        assert!((cross_section_mean_of(g, 3.0) - 2.0 / 3.0).abs() < 1e-12);
        let zz: Vec<f64> = (0..=3000).map(|i| i as f64 * 0.001).collect();
        let ee: Vec<f64> = zz.iter().map(|&z| g(z)).collect();
        assert!((cross_section_mean(&zz, &ee, 3.0).unwrap() - 2.0 / 3.0).abs() < 1e-6);
    }
}
