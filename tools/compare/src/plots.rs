//! Building the plots from the scores.

use std::path::{Path, PathBuf};

use anyhow::Result;
use pellet_plot::{
    format_mm, single_bed_note, spread_note, window_note, CurveStyle, ProfileFrame, ProfileSeries, RefCurve,
};
use pellet_refs::bulk::BulkCorrelation;
use pellet_refs::radial::RadialCorrelation;
use pellet_refs::registry::Reference;
use pellet_refs::scoring::{radial_curve, Bed, BulkScore, EpsBChoice};
use pellet_refs::{Grade, NDefinition, Shape};

use crate::beds::SimProfile;
use crate::inputs::Summary;
use crate::plot_path;

fn style(grade: Grade) -> CurveStyle {
    if grade == Grade::C {
        CurveStyle::Dashed
    } else {
        CurveStyle::Solid
    }
}

/// A radial correlation on a fine grid over the profile's z range.
pub fn radial_reference(c: &RadialCorrelation, p: &SimProfile, bed: &Bed, choice: EpsBChoice) -> Result<RefCurve> {
    let z_max = p.profile.z.last().copied().unwrap_or(0.0).max(0.0);
    let steps = ((z_max / 0.005).ceil() as usize).clamp(2, 4000);
    let z: Vec<f64> = (0..=steps).map(|i| z_max * i as f64 / steps as f64).collect();
    let curve = radial_curve(c, &z, bed.n_for(p.profile.z_unit), choice)?;
    let eps_b = match (curve.eps_b, curve.eps_b_method) {
        (Some(v), Some(m)) => format!(", ε_b = {v:.3} {m}"),
        _ => String::new(),
    };
    let grade = if c.grade == Grade::C { " [C]" } else { "" };
    Ok(RefCurve::new(format!("{}{eps_b}{grade}", c.label), z.into_iter().zip(curve.eps).collect(), style(c.grade)))
}

/// Experimental points.
pub fn experiment_points(name: &str, z: &[f64], eps: &[f64]) -> RefCurve {
    RefCurve::new(
        format!("experiment {name}"),
        z.iter().copied().zip(eps.iter().copied()).collect(),
        CurveStyle::Markers,
    )
}

/// The profile plot's wall (x = 0), axis (x = N/2 in the wall unit, when N is known) and
/// caption: the axial window of the summaries that describe the profile, and whether the
/// profile is one bed (a single sample) or a mean with its spread. The summaries describe the
/// profile when there is one per profile CSV; otherwise the first describes it (as it gives
/// the profile's dp and D).
pub fn profile_frame(p: &SimProfile, bed: Option<&Bed>, summaries: &[(String, Summary)]) -> ProfileFrame {
    let axis = bed.and_then(|b| b.n_for(p.profile.z_unit)).map(|n| n / 2.0);
    let own = if summaries.len() == p.packings { summaries } else { &summaries[..summaries.len().min(1)] };
    let mut windows: Vec<([f64; 2], Vec<&str>)> = Vec::new();
    for (source, s) in own {
        let Some(w) = s.window_mm else { continue };
        match windows.iter_mut().find(|(v, _)| *v == w) {
            Some((_, sources)) => sources.push(source),
            None => windows.push((w, vec![source])),
        }
    }
    let window = match windows.as_slice() {
        [] => "axial window not known: no voidprof summary with window_mm describes this profile".to_string(),
        [(w, sources)] => format!("{} ({})", window_note(w[0], w[1]), sources.join(", ")),
        several => {
            let each: Vec<String> = several
                .iter()
                .map(|(w, sources)| format!("z = {}–{} mm ({})", format_mm(w[0]), format_mm(w[1]), sources.join(", ")))
                .collect();
            format!("ε averaged over different axial windows: {}", each.join("; "))
        }
    };
    let first = own.first().map(|(_, s)| s);
    let beds_in_summary = first.and_then(|s| s.beds);
    let samples = match (p.packings, &p.spread, beds_in_summary) {
        (k, Some(_), _) if k > 1 => spread_note(k, "profiles"),
        (_, Some(_), Some(k)) if k > 1 => {
            format!("mean of {k} beds (voidprof summary); the band is the profile CSV's void_fraction_std")
        }
        (_, Some(_), _) => "the band is the profile CSV's void_fraction_std".to_string(),
        (_, None, Some(1)) => {
            let source = first.and_then(|s| s.per_bed.as_ref()?.first()?.source.clone()).unwrap_or_default();
            single_bed_note(if source == "-" { "stdin" } else { &source })
        }
        (_, None, Some(k)) => {
            format!("mean of {k} beds (voidprof summary); their spread is not in the profile CSV, so none is shown")
        }
        (_, None, None) => {
            "one profile, no spread: if it is of one bed, it is a single sample; beds packed with another seed differ"
                .to_string()
        }
    };
    ProfileFrame::wall_distance(axis).with_note(window).with_note(samples)
}

