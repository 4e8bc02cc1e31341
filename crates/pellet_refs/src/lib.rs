//! The literature's correlations for packed tubes, and the scores that
//! compare a simulated bed with them.
//!
//! Two families, each correlation a plain function with its citation,
//! grade, validity range and definition of N in its doc comment:
//!
//! - [`bulk`]: bulk (tube-average) porosity ε as a function of N = D/dp
//!   (spheres) or N = D/dpv (cylinders; dpv is the diameter of the sphere
//!   with the pellet's volume).
//! - [`radial`]: the radial void fraction ε(z) near the wall of a tube
//!   packed with spheres, z = (R − r)/dp.
//!
//! Grades say how sure the coefficients are: **A** confirmed by two
//! independent sources or an exact geometric limit; **B** one source or a
//! strong internal check; **C** recalled, plausible, unverified. Grade C
//! curves are drawn but never gated on ([`Grade::is_gated`]).
//!
//! [`registry`] finds a correlation by its canonical name or an alias
//! (`de-klerk` = `de-klerk-2003`), [`metrics`] holds the error measures and
//! [`scoring`] turns a profile and a bed's numbers into [`scoring::Score`]s.
//! Nothing here reads or writes files.
//!
//! ```
//! use pellet_refs::{bulk, radial};
//! // Dixon (1988), spheres, N = 5: 0.4265 (the reference value)
//! assert!((bulk::dixon_1988_spheres(5.0) - 0.42648).abs() < 1e-5);
//! // de Klerk (2003) at the wall is 1 whatever ε_b
//! assert_eq!(radial::de_klerk_2003(0.0, 0.39), 1.0);
//! ```
#![deny(missing_docs)]

pub mod bulk;
pub mod metrics;
pub mod radial;
pub mod registry;
mod score;
pub mod scoring;
mod special;

pub use registry::{resolve, Reference};
pub use special::bessel_j0;

use serde::Serialize;

/// The pellet shape a correlation was made for, or a bed is made of.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Shape {
    /// Spheres: dp = dpv.
    Sphere,
    /// Solid cylinders (the correlations assume equilateral ones, h = d).
    Cylinder,
    /// Raschig rings (hollow cylinders).
    Ring,
}

impl Shape {
    /// Parses `sphere`, `cylinder` or `ring` (plural forms accepted).
    pub fn parse(s: &str) -> Option<Shape> {
        match s.trim().to_ascii_lowercase().as_str() {
            "sphere" | "spheres" => Some(Shape::Sphere),
            "cylinder" | "cylinders" => Some(Shape::Cylinder),
            "ring" | "rings" | "raschig-ring" | "raschig_ring" => Some(Shape::Ring),
            _ => None,
        }
    }

    /// The lowercase name used in files and messages.
    pub fn name(self) -> &'static str {
        match self {
            Shape::Sphere => "sphere",
            Shape::Cylinder => "cylinder",
            Shape::Ring => "ring",
        }
    }
}

/// How sure the coefficients of a correlation are (see the crate doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Grade {
    /// Confirmed by two independent sources or an exact geometric limit.
    A,
    /// One source, or a strong internal check.
    B,
    /// Recalled, plausible, unverified: shown, never gated on.
    C,
}

impl Grade {
    /// Whether a `--fail-above` style gate may use scores against it.
    pub fn is_gated(self) -> bool {
        self != Grade::C
    }
}

/// Which pellet length makes N = D/length (and, for profiles, scales z).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum NDefinition {
    /// N = D/dp, dp the pellet's nominal diameter.
    DOverDp,
    /// N = D/dpv, dpv the diameter of the sphere with the pellet's volume.
    DOverDpv,
    /// N = D/dpv of the ring's envelope (the solid cylinder around it).
    DOverDpvEnvelope,
}

impl NDefinition {
    /// A short formula for reports.
    pub fn formula(self) -> &'static str {
        match self {
            NDefinition::DOverDp => "N = D/dp",
            NDefinition::DOverDpv => "N = D/dpv",
            NDefinition::DOverDpvEnvelope => "N = D/dpv(envelope cylinder)",
        }
    }
}

/// A closed interval of N (either end may be infinite).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Range {
    /// Smallest valid value.
    pub min: f64,
    /// Largest valid value.
    pub max: f64,
}

impl Range {
    /// Every N ≥ `min`.
    pub const fn from(min: f64) -> Range {
        Range { min, max: f64::INFINITY }
    }

    /// `min` ≤ N ≤ `max`.
    pub const fn between(min: f64, max: f64) -> Range {
        Range { min, max }
    }

    /// Whether `x` lies in the range.
    pub fn contains(&self, x: f64) -> bool {
        x >= self.min && x <= self.max
    }

    /// `a ≤ N ≤ b` or `N ≥ a`, for messages.
    pub fn describe(&self, var: &str) -> String {
        if self.max.is_infinite() {
            format!("{var} ≥ {}", self.min)
        } else {
            format!("{} ≤ {var} ≤ {}", self.min, self.max)
        }
    }
}

/// Errors of this crate.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum RefError {
    /// No correlation has this name or alias.
    #[error("unknown reference {name:?} (known: {known})")]
    UnknownReference {
        /// The name asked for.
        name: String,
        /// Every canonical name, comma-separated.
        known: String,
    },
    /// A computation needs a number that was not given.
    #[error("{reference} needs {what}")]
    Missing {
        /// The reference's name.
        reference: String,
        /// What is missing, e.g. "N = D/dp".
        what: String,
    },
}
