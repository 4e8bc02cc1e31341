//! The text outputs: radial CSV, axial CSV, spread CSV and the JSON summary.

use std::fmt::Write;

use serde_json::{json, Value};

use crate::Measurement;

/// The header of the radial profile CSV (fixed: downstream tools read it).
pub const RADIAL_HEADER: &str = "r_mm,wall_distance_mm,wall_distance_dp,wall_distance_dpv,void_fraction";

/// The mean radial profile: one row per radius, from the axis to the wall.
pub fn radial_csv(m: &Measurement) -> String {
    let mut out = String::from(RADIAL_HEADER);
    out.push('\n');
    let r_tube = m.stats.tube_radius;
    for (r, e) in m.stats.radius.iter().zip(&m.stats.mean) {
        let wall = r_tube - r;
        let _ = writeln!(out, "{:.6},{:.6},{:.6},{:.6},{:.6}", r * 1e3, wall * 1e3, wall / m.dp, wall / m.dpv, e);
    }
    out
}

/// Every bed's radial profile beside the mean, standard deviation, min and max.
pub fn spread_csv(m: &Measurement) -> String {
    let mut out = String::from("r_mm,wall_distance_mm,wall_distance_dpv,void_fraction_mean,void_fraction_std,void_fraction_min,void_fraction_max");
    for k in 1..=m.beds.len() {
        let _ = write!(out, ",void_fraction_{k}");
    }
    out.push('\n');
    let s = &m.stats;
    for i in 0..s.radius.len() {
        let wall = s.tube_radius - s.radius[i];
        let _ = write!(
            out,
            "{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6}",
            s.radius[i] * 1e3,
            wall * 1e3,
            wall / m.dpv,
            s.mean[i],
            s.std[i],
            s.min[i],
            s.max[i]
        );
        for b in &m.beds {
            let _ = write!(out, ",{:.6}", b.profile.void_fraction[i]);
        }
        out.push('\n');
    }
    out
}

/// The axial profile ε(z), averaged over the beds, bin by bin.
pub fn axial_csv(m: &Measurement) -> String {
    let mut out = String::from("z_mm,z_dp,void_fraction\n");
    let first = &m.beds[0].profile.axial;
    for j in 0..first.void_fraction.len() {
        let mid = 0.5 * (first.edges[j] + first.edges[j + 1]);
        let mean = m.beds.iter().map(|b| b.profile.axial.void_fraction[j]).sum::<f64>() / m.beds.len() as f64;
        let _ = writeln!(out, "{:.6},{:.6},{:.6}", mid * 1e3, mid / m.dp, mean);
    }
    out
}

