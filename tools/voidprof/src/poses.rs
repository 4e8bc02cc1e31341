//! Checks of a bed given as poses (`--poses`), which unlike a packing file from `pack` may
//! hold pellets no tube could: outside the wall, below the floor, inside each other.

use anyhow::bail;

use pellet_geom::math::Real;
use pellet_geom::{Bed, ClosedForm, Pellet, PlacedPellet};

/// How far (fraction of the pellet diameter dp) a pellet may reach past the wall or the floor,
/// or into another pellet, before it is reported: a rigid-body packing's contacts penetrate by
/// less than that.
pub const TOLERANCE_DP: Real = 0.01;

/// Errors for a tube narrower than the pellet and for pellets outside the tube or below the
/// floor (by more than [`TOLERANCE_DP`]); a warning line for pellets that overlap.
pub fn check(bed: &Bed, source: &str, dp: Real) -> anyhow::Result<Option<String>> {
    let pellet = &bed.pellet_types[0];
    let radius = 0.5 * bed.tube.diameter;
    let narrowest = narrowest_width(pellet);
    if bed.tube.diameter < narrowest {
        bail!(
            "--tube-diameter {} mm is narrower than the pellet ({:.4} mm across at its narrowest); give the tube's inner diameter in mm",
            bed.tube.diameter * 1e3,
            narrowest * 1e3
        );
    }
    let tol = TOLERANCE_DP * dp;
    for (i, pose) in bed.pellets.iter().enumerate() {
        let (reach, bottom) = extent(pellet, pose);
        let [x, y, z] = pose.position.map(|c| c * 1e3);
        if reach > radius + tol {
            bail!(
                "{source}: pellet {} at ({x}, {y}, {z}) mm reaches {:.3} mm from the axis, outside the {} mm tube (tolerance {:.3} mm); check the units (mm) and the tube diameter",
                i + 1,
                reach * 1e3,
                bed.tube.diameter * 1e3,
                tol * 1e3
            );
        }
        if bottom < -tol {
            bail!(
                "{source}: pellet {} at ({x}, {y}, {z}) mm reaches {:.3} mm below the floor z = 0 (tolerance {:.3} mm); the floor must be at z = 0",
                i + 1,
                -bottom * 1e3,
                tol * 1e3
            );
        }
    }
    Ok(match pellet_analysis::overlapping_pairs(bed, tol) {
        Some((0, _)) => None,
        Some((pairs, pellets)) => Some(format!(
            "{source}: {pairs} pairs of pellets ({pellets} pellets) overlap by more than {:.3} mm; the profile counts their common volume once, the bulk porosity twice",
            tol * 1e3
        )),
        None => Some(format!("{source}: overlaps between pellets are not checked for this shape (no closed form)")),
    })
}

/// The pellet's smallest extent along its body axes (m): no tube narrower than it holds it.
fn narrowest_width(pellet: &Pellet) -> Real {
    match pellet.closed_form {
        Some(ClosedForm::Sphere { radius }) => return 2.0 * radius,
        Some(ClosedForm::Cylinder { radius, half_height })
        | Some(ClosedForm::HollowCylinder { outer_radius: radius, half_height, .. }) => {
            return 2.0 * radius.min(half_height)
        }
        None => {}
    }
    (0..3)
        .map(|k| {
            let (lo, hi) = pellet
                .mesh
                .vertices
                .iter()
                .fold((Real::MAX, Real::MIN), |(lo, hi), v| (lo.min(v.coords[k]), hi.max(v.coords[k])));
            hi - lo
        })
        .fold(Real::MAX, Real::min)
}

/// The farthest reach from the tube axis and the lowest point of a placed pellet (m): exact for
/// a sphere, from the mesh vertices otherwise.
fn extent(pellet: &Pellet, pose: &PlacedPellet) -> (Real, Real) {
    if let Some(ClosedForm::Sphere { radius }) = pellet.closed_form {
        let [x, y, z] = pose.position;
        return (x.hypot(y) + radius, z - radius);
    }
    pellet.mesh.vertices.iter().fold((0.0, Real::MAX), |(reach, bottom), v| {
        let w = pose.to_world(v);
        (reach.max(w.x.hypot(w.y)), bottom.min(w.z))
    })
}
