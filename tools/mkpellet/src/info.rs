//! `mkpellet info`: what a pellet file holds, as text or JSON.

use anyhow::bail;
use serde_json::json;

use pellet_cli::Outcome;
use pellet_geom::{ClosedForm, ConvexPiece, Pellet};
use pellet_io::PelletFile;

pub fn run(input: &str, as_json: bool, density: f64, stl: Option<&str>, obj: Option<&str>) -> anyhow::Result<Outcome> {
    if !(density.is_finite() && density > 0.0) {
        bail!("--density must be a finite number > 0 kg/m³ (got {density})");
    }
    let bytes = pellet_io::read_input(input)?;
    let file = pellet_io::decode_pellet(&bytes, input)?;
    let exports = crate::mesh_exports(&file.pellet, stl, obj)?;
    if exports.iter().any(|o| o.path == "-") {
        bail!("--stl/--obj cannot write to stdout here: stdout carries the report");
    }
    pellet_io::write_outputs(&exports)?;
    let report = summary(&file, density)?;
    let text = if as_json { serde_json::to_string_pretty(&report)? + "\n" } else { render_text(&file.pellet, &report) };
    pellet_cli::print_stdout(&text)?;
    Ok(Outcome::Success)
}

fn summary(file: &PelletFile, density: f64) -> anyhow::Result<serde_json::Value> {
    let p = &file.pellet;
    let topo = p.topology()?;
    let props = &p.properties;
    let mm = |x: f64| x * 1e3;
    let pieces: Vec<serde_json::Value> = p
        .pieces
        .iter()
        .map(|piece| match piece {
            ConvexPiece::Ball { radius, .. } => json!({"kind": "ball", "radius_mm": mm(*radius)}),
            ConvexPiece::Cylinder { center, radius, half_height } => json!({
                "kind": "cylinder", "center_mm": [mm(center.x), mm(center.y), mm(center.z)],
                "radius_mm": mm(*radius), "height_mm": mm(2.0 * half_height)}),
            ConvexPiece::Hull { points } => json!({"kind": "hull", "points": points.len()}),
        })
        .collect();
    let closed_form = p.closed_form.map(|c| match c {
        ClosedForm::Sphere { radius } => json!({"kind": "sphere", "radius_mm": mm(radius)}),
        ClosedForm::Cylinder { radius, half_height } => {
            json!({"kind": "cylinder", "radius_mm": mm(radius), "height_mm": mm(2.0 * half_height)})
        }
        ClosedForm::HollowCylinder { inner_radius, outer_radius, half_height } => json!({
            "kind": "hollow_cylinder", "inner_radius_mm": mm(inner_radius),
            "outer_radius_mm": mm(outer_radius), "height_mm": mm(2.0 * half_height)}),
    });
    let rows = |m: &pellet_geom::math::Matrix| -> Vec<[f64; 3]> {
        (0..3).map(|i| [m[(i, 0)], m[(i, 1)], m[(i, 2)]]).collect()
    };
    Ok(json!({
        "format_version": pellet_io::PELLET_FORMAT_VERSION,
        "written_by": file.provenance,
        "shape": p.shape.kind(),
        "parameters": p.shape,
        "level": p.level,
        "faces": topo.faces,
        "vertices": topo.vertices,
        "edges": topo.edges,
        "euler_characteristic": topo.euler_characteristic,
        "genus": topo.genus(),
        "volume_mm3": props.volume * 1e9,
        "area_mm2": props.area * 1e6,
        "equivalent_diameter_mm": mm(props.equivalent_diameter),
        "sphericity": props.sphericity,
        "centroid_mm": [mm(props.centroid.x), mm(props.centroid.y), mm(props.centroid.z)],
        "bounding_radius_mm": mm(p.bounding_radius),
        "inertia_per_density_m5": rows(&props.inertia),
        "principal_moments_per_density_m5": [props.principal_moments.x, props.principal_moments.y, props.principal_moments.z],
        "principal_axes_columns": rows(&props.principal_axes),
        "density_kg_m3": density,
        "mass_g": props.volume * density * 1e3,
        "principal_inertia_kg_mm2": (props.principal_moments * density * 1e6).as_slice(),
        "closed_form": closed_form,
        "collision_pieces": pieces,
        "notes": p.notes,
    }))
}

fn render_text(p: &Pellet, r: &serde_json::Value) -> String {
    let f = |k: &str| r[k].as_f64().unwrap_or(f64::NAN);
    let v3 = |k: &str| {
        let a = &r[k];
        format!(
            "{:.6}, {:.6}, {:.6}",
            a[0].as_f64().unwrap_or(0.0),
            a[1].as_f64().unwrap_or(0.0),
            a[2].as_f64().unwrap_or(0.0)
        )
    };
    let mut s = String::new();
    let params = serde_json::to_string(&p.shape).unwrap_or_default();
    s += &format!("shape:                {} {params}\n", p.shape.kind());
    s += &format!(
        "mesh:                 {} faces, {} vertices, Euler characteristic {} (genus {}), Loop level {}\n",
        r["faces"], r["vertices"], r["euler_characteristic"], r["genus"], p.level
    );
    s += &format!("volume:               {:.6} mm³\n", f("volume_mm3"));
    s += &format!("surface area:         {:.6} mm²\n", f("area_mm2"));
    s += &format!("equal-volume dpv:     {:.6} mm\n", f("equivalent_diameter_mm"));
    s += &format!("sphericity:           {:.6}\n", f("sphericity"));
    s += &format!("centroid:             ({}) mm\n", v3("centroid_mm"));
    s += &format!("bounding radius:      {:.6} mm\n", f("bounding_radius_mm"));
    s += &format!(
        "principal I/ρ:        ({:.6e}, {:.6e}, {:.6e}) m⁵\n",
        p.properties.principal_moments.x, p.properties.principal_moments.y, p.properties.principal_moments.z
    );
    s += &format!("at density:           {} kg/m³\n", f("density_kg_m3"));
    s += &format!("  mass:               {:.6} g\n", f("mass_g"));
    s += &format!("  principal inertia:  ({}) kg·mm²\n", v3("principal_inertia_kg_mm2"));
    let closed = match p.closed_form {
        Some(ClosedForm::Sphere { .. }) => "sphere SDF",
        Some(ClosedForm::Cylinder { .. }) => "solid-cylinder SDF",
        Some(ClosedForm::HollowCylinder { .. }) => "hollow-cylinder SDF",
        None => "none (mesh queries)",
    };
    s += &format!("closed form:          {closed}\n");
    s += &format!("collision pieces:     {} convex\n", p.pieces.len());
    for note in &p.notes {
        s += &format!("note:                 {note}\n");
    }
    s
}