/// profile.png and profile.svg.
pub fn profile_plot(
    dir: &Path,
    p: &SimProfile,
    bed: Option<&Bed>,
    frame: &ProfileFrame,
    curves: &[RefCurve],
) -> Result<Vec<PathBuf>> {
    let label = if p.packings > 1 { format!("simulated, mean of {}", p.packings) } else { "simulated".into() };
    let mut series = ProfileSeries::new(label, p.profile.z.clone(), p.profile.eps.clone());
    if let Some(s) = &p.spread {
        series = series.with_spread(s.clone());
    }
    let n = bed.and_then(|b| b.n_for(p.profile.z_unit));
    let shape = bed.map_or("", |b| b.shape.name());
    let title = match n {
        Some(n) => format!("Radial void fraction, {shape}s, N = D/{} = {n:.2}", p.profile.z_unit.name()),
        None => format!("Radial void fraction, {shape}s"),
    };
    let x_label = format!("(R − r)/{}", p.profile.z_unit.name());
    let mut paths = Vec::new();
    for ext in ["png", "svg"] {
        let path = plot_path(dir, "profile", ext);
        pellet_plot::plot_profile_with_x_label(&path, &title, &x_label, frame, std::slice::from_ref(&series), curves)?;
        paths.push(path);
    }
    Ok(paths)
}

/// The N definition of the porosity plot's x axis for a bed shape.
fn axis_definition(shape: Shape) -> NDefinition {
    match shape {
        Shape::Sphere => NDefinition::DOverDp,
        Shape::Cylinder | Shape::Ring => NDefinition::DOverDpv,
    }
}

/// porosity_vs_n.png and .svg: every scored bulk correlation over its
/// validity range, and the simulated beds as points. A correlation with
/// another N definition than the axis is converted with the first bed's
/// ratio of the two Ns (and left out if that is unknown).
pub fn porosity_plot(dir: &Path, refs: &[Reference], beds: &[Bed], scores: &[&BulkScore]) -> Result<Vec<PathBuf>> {
    let shape = beds[0].shape;
    let axis = axis_definition(shape);
    let bed_ns: Vec<f64> = beds.iter().filter_map(|b| b.n(axis)).collect();
    let lo = bed_ns.iter().copied().fold(f64::INFINITY, f64::min).clamp(1.0, 3.0);
    let hi = bed_ns.iter().copied().fold(0.0, f64::max).max(12.0) * 1.25;
    let mut curves = Vec::new();
    for r in refs {
        let Reference::Bulk(c) = r else { continue };
        if !scores.iter().any(|s| s.reference == c.name) {
            continue;
        }
        if let Some(curve) = bulk_curve(c, &beds[0], axis, lo, hi) {
            curves.push(curve);
        }
    }
    let points: Vec<(f64, f64)> = beds.iter().filter_map(|b| Some((b.n(axis)?, b.bulk_porosity?))).collect();
    curves.push(RefCurve::new("simulated beds", points, CurveStyle::Markers).with_color((0, 0, 0)));
    let title = format!("Bulk porosity vs N, {}s", shape.name());
    let x_label = axis.formula().to_string();
    let mut paths = Vec::new();
    for ext in ["png", "svg"] {
        let path = plot_path(dir, "porosity_vs_n", ext);
        pellet_plot::plot_porosity_vs_n(&path, &title, &x_label, &curves)?;
        paths.push(path);
    }
    Ok(paths)
}

fn bulk_curve(c: &BulkCorrelation, bed: &Bed, axis: NDefinition, lo: f64, hi: f64) -> Option<RefCurve> {
    // x on the axis = N_own / ratio, ratio = N_own/N_axis for this bed geometry.
    let ratio = if c.n_definition == axis { 1.0 } else { bed.n(c.n_definition)? / bed.n(axis)? };
    let (a, b) = (lo.max(c.n_range.min / ratio), hi.min(c.n_range.max / ratio));
    if b.partial_cmp(&a) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    let pts: Vec<(f64, f64)> = (0..=400)
        .filter_map(|i| {
            let x = a + (b - a) * i as f64 / 400.0;
            let y = c.predict(x * ratio, &bed.extras())?;
            y.is_finite().then_some((x, y))
        })
        .collect();
    let grade = if c.grade == Grade::C { " [C]" } else { "" };
    let units = if c.n_definition == axis { String::new() } else { format!(" ({})", c.n_definition.formula()) };
    Some(RefCurve::new(format!("{}{units}{grade}", c.label), pts, style(c.grade)))
}
