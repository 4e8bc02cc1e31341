//! packbed's plots, rendered without any system library: PNG or SVG chosen
//! by the file extension, text drawn with the embedded DejaVu Sans font
//! (plotters' `ab_glyph` backend), so a bare machine renders them.
//!
//! Two charts:
//! - [`plot_profile`]: radial void fraction ε against the wall distance
//!   z = (R − r)/dp: simulated series (with an optional ± spread band, for
//!   the mean of several packings) and reference curves (correlations,
//!   experimental points). Its [`ProfileFrame`] marks the tube wall and the
//!   tube axis on the x axis and adds caption lines under the chart (the
//!   axial window the profile was averaged over, how many beds it is).
//! - [`plot_porosity_vs_n`]: bulk porosity against N with correlation
//!   curves and simulated beds as points.
//!
//! ```no_run
//! use pellet_plot::{plot_profile, window_note, CurveStyle, ProfileFrame, ProfileSeries, RefCurve};
//! let sim = ProfileSeries::new("simulated", vec![0.0, 0.5, 1.0, 3.0], vec![1.0, 0.25, 0.5, 0.4]);
//! let dk = RefCurve::new("de Klerk (2003)", vec![(0.0, 1.0), (0.5, 0.27), (1.0, 0.6)], CurveStyle::Solid);
//! // N = D/dp = 6: the axis lies at (R − r)/dp = 3.
//! let frame = ProfileFrame::wall_distance(Some(3.0)).with_note(window_note(0.0, 100.0));
//! plot_profile("profile.png".as_ref(), "N = 6 spheres", &frame, &[sim], &[dk]).unwrap();
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

/// What a radial profile chart shows besides its data: where the tube wall
/// and the tube axis lie on its x axis, and caption lines under the chart.
///
/// The wall is drawn as a solid vertical line labelled `wall (r = R)`, the
/// axis as a dashed one labelled `axis (r = 0)`. An axis that is not known,
/// or lies far beyond the data, is named at the far end of the x axis with
/// an arrow pointing toward it.
#[derive(Clone, Debug, PartialEq)]
pub struct ProfileFrame {
    /// x of the tube wall (r = R), in the x axis's unit.
    pub wall: f64,
    /// x of the tube axis (r = 0), if known.
    pub axis: Option<f64>,
    /// Caption lines under the chart, e.g. [`window_note`], [`single_bed_note`].
    pub notes: Vec<String>,
}

impl ProfileFrame {
    /// The frame of x = (R − r)/L for a length L (dp, dpv, or 1 mm): the wall
    /// at x = 0 and the axis at x = R/L = N/2 (`None` when R is not known).
    pub fn wall_distance(axis: Option<f64>) -> ProfileFrame {
        ProfileFrame { wall: 0.0, axis: axis.filter(|a| a.is_finite() && *a > 0.0), notes: Vec::new() }
    }

    /// The same frame with one more caption line.
    pub fn with_note(mut self, note: impl Into<String>) -> ProfileFrame {
        self.notes.push(note.into());
        self
    }
}

/// A length in mm for a caption: at most two decimals, trailing zeros dropped (`25`, `29.12`).
pub fn format_mm(value_mm: f64) -> String {
    let text = format!("{value_mm:.2}");
    let text = text.trim_end_matches('0').trim_end_matches('.');
    if text == "-0" {
        "0".into()
    } else {
        text.into()
    }
}

/// The caption line naming the axial window a profile was averaged over
/// (heights above the floor, mm): `ε averaged over the axial window z = 0–25 mm`.
pub fn window_note(z0_mm: f64, z1_mm: f64) -> String {
    format!("ε averaged over the axial window z = {}–{} mm", format_mm(z0_mm), format_mm(z1_mm))
}

/// The caption line of a profile of one bed: one packing is a single sample
/// of the random packing process, and no spread over seeds is shown.
/// `bed` names it (a file, a seed), or is empty.
pub fn single_bed_note(bed: &str) -> String {
    let which = if bed.is_empty() { String::new() } else { format!(" ({bed})") };
    format!("one bed{which}: a single sample; beds packed with another seed differ, and their spread is not shown")
}

/// The caption line of a mean over `count` beds drawn with its spread band;
/// `what` names them in the plural (`beds`, `seeds`).
pub fn spread_note(count: usize, what: &str) -> String {
    format!("mean of {count} {what}; the band is ± 1 standard deviation over them")
}

/// Draws a radial void-fraction profile chart to `path` (`.png` or `.svg`):
/// x = (R − r)/dp, y = ε, with the wall, the axis and the caption lines of
/// `frame`. The file is written atomically.
pub fn plot_profile(
    path: &Path,
    title: &str,
    frame: &ProfileFrame,
    series: &[ProfileSeries],
    references: &[RefCurve],
) -> Result<(), PlotError> {
    plot_profile_with_x_label(path, title, "(R − r)/dp", frame, series, references)
}

/// Like [`plot_profile`] with another x label, e.g. `(R − r)/dpv`.
pub fn plot_profile_with_x_label(
    path: &Path,
    title: &str,
    x_label: &str,
    frame: &ProfileFrame,
    series: &[ProfileSeries],
    references: &[RefCurve],
) -> Result<(), PlotError> {
    Chart { title, x_label, y_label: "void fraction ε", series, references, frame: Some(frame) }.render(path)
}

/// Draws bulk porosity against N to `path` (`.png` or `.svg`): correlation
/// curves and the simulated beds (use [`CurveStyle::Markers`] for them).
pub fn plot_porosity_vs_n(path: &Path, title: &str, x_label: &str, curves: &[RefCurve]) -> Result<(), PlotError> {
    Chart { title, x_label, y_label: "bulk porosity ε", series: &[], references: curves, frame: None }.render(path)
}
