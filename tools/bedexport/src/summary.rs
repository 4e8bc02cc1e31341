//! The text summary printed when the export is done.

use std::fmt::Write;

use crate::Exported;

/// What was written, what each treatment did, and the voxel porosity
/// beside the exact one.
pub fn text(e: &Exported) -> String {
    let mut s = String::new();
    let (z0, z1) = (e.range.0 * 1e3, e.range.1 * 1e3);
    if e.whole {
        let _ = writeln!(s, "pellets: {} of {} (centroid in {z0:.3} to {z1:.3} mm)", e.selected, e.pellets);
    } else {
        let _ = writeln!(
            s,
            "pellets: {} of {} in {z0:.3} to {z1:.3} mm, {} of them cut at the planes and capped",
            e.selected, e.pellets, e.cut
        );
    }
    for (what, path) in &e.files {
        let _ = writeln!(s, "wrote {what}: {path}");
    }
    if e.triangles > 0 {
        let _ = writeln!(s, "surface triangles: {}", e.triangles);
    }
    for line in &e.report.lines {
        let _ = writeln!(
            s,
            "{}: {} pellet-pellet, {} pellet-wall and {} pellet-floor contacts treated; porosity change {:+.5} ({})",
            line.name,
            line.pellet_contacts,
            line.wall_contacts,
            line.floor_contacts,
            line.porosity_change,
            line.parameters
        );
    }
    if let Some((grid, exact, dp)) = &e.voxels {
        let [nx, ny, nz] = grid.dims;
        let (g0, g1) = grid.z_range();
        let _ = writeln!(
            s,
            "voxels: {nx} x {ny} x {nz} of {:.4} mm ({:.2} per dp), z {:.3} to {:.3} mm",
            grid.spacing * 1e3,
            dp / grid.spacing,
            g0 * 1e3,
            g1 * 1e3
        );
        match exact {
            Some(x) => {
                let _ = writeln!(
                    s,
                    "voxel porosity {:.5}; exact bulk porosity (as voidprof) {x:.5}; difference {:+.5}",
                    grid.porosity(),
                    grid.porosity() - x
                );
            }
            None => {
                let _ = writeln!(s, "voxel porosity {:.5}", grid.porosity());
            }
        }
    }
    s
}
