//! The numbers the report states: maximum relative error, mean and spread
//! over seeds, the mean profile, least-squares trends. R² and RMSE come
//! from `pellet_refs::metrics::error_metrics`, the same as `compare`'s.

/// Mean and sample standard deviation (0 for one value); `None` for none.
pub fn mean_std(values: &[f64]) -> Option<(f64, f64)> {
    if values.is_empty() {
        return None;
    }
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let std = if values.len() > 1 {
        (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
    } else {
        0.0
    };
    Some((mean, std))
}

/// The paper's MRE: the *maximum* over beds of |simulated − predicted| /
/// predicted, as a fraction; `None` for no beds.
pub fn max_relative_error(pairs: &[(f64, f64)]) -> Option<f64> {
    pairs.iter().map(|(sim, pred)| ((sim - pred) / pred).abs()).reduce(f64::max)
}

/// Pointwise mean and standard deviation of profiles sampled on one grid.
/// Profiles whose length differs from the first are left out (a grid
/// mismatch would otherwise average unrelated radii); their count is returned.
pub fn mean_profile(profiles: &[&[f64]]) -> Option<(Vec<f64>, Vec<f64>, usize)> {
    let first = profiles.first()?;
    let same: Vec<&[f64]> = profiles.iter().copied().filter(|p| p.len() == first.len()).collect();
    let mut mean = Vec::with_capacity(first.len());
    let mut std = Vec::with_capacity(first.len());
    for i in 0..first.len() {
        let column: Vec<f64> = same.iter().map(|p| p[i]).collect();
        let (m, s) = mean_std(&column)?;
        mean.push(m);
        std.push(s);
    }
    Some((mean, std, profiles.len() - same.len()))
}

/// Least-squares slope of y against x; `None` with fewer than two distinct x.
pub fn slope(points: &[(f64, f64)]) -> Option<f64> {
    let n = points.len() as f64;
    let mx = points.iter().map(|p| p.0).sum::<f64>() / n;
    let my = points.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = points.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

#[cfg(test)]
mod tests {
    use super::*;
    use pellet_refs::metrics::error_metrics;

    #[test]
    fn mre_is_the_largest_absolute_relative_error() {
        // 0.44 vs 0.40: +10 %; 0.38 vs 0.40: −5 %; the maximum counts, not the mean.
        let mre = max_relative_error(&[(0.44, 0.40), (0.38, 0.40)]).unwrap();
        assert!((mre - 0.10).abs() < 1e-12, "{mre}");
        let mre = max_relative_error(&[(0.30, 0.40)]).unwrap();
        assert!((mre - 0.25).abs() < 1e-12, "{mre}");
        assert_eq!(max_relative_error(&[]), None);
    }

    #[test]
    fn rmse_and_r2_by_hand() {
        // o = 1, 2, 3; p = 1, 2, 4: SSres = 1, SStot = 2 → R² = 0.5; RMSE = √(1/3).
        let m = error_metrics(&[1.0, 2.0, 3.0], &[1.0, 2.0, 4.0]).unwrap();
        assert!((m.rmse - (1.0f64 / 3.0).sqrt()).abs() < 1e-12);
        assert!((m.r2.unwrap() - 0.5).abs() < 1e-12);
        let perfect = error_metrics(&[0.4, 0.5], &[0.4, 0.5]).unwrap();
        assert_eq!((perfect.rmse, perfect.r2), (0.0, Some(1.0)));
    }

    #[test]
    fn mean_std_mean_profile_and_slope() {
        let (m, s) = mean_std(&[0.40, 0.42, 0.44]).unwrap();
        assert!((m - 0.42).abs() < 1e-12 && (s - 0.02).abs() < 1e-12);
        assert_eq!(mean_std(&[0.5]), Some((0.5, 0.0)));
        let (a, b, c) = ([1.0, 0.4], [1.0, 0.6], [1.0, 0.5, 0.2]);
        let (mean, std, skipped) = mean_profile(&[&a, &b, &c]).unwrap();
        assert_eq!(skipped, 1);
        assert!((mean[1] - 0.5).abs() < 1e-12 && std[0] == 0.0);
        assert!((slope(&[(0.0, 1.0), (1.0, 3.0), (2.0, 5.0)]).unwrap() - 2.0).abs() < 1e-12);
        assert_eq!(slope(&[(1.0, 1.0), (1.0, 2.0)]), None);
    }
}