fn mean_std(values: &[f64]) -> (f64, f64) {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let std = if values.len() > 1 {
        (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
    } else {
        0.0
    };
    (mean, std)
}

/// The JSON summary.
pub fn summary(m: &Measurement) -> Value {
    let bulk: Vec<f64> = m.beds.iter().map(|b| b.bulk.porosity).collect();
    let (bulk_mean, bulk_std) = mean_std(&bulk);
    let pellets: Vec<f64> = m.beds.iter().map(|b| b.pellets as f64).collect();
    let in_window: Vec<f64> = m.beds.iter().map(|b| b.bulk.centres_in_window as f64).collect();
    let count = |v: &[f64]| if v.len() == 1 { json!(v[0] as usize) } else { json!(mean_std(v).0) };
    let (dr, arc, dz) = m.beds[0].profile.steps;
    let beds: Vec<Value> = m
        .beds
        .iter()
        .map(|b| {
            json!({
                "source": b.source,
                "bulk_porosity": b.bulk.porosity,
                "profile_porosity": b.profile.cross_section_mean(),
                "pellets": b.pellets,
                "pellets_in_window": b.bulk.centres_in_window,
                "pellets_cut_by_window": b.bulk.cut,
                "pellet_volume_in_window_mm3": b.bulk.pellet_volume * 1e9,
                "coordination": b.coordination.as_ref().map(|c| json!({
                    "mean": c.mean,
                    "pellets": c.pellets,
                    "histogram": c.histogram,
                    "contact_gap_mm": c.gap * 1e3,
                })),
                "deepest_overlap": b.overlap.as_ref().map(|o| overlap_json(o, m.dpv)),
                "orientation": b.orientation.as_ref().map(|o| json!({
                    "edges_deg": o.edges_deg,
                    "counts": o.counts,
                    "pellets": o.pellets,
                    "mean_cos2": if o.mean_cos2.is_finite() { json!(o.mean_cos2) } else { Value::Null },
                    "order_parameter": if o.order_parameter.is_finite() { json!(o.order_parameter) } else { Value::Null },
                })),
            })
        })
        .collect();
    // The deepest pellet–pellet overlap over the beds (0 when none overlap), when measured.
    let deepest = m
        .beds
        .iter()
        .filter_map(|b| b.overlap)
        .fold(None, |acc: Option<f64>, o| Some(acc.unwrap_or(0.0).max(o.pellets.map_or(0.0, |p| p.depth))));
    json!({
        "tool": "voidprof",
        "version": env!("CARGO_PKG_VERSION"),
        "args": std::env::args().skip(1).collect::<Vec<_>>(),
        "bulk_porosity": bulk_mean,
        "bulk_porosity_std": bulk_std,
        "profile_porosity": mean_profile_porosity(m),
        "window_mm": [m.window.0 * 1e3, m.window.1 * 1e3],
        "window_rule": m.window_rule.as_deref().unwrap_or("given by --window"),
        "pellets": count(&pellets),
        "pellets_in_window": count(&in_window),
        "shape": m.shape,
        "pellet_diameter_mm": m.dp * 1e3,
        "dpv_mm": m.dpv * 1e3,
        "tube_diameter_mm": m.tube_diameter * 1e3,
        "N": m.tube_diameter / m.dp,
        "N_dpv": m.tube_diameter / m.dpv,
        "beds": m.beds.len(),
        "geometry": if m.mesh { "mesh" } else { "exact shape where known, else mesh" },
        "resolution_mm": { "radial_step": dr * 1e3, "arc_step": arc * 1e3, "axial_step": dz * 1e3 },
        "profile_std_max": m.stats.std.iter().copied().fold(0.0, f64::max),
        "deepest_overlap_mm": deepest.map(|d| d * 1e3),
        "deepest_overlap_dpv": deepest.map(|d| d / m.dpv),
        "per_bed": beds,
    })
}

/// One bed's deepest overlaps: between two pellets (0 and no pellets when none overlap)
/// and between a pellet and the tube (null when none pokes out), in mm and in dpv.
fn overlap_json(o: &pellet_analysis::DeepestOverlap, dpv: f64) -> Value {
    let mm = |p: &pellet_geom::math::Point| [p.x * 1e3, p.y * 1e3, p.z * 1e3];
    let depth = o.pellets.map_or(0.0, |p| p.depth);
    json!({
        "depth_mm": depth * 1e3,
        "depth_dpv": depth / dpv,
        "pellets": o.pellets.map(|p| [p.pellets.0, p.pellets.1]),
        "point_mm": o.pellets.map(|p| mm(&p.point)),
        "candidate_pairs": o.candidate_pairs,
        "tube": o.boundary.map(|b| json!({
            "depth_mm": b.depth * 1e3,
            "depth_dpv": b.depth / dpv,
            "boundary": b.boundary.name(),
            "pellet": b.pellet,
            "point_mm": mm(&b.point),
        })),
    })
}

/// ∫ ε̄(r) 2πr dr / (πR²) of the mean profile.
fn mean_profile_porosity(m: &Measurement) -> f64 {
    let s = &m.stats;
    let mut sum = 0.0;
    for k in 1..s.radius.len() {
        let (r0, r1) = (s.radius[k - 1], s.radius[k]);
        sum += 0.5 * (r1 - r0) * (r0 * s.mean[k - 1] + r1 * s.mean[k]);
    }
    2.0 * sum / (s.tube_radius * s.tube_radius)
}
