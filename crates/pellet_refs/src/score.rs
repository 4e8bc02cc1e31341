//! [`Score`]: either kind of score, as `scores.json` lists them, and the
//! metrics gates can name.

use serde::Serialize;

use crate::scoring::{BulkScore, ProfileScore};

/// A score of either kind, as written to `scores.json`.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum Score {
    /// A profile against a radial correlation or experimental data.
    Profile(ProfileScore),
    /// Bulk porosity against a bulk correlation.
    Bulk(BulkScore),
}

impl Score {
    /// The reference's name.
    pub fn reference(&self) -> &str {
        match self {
            Score::Profile(s) => &s.reference,
            Score::Bulk(s) => &s.reference,
        }
    }

    /// Whether gates consider it: valid and not grade C.
    pub fn is_gated(&self) -> bool {
        match self {
            Score::Profile(s) => s.valid && s.gated,
            Score::Bulk(s) => s.valid && s.gated,
        }
    }

    /// A named metric: `rmse`, `mae`, `max_abs_error`, `r2` for profiles;
    /// `mre` and `relative_error` (its magnitude) for bulk scores.
    pub fn metric(&self, name: &str) -> Option<f64> {
        match (self, name) {
            (Score::Profile(s), "rmse") => Some(s.metrics.rmse),
            (Score::Profile(s), "mae") => Some(s.metrics.mae),
            (Score::Profile(s), "max_abs_error") => Some(s.metrics.max_abs_error),
            (Score::Profile(s), "r2") => s.metrics.r2,
            (Score::Bulk(s), "mre") => Some(s.mre),
            (Score::Bulk(s), "relative_error") => Some(s.relative_error.abs()),
            _ => None,
        }
    }
}

/// The metric names [`Score::metric`] knows.
pub const METRICS: &[&str] = &["rmse", "mae", "max_abs_error", "r2", "mre", "relative_error"];
