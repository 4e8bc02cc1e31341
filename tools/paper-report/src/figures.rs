//! The report's PNG figures, drawn with pellet_plot (embedded font, written
//! atomically). Each function returns the file name it wrote, or `None`
//! when there is nothing to draw yet.

use std::path::Path;

use anyhow::Result;
use pellet_plot::{
    format_mm, plot_porosity_vs_n, plot_profile_with_x_label, single_bed_note, spread_note, window_note, Chart,
    CurveStyle, ProfileFrame, ProfileSeries, RefCurve,
};
use pellet_refs::bulk::{Formula, BULK};
use pellet_refs::scoring::ZUnit;
use pellet_refs::{Grade, Shape};

use crate::analysis::{dixon, ProfileResult, StudySeries, TubeResult};

const BLACK: (u8, u8, u8) = (0, 0, 0);
const GREY: (u8, u8, u8) = (150, 150, 150);

/// Bulk porosity against N for one shape (the paper's Fig. 14): every
/// bulk correlation for the shape over N = 2.5–10, seeds and means.
pub fn porosity_vs_n(dir: &Path, shape: Shape, tubes: &[TubeResult]) -> Result<Option<String>> {
    if tubes.is_empty() {
        return Ok(None);
    }
    // Spheres: N = D/dp; cylinders and rings: N = D/dpv, as Dixon defines it.
    let n_of = |t: &TubeResult| if shape == Shape::Sphere { t.n } else { t.n_dpv };
    let grid: Vec<f64> = (0..=150).map(|i| 2.5 + 7.5 * i as f64 / 150.0).collect();
    let mut curves = Vec::new();
    for c in BULK.iter().filter(|c| c.shape == shape) {
        let Formula::OfN(f) = c.formula else { continue };
        let pts: Vec<(f64, f64)> = grid.iter().filter(|n| c.n_range.contains(**n)).map(|&n| (n, f(n))).collect();
        if pts.len() > 1 {
            let style = if c.grade == Grade::C { CurveStyle::Dashed } else { CurveStyle::Solid };
            curves.push(RefCurve::new(c.label, pts, style));
        }
    }
    if shape == Shape::Ring {
        // The ring estimate as a function of N = D/dpv of the ring (see analysis::dixon).
        let pts = grid.iter().map(|&n| (n, dixon(Shape::Ring, n, n))).collect();
        curves.push(RefCurve::new("ring envelope + Dixon (ours, grade C)", pts, CurveStyle::Dashed));
    }
    let seeds: Vec<(f64, f64)> =
        tubes.iter().flat_map(|t| t.porosity_seeds.iter().map(move |p| (n_of(t), *p))).collect();
    curves.push(RefCurve::new("simulated, each seed", seeds, CurveStyle::Markers).with_color(GREY));
    let means = tubes.iter().map(|t| (n_of(t), t.porosity_mean)).collect();
    curves.push(RefCurve::new("simulated, mean", means, CurveStyle::Markers).with_color(BLACK));
    let name = format!("porosity_vs_n_{}.png", shape.name());
    let x = if shape == Shape::Sphere { "N = D/dp" } else { "N = D/dpv" };
    plot_porosity_vs_n(&dir.join(&name), &format!("Bulk porosity, {}s (window 0–100 mm)", shape.name()), x, &curves)?;
    Ok(Some(name))
}

/// The profile plot's wall (x = 0), axis (x = N/2 in the wall unit) and caption: the axial
/// window and over how many seeds the spread is.
pub fn profile_frame(p: &ProfileResult) -> ProfileFrame {
    let n = if p.z_unit == ZUnit::Dp { p.n } else { p.n_dpv };
    let window = match p.windows_mm.as_slice() {
        [] => "axial window not known (no window_mm in the beds' voidprof summaries)".to_string(),
        [w] => window_note(w[0], w[1]),
        several => {
            let each: Vec<String> =
                several.iter().map(|w| format!("z = {}–{} mm", format_mm(w[0]), format_mm(w[1]))).collect();
            format!("ε averaged over different axial windows: {}", each.join(", "))
        }
    };
    let seeds = match p.beds.as_slice() {
        [one] => single_bed_note(one),
        many => spread_note(many.len(), "seeds"),
    };
    ProfileFrame::wall_distance(Some(n / 2.0)).with_note(window).with_note(seeds)
}

/// One tube's mean radial profile ± its spread over seeds, with its references.
pub fn profile(dir: &Path, p: &ProfileResult) -> Result<String> {
    let name = format!("profile_{}.png", p.config);
    let series =
        vec![ProfileSeries::new("simulated, mean ± std of seeds", p.z.clone(), p.mean.clone())
            .with_spread(p.std.clone())];
    let refs: Vec<RefCurve> = p
        .scores
        .iter()
        .map(|s| {
            let label = match s.eps_b {
                Some(e) => format!("{} (ε_b {e:.3})", s.reference),
                None => s.reference.clone(),
            };
            let style = if p.shape == Shape::Sphere { CurveStyle::Solid } else { CurveStyle::Dashed };
            RefCurve::new(label, p.z.iter().copied().zip(s.curve.iter().copied()).collect(), style)
        })
        .collect();
    let x = format!("(R − r)/{}", p.z_unit.name());
    let title = format!("Radial void fraction, {} N = {:.2}", p.shape.name(), p.n);
    plot_profile_with_x_label(&dir.join(&name), &title, &x, &profile_frame(p), &series, &refs)?;
    Ok(name)
}

/// Porosity against COR or friction, one series per shape and tube, ± std.
pub fn parameter(dir: &Path, study: &str, series: &[StudySeries]) -> Result<Option<String>> {
    let drawn: Vec<ProfileSeries> = series
        .iter()
        .filter(|s| !s.points.is_empty())
        .map(|s| {
            let x = s.points.iter().map(|p| p.0).collect();
            let y = s.points.iter().map(|p| p.1).collect();
            ProfileSeries::new(s.label.clone(), x, y).with_spread(s.points.iter().map(|p| p.2).collect())
        })
        .collect();
    if drawn.is_empty() {
        return Ok(None);
    }
    let name = format!("porosity_vs_{study}.png");
    let (title, x) = if study == "cor" {
        ("Bulk porosity against COR (μ = 0.6), mean ± std", "pellet–pellet COR")
    } else {
        ("Bulk porosity against friction (COR = 0.6), mean ± std", "pellet–pellet friction μ")
    };
    Chart { title, x_label: x, y_label: "bulk porosity ε", series: &drawn, references: &[], frame: None }
        .render(&dir.join(&name))?;
    Ok(Some(name))
}
