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
    if distance == 0.0 {
        return None;
    }
    let gap = distance - ra - rb;
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

/// Whether a sampled hit between two cylinders or rings adds nothing that the exact contacts
/// do not give: a side sample on the other's side or cap, or a cap sample on the other's side.
/// Where two outer sides meet, the deepest point is the axes' common perpendicular
/// ([`lateral_hit`]) or lies on a rim; where a side lies on a cap, the contact is a segment
/// whose ends are rims (the side's ends or the cap's edge), and along it the gap is linear, so
/// no point inside is deeper than both ends. The rims' samples are refined to their exact
/// deepest points. The sampled hits in between came with normals fanned over the curved side,
/// 1.3° apart, each its own patch: up to 19 points and 7 loaded ones for one pair lying on
/// another's cap, rows that only slowed the solve and made its answer depend on the order.
///
/// `src_cone` is the sample's outward normal cone in its body frame (equal ends on a smooth
/// face) and `src_point` the sample; `dst_point` and `dst_normal` the point and the SDF's
/// outward normal in the other body's frame. Ring bores (concave) are kept.
pub(crate) fn redundant_hit(
    src: &ShapeDesc,
    src_point: &Vec3,
    src_cone: &(Vec3, Vec3),
    dst: &ShapeDesc,
    dst_point: &Vec3,
    dst_normal: &Vec3,
) -> bool {
    if side(src).is_none() || side(dst).is_none() || src_cone.0 != src_cone.1 {
        return false;
    }
    let cap = |n: &Vec3| n.x == 0.0 && n.y == 0.0;
    let src_on_side = outer_side(src_point, &src_cone.0);
    let src_on_cap = cap(&src_cone.0);
    let dst_side = on_outer_side(dst, dst_point, dst_normal);
    let dst_cap = cap(dst_normal);
    (src_on_side && (dst_side || dst_cap)) || (src_on_cap && dst_side)
}

/// Whether a cylinder's or ring's surface normal `n` at body-frame point `p` is its outer
/// side's (radial, outwards; a ring's bore faces inwards).
fn outer_side(p: &Vec3, n: &Vec3) -> bool {
    n.z == 0.0 && n.x * p.x + n.y * p.y > 0.0
}

/// Whether the signed distance of `shape` at body-frame point `p` took its outer side's face
/// (its gradient `n` radial and outwards): the side of a cylinder or a ring, not a cap, an
/// edge or a ring's bore.
pub(crate) fn on_outer_side(shape: &ShapeDesc, p: &Vec3, n: &Vec3) -> bool {
    side(shape).is_some() && outer_side(p, n)
}
