//! packbed's plots, rendered without any system library: PNG or SVG chosen
//! by the file extension, text drawn with the embedded DejaVu Sans font
//! (plotters' `ab_glyph` backend), so a bare machine renders them.
//!
//! Two charts:
//! - [`plot_profile`]: radial void fraction ε against the wall distance
//!   z = (R − r)/dp: simulated series (with an optional ± spread band, for
//!   the mean of several packings) and reference curves (correlations,
//!   experimental points).
//! - [`plot_porosity_vs_n`]: bulk porosity against N with correlation
//!   curves and simulated beds as points.
//!
//! ```no_run
//! use pellet_plot::{plot_profile, CurveStyle, ProfileSeries, RefCurve};
//! let sim = ProfileSeries::new("simulated", vec![0.0, 0.5, 1.0], vec![1.0, 0.25, 0.5]);
//! let dk = RefCurve::new("de Klerk (2003)", vec![(0.0, 1.0), (0.5, 0.27), (1.0, 0.6)], CurveStyle::Solid);
//! plot_profile("profile.png".as_ref(), "N = 6 spheres", &[sim], &[dk]).unwrap();
//! ```
#![deny(missing_docs)]

mod chart;

use std::path::Path;

pub use chart::{Chart, ImageFormat};

/// A simulated profile: ε at wall distances z, and optionally a spread
/// (e.g. the standard deviation over several packings) drawn as a band.
#[derive(Clone, Debug, PartialEq)]
pub struct ProfileSeries {
    /// Legend label.
    pub label: String,
    /// Abscissae (ascending).
    pub x: Vec<f64>,
    /// Values.
    pub y: Vec<f64>,
    /// Half-width of the band around `y`, one per point.
    pub spread: Option<Vec<f64>>,
}

impl ProfileSeries {
    /// A series without spread.
    pub fn new(label: impl Into<String>, x: Vec<f64>, y: Vec<f64>) -> ProfileSeries {
        ProfileSeries { label: label.into(), x, y, spread: None }
    }

    /// The same series with a ± spread band.
    pub fn with_spread(mut self, spread: Vec<f64>) -> ProfileSeries {
        self.spread = Some(spread);
        self
    }
}

/// How a reference curve is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CurveStyle {
    /// A solid line (verified correlations).
    Solid,
    /// A dashed line (unverified, grade C correlations).
    Dashed,
    /// Markers only (experimental data, simulated beds).
    Markers,
}

/// A reference drawn over the simulated data.
#[derive(Clone, Debug, PartialEq)]
pub struct RefCurve {
    /// Legend label.
    pub label: String,
    /// Points (x, y).
    pub points: Vec<(f64, f64)>,
    /// Line or markers.
    pub style: CurveStyle,
    /// An explicit colour (r, g, b); `None` takes the next palette colour.
    pub color: Option<(u8, u8, u8)>,
}

impl RefCurve {
    /// A curve.
    pub fn new(label: impl Into<String>, points: Vec<(f64, f64)>, style: CurveStyle) -> RefCurve {
        RefCurve { label: label.into(), points, style, color: None }
    }

    /// The same curve in an explicit colour (e.g. black for simulated points).
    pub fn with_color(mut self, rgb: (u8, u8, u8)) -> RefCurve {
        self.color = Some(rgb);
        self
    }
}

/// What can go wrong drawing a plot.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// The extension is neither `.png` nor `.svg`.
    #[error("{path}: unknown image type; use a .png or .svg file name")]
    UnknownFormat {
        /// The path given.
        path: String,
    },
    /// Nothing to plot.
    #[error("{path}: nothing to plot (no finite points)")]
    Empty {
        /// The path given.
        path: String,
    },
    /// The drawing backend failed (e.g. the file cannot be written).
    #[error("{path}: drawing failed: {reason}")]
    Draw {
        /// The path given.
        path: String,
        /// The backend's message.
        reason: String,
    },
}

/// Draws a radial void-fraction profile chart to `path` (`.png` or `.svg`):
/// x = (R − r)/dp, y = ε. The file is written atomically.
pub fn plot_profile(
    path: &Path,
    title: &str,
    series: &[ProfileSeries],
    references: &[RefCurve],
) -> Result<(), PlotError> {
    let chart = Chart { title, x_label: "(R − r)/dp", y_label: "void fraction ε", series, references };
    chart.render(path)
}

/// Like [`plot_profile`] with another x label, e.g. `(R − r)/dpv`.
pub fn plot_profile_with_x_label(
    path: &Path,
    title: &str,
    x_label: &str,
    series: &[ProfileSeries],
    references: &[RefCurve],
) -> Result<(), PlotError> {
    Chart { title, x_label, y_label: "void fraction ε", series, references }.render(path)
}

/// Draws bulk porosity against N to `path` (`.png` or `.svg`): correlation
/// curves and the simulated beds (use [`CurveStyle::Markers`] for them).
pub fn plot_porosity_vs_n(path: &Path, title: &str, x_label: &str, curves: &[RefCurve]) -> Result<(), PlotError> {
    Chart { title, x_label, y_label: "bulk porosity ε", series: &[], references: curves }.render(path)
}
