//! The exact contact of two outer lateral surfaces (cylinders and rings) that cross.
//!
//! Sampled, the point where two crossed cylinders' sides meet is missed: the side carries rings
//! of samples 2h/5 apart along the axis, and the other side curves away from the line between
//! them, so the deepest sample can lie (2h/10)²/(2r) short of the deepest point, 0.1 mm for
//! 10 mm cylinders. The exact point comes from the closest points of the two axes: where both
//! lie within their lateral surfaces, the sides touch there, along the common perpendicular,
//! and the gap is the axes' distance less the two radii. Where either closest point lies beyond
//! its surface's end, the contact is at a rim, whose samples are refined exactly along it
//! (`contact_sampled`).

use super::contact::NormalOwner;
use super::narrow_phase::Pellet;
use super::patch::Hit;
use super::sdf::distance as distance_to;
use crate::math::{Real, Vec3};
use crate::shape::ShapeDesc;

/// The feature of the exact lateral contact (sample indices lie far below it).
pub(crate) const LATERAL: u32 = 1 << 29;
/// Axes closer to parallel than this (sine of their angle) touch along a line whose ends are
/// the rims': the samples and the rim refinement give them.
const PARALLEL: Real = 1e-6;
/// How closely (× the bounding radius) the other pellet's signed distance at each contact point
/// must equal the gap: exactly, up to round-off, where the sides themselves meet.
const AGREE: Real = 1e-9;

/// Radius and half-height of a pellet's outer lateral surface (cylinders and rings).
fn side(shape: &ShapeDesc) -> Option<(Real, Real)> {
    match *shape {
        ShapeDesc::Cylinder { radius, half_height } => Some((radius, half_height)),
        ShapeDesc::HollowCylinder { outer_radius, half_height, .. } => Some((outer_radius, half_height)),
        _ => None,
    }
}

/// The axis (unit, world) and centre of a pellet.
fn axis(p: &Pellet<'_>) -> (Vec3, Vec3) {
    (p.body.orientation * Vec3::z(), p.body.position)
}

/// The exact contact of `a`'s and `b`'s outer lateral surfaces where their axes' closest points
/// lie inside both surfaces (strictly: a closest point on an end circle is a rim's), with the
/// gap along the common perpendicular, whatever the gap; `None` for other shapes, parallel
/// axes, closest points beyond an end, or points where the sides do not meet (a ring's hole,
/// a cap nearer than the side).
pub(crate) fn lateral_hit(a: &Pellet<'_>, b: &Pellet<'_>) -> Option<Hit> {
    let (ra, ha) = side(a.shape)?;
    let (rb, hb) = side(b.shape)?;
    let ((u, xa), (v, xb)) = (axis(a), axis(b));
    let w = xa - xb;
    let c = u.dot(&v);
    let sin2 = 1.0 - c * c;
    if sin2 <= PARALLEL * PARALLEL {
        return None;
    }
    let (d, e) = (u.dot(&w), v.dot(&w));
    // Closest points of the lines xa + s u and xb + t v.
    let s = (c * e - d) / sin2;
    let t = (e - c * d) / sin2;
    if s.abs() >= ha || t.abs() >= hb {
        return None;
    }
    let (pa, pb) = (xa + u * s, xb + v * t);
    let between = pa - pb;
    let distance = between.norm();
    let gap = distance - ra - rb;
    if distance == 0.0 {
        return None;
    }
    let normal = between / distance;
    let (pa, pb) = (pa - normal * ra, pb + normal * rb);
    // Each point must meet the other pellet's side there: not a ring's hole (linked rings,
    // a pin through a bore) and not a cap nearer than the side (a crossing deep at an end).
    let meets = |p: &Pellet<'_>, at: &Vec3| {
        let local = p.body.orientation.inverse_transform_vector(&(at - p.body.position));
        (distance_to(p.shape, &local) - gap).abs() <= AGREE * p.geom.bounding_radius
    };
    if !(meets(b, &pa) && meets(a, &pb)) {
        return None;
    }
    Some(Hit { pa, pb, normal, gap, feature: LATERAL, owner: NormalOwner::B, wedge: None })
}

/// Whether a sampled hit is one of the two outer lateral surfaces on the other (the exact
/// contact replaces those): `src_cone` is the sample's outward normal in its body frame (equal
/// ends on a smooth face) and `src_point` the sample; `dst_point` and `dst_normal` the point and
/// the SDF's outward normal in the other body's frame.
pub(crate) fn side_on_side(
    src: &ShapeDesc,
    src_point: &Vec3,
    src_cone: &(Vec3, Vec3),
    dst: &ShapeDesc,
    dst_point: &Vec3,
    dst_normal: &Vec3,
) -> bool {
    let outer =
        |shape: &ShapeDesc, p: &Vec3, n: &Vec3| side(shape).is_some() && n.z == 0.0 && n.x * p.x + n.y * p.y > 0.0;
    src_cone.0 == src_cone.1 && outer(src, src_point, &src_cone.0) && outer(dst, dst_point, dst_normal)
}
