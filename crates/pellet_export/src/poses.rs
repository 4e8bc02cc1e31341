//! The poses as CSV, for anything else (and for `voidprof --poses`).
//!
//! # Format
//!
//! A header line, then one pellet per line:
//!
//! `id,type,x,y,z,qw,qx,qy,qz,axis_x,axis_y,axis_z,r`
//!
//! - `id`: the pellet's index in the packing file; `type`: its pellet type index;
//! - `x,y,z`: the centroid in the chosen unit (mm by default);
//! - `qw,qx,qy,qz`: the unit quaternion rotating the body frame (origin at
//!   the centroid, symmetry axis along body z) into the world;
//! - `axis_x,axis_y,axis_z`: the body z axis in world (unit vector);
//! - `r`: the centroid's distance from the tube axis (same unit as x).
//!
//! Tube axis z, floor z = 0. The columns `id,x,y,z,qw,qx,qy,qz` are those
//! `voidprof --poses` reads (extra columns are ignored), in millimetres.

use std::fmt::Write;

use pellet_geom::math::Real;
use pellet_geom::Bed;

/// The header line of the poses CSV.
pub const HEADER: &str = "id,type,x,y,z,qw,qx,qy,qz,axis_x,axis_y,axis_z,r";

/// The poses CSV of the pellets `indices` of `bed`, lengths × `scale`.
pub fn csv(bed: &Bed, indices: &[usize], scale: Real) -> String {
    let mut out = String::with_capacity(160 * (indices.len() + 1));
    out.push_str(HEADER);
    out.push('\n');
    for &i in indices {
        let p = &bed.pellets[i];
        let [x, y, z] = p.position.map(|c| c * scale);
        let [qw, qx, qy, qz] = p.orientation;
        let a = p.axis();
        let _ = writeln!(
            out,
            "{i},{},{x:.9},{y:.9},{z:.9},{qw:.12},{qx:.12},{qy:.12},{qz:.12},{:.9},{:.9},{:.9},{:.9}",
            p.type_index,
            a.x,
            a.y,
            a.z,
            x.hypot(y)
        );
    }
    out
}
