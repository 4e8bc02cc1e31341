//! Contacts of non-spherical pellets with the static walls (`docs/engine.md`, "Contact
//! generation").
//!
//! Cylinders and rings, analytically: against a plane, per outer rim the lowest point plus the
//! three rim points 90°, 180° and 270° from it (a cap lying flat then gives a 4-point support
//! square; tilted, only the lowest point is near); against the tube wall, per outer rim the
//! points of locally largest radial distance (1-D maximisations along the rim; at most two). The
//! maximum of the convex function ρ over a cylinder lies on a rim circle, so this is exact.
//! Mesh shapes: their samples, reduced to ≤ 4 points per wall.

use super::contact::{Contact, ContactKey, Counterpart, GapKinematics, NormalOwner};
use super::narrow_phase::Pellet;
use super::patch::{reduce, Hit, NEAR_BAND};
use super::rim_refine::{rim_min, AngleNear};
use crate::container::{Container, WallId};
use crate::math::{axial_distance, Mat3, Real, Vec3};
use crate::shape::ShapeDesc;
use std::f64::consts::TAU;
use std::sync::OnceLock;

/// Coarse angles scanned before the refinement of the tube-wall maximum.
const TUBE_SCAN: usize = 16;
/// Sine of the tilt below which a rim's points on a plane stay fixed in the body
/// (`square_direction`).
const FLAT_TILT: Real = 1e-2;
/// Angles per turn to which the lowest rim point of a nearly flat rim is rounded.
const FLAT_ANGLES: Real = 128.0;
/// Feature offset of a rim's second point on the tube wall (`tube_points`).
const TUBE_SECOND: u32 = 1 << 8;

/// A plane wall as (inward normal, offset): gap(p) = n·p − offset.
fn plane(container: &Container, wall: WallId) -> Option<(Vec3, Real)> {
    match wall {
        WallId::Floor => Some((Vec3::z(), 0.0)),
        WallId::Lid => container.lid_height.map(|h| (-Vec3::z(), -h)),
        WallId::Plane(i) => container.planes.get(i as usize).map(|p| (p.normal, p.offset)),
        WallId::Tube => None,
    }
}

fn make(a: &Pellet<'_>, wall: WallId, p: Vec3, normal: Vec3, gap: Real, kin: GapKinematics, feature: u32) -> Contact {
    Contact {
        a: a.index,
        b: Counterpart::Wall(wall),
        point: p - normal * (0.5 * gap),
        lever_a: p - a.body.position,
        lever_b: Vec3::zeros(),
        normal,
        gap,
        kinematics: kin,
        key: ContactKey { a: a.index as u32, b: Counterpart::Wall(wall), feature },
    }
}

/// Tube wall normal and gap at world point `p`.
fn tube_at(container: &Container, p: &Vec3) -> (Vec3, Real, Real) {
    let rho = axial_distance(p.x, p.y);
    let n = if rho > 0.0 { Vec3::new(-p.x / rho, -p.y / rho, 0.0) } else { -Vec3::x() };
    (n, container.tube_radius - rho, rho)
}

/// Contacts of a cylinder or ring (`a`) with `wall`, gap ≤ `max_gap`.
fn rims_wall(container: &Container, wall: WallId, a: &Pellet<'_>, max_gap: Real, out: &mut Vec<Contact>) {
    let rot = *a.body.orientation.to_rotation_matrix().matrix();
    for k in (0..a.geom.rims.len()).filter(|&k| a.geom.rims[k].outer) {
        rim_wall(container, wall, a, &rot, k, max_gap, out);
    }
}

/// The rim feature's wall contact: on a plane wall, feature 4k + j is point j of rim k; on the
/// tube, feature k or k + `TUBE_SECOND` is one of rim k's points nearest the wall.
fn rim_of_feature(container: &Container, wall: WallId, feature: u32) -> usize {
    if plane(container, wall).is_some() {
        feature as usize / 4
    } else {
        (feature % TUBE_SECOND) as usize
    }
}

/// The direction (world) from a rim's centre to the first of its four points on a plane, given
/// `d`, the plane's inward normal reversed and projected onto the rim's plane (its length is
/// the sine of the tilt). Tilted by more than `FLAT_TILT`, it is the lowest point's. Nearer to
/// flat, the lowest point's angle on the rim is rounded to `FLAT_ANGLES` steps, so that a cap
/// lying flat keeps its four points, fixed in the body, while round-off rocks it: points that
/// followed every 1e-7 rad of tilt swung round the rim by 0.01 rad a step, and their warm
/// friction then pulled in every direction. The rounding leaves the lowest point at most
/// sin(tilt) r (1 − cos(π/FLAT_ANGLES)) ≈ 3e-6 r too high.
fn square_direction(rot: &Mat3, d: &Vec3) -> Vec3 {
    let s = d.norm();
    if s > FLAT_TILT {
        return d / s;
    }
    let body = rot.transpose() * d;
    let step = TAU / FLAT_ANGLES;
    let t = if s > 0.0 { (body.y.atan2(body.x) / step).round() * step } else { 0.0 };
    rot * Vec3::new(t.cos(), t.sin(), 0.0)
}

/// Contacts of outer rim `k` of `a` (rotation matrix `rot`) with `wall`, gap ≤ `max_gap`.
fn rim_wall(
    container: &Container,
    wall: WallId,
    a: &Pellet<'_>,
    rot: &Mat3,
    k: usize,
    max_gap: Real,
    out: &mut Vec<Contact>,
) {
    let rim = &a.geom.rims[k];
    let x = a.body.position;
    let axis = rot.column(2).into_owned();
    let centre = x + axis * rim.z;
    if let Some((n, offset)) = plane(container, wall) {
        let d = -(n - axis * n.dot(&axis));
        let e = square_direction(rot, &d);
        let f = axis.cross(&e);
        for (j, dir) in [e, f, -e, -f].iter().enumerate() {
            let p = centre + dir * rim.radius;
            let gap = n.dot(&p) - offset;
            if gap <= max_gap {
                let kin = GapKinematics::Point { owner: NormalOwner::Fixed };
                out.push(make(a, wall, p, n, gap, kin, (4 * k + j) as u32));
            }
        }
    } else {
        for (p, feature) in tube_points(a, rot, k) {
            let (n, gap, rho) = tube_at(container, &p);
            if gap <= max_gap {
                out.push(make(a, wall, p, n, gap, GapKinematics::PointTube { rho }, feature));
            }
        }
    }
}

/// The points of rim `k` of `a` nearest the tube wall, with their features: every local maximum
/// of the radial distance ρ along the rim, refined by Brent's method from a coarse scan. There
/// are at most two: ρ² along a circle is a trigonometric polynomial of degree 2. A cap facing the
/// wall touches it at two rim points, left and right of its centre, whose radial distances differ
/// only by its tilt; one point alone let the cap turn about it into the wall. A single maximum
/// is feature k; of two, the one on the rim's clockwise side (seen from the axis) is k and the
/// other k + `TUBE_SECOND`, so that a cap at rest keeps both keys.
fn tube_points(a: &Pellet<'_>, rot: &Mat3, k: usize) -> Vec<(Vec3, u32)> {
    let rim = &a.geom.rims[k];
    let x = a.body.position;
    let world = |c: Real, s: Real| rot * Vec3::new(rim.radius * c, rim.radius * s, rim.z) + x;
    let neg_rho = |c: Real, s: Real| {
        let p = world(c, s);
        -axial_distance(p.x, p.y)
    };
    let step = TAU / TUBE_SCAN as Real;
    let angles = scan_angles();
    let mut scan = [0.0; TUBE_SCAN];
    for (v, &(c, s)) in scan.iter_mut().zip(angles) {
        *v = neg_rho(c, s);
    }
    let mut found: Vec<(Real, Real)> = Vec::with_capacity(2);
    for s in 0..TUBE_SCAN {
        let (prev, next) = (scan[(s + TUBE_SCAN - 1) % TUBE_SCAN], scan[(s + 1) % TUBE_SCAN]);
        // A local minimum of −ρ among the scan (ties towards the lower index).
        if scan[s] <= prev && scan[s] < next {
            let t0 = step * s as Real;
            let near = AngleNear::with_cos_sin(t0, angles[s].0, angles[s].1);
            let f = |t: Real| {
                let (c, s) = near.cos_sin(t);
                neg_rho(c, s)
            };
            let (t, v) = rim_min(f, t0 - step, t0 + step);
            let t = t.rem_euclid(TAU);
            let same = |u: Real| {
                let d = (u - t).rem_euclid(TAU);
                d.min(TAU - d) < 1e-6
            };
            if !found.iter().any(|&(u, _)| same(u)) {
                found.push((t, v));
            }
        }
    }
    // A rim of a pellet upright on the floor is a horizontal circle with one maximum; the scan
    // finds at least one whenever the scan values are not all equal (a rim centred on the axis).
    if found.is_empty() {
        found.push((0.0, neg_rho(1.0, 0.0)));
    }
    found.sort_by(|p, q| p.1.total_cmp(&q.1).then(p.0.total_cmp(&q.0)));
    found.truncate(2);
    let points: Vec<Vec3> = found
        .iter()
        .map(|&(t, _)| {
            let (s, c) = t.sin_cos();
            world(c, s)
        })
        .collect();
    if points.len() == 1 {
        return vec![(points[0], k as u32)];
    }
    let centre = x + rot.column(2).into_owned() * rim.z;
    let side = |p: &Vec3| Vec3::z().cross(&centre).dot(&(p - centre));
    let first = if side(&points[0]) <= side(&points[1]) { 0 } else { 1 };
    vec![(points[first], k as u32), (points[1 - first], k as u32 + TUBE_SECOND)]
}

/// (cos, sin) of the tube scan's angles (`TAU / TUBE_SCAN` × s, as `tube_points` spells them),
/// computed once.
fn scan_angles() -> &'static [(Real, Real); TUBE_SCAN] {
    static ANGLES: OnceLock<[(Real, Real); TUBE_SCAN]> = OnceLock::new();
    ANGLES.get_or_init(|| {
        std::array::from_fn(|s| {
            let step = TAU / TUBE_SCAN as Real;
            let (sin, cos) = (step * s as Real).sin_cos();
            (cos, sin)
        })
    })
}

/// The wall contact of mesh sample `i` of `a`.
fn sample_hit(container: &Container, wall: WallId, a: &Pellet<'_>, i: usize) -> Option<(Hit, GapKinematics)> {
    let p = a.body.orientation * a.geom.samples.get(i)? + a.body.position;
    let (n, gap, kin) = match plane(container, wall) {
        Some((n, offset)) => (n, n.dot(&p) - offset, GapKinematics::Point { owner: NormalOwner::Fixed }),
        None if wall == WallId::Tube => {
            let (n, gap, rho) = tube_at(container, &p);
            (n, gap, GapKinematics::PointTube { rho })
        }
        None => return None,
    };
    let hit = Hit { pa: p, pb: p - n * gap, normal: n, gap, feature: i as u32, owner: NormalOwner::Fixed, wedge: None };
    Some((hit, kin))
}

/// Contacts of a mesh pellet with `wall`: samples within `max_gap`, reduced to ≤ 4.
fn samples_wall(container: &Container, wall: WallId, a: &Pellet<'_>, max_gap: Real, out: &mut Vec<Contact>) {
    let mut hits = Vec::new();
    let mut kins = Vec::new();
    for i in 0..a.geom.samples.len() {
        if let Some((h, kin)) = sample_hit(container, wall, a, i) {
            if h.gap <= max_gap {
                hits.push(h);
                kins.push(kin);
            }
        }
    }
    if hits.is_empty() {
        return;
    }
    let mut order: Vec<usize> = (0..hits.len()).collect();
    order.sort_by(|&i, &j| hits[i].gap.total_cmp(&hits[j].gap).then(i.cmp(&j)));
    let n = hits[order[0]].normal;
    for k in reduce(&hits, &order, &n, NEAR_BAND * a.geom.bounding_radius, &[], 0.0) {
        let h = &hits[k];
        out.push(make(a, wall, h.pa, h.normal, h.gap, kins[k], h.feature));
    }
}

/// Contacts of a non-spherical pellet with `wall`, gap ≤ `max_gap`.
pub fn shape_wall(container: &Container, wall: WallId, a: Pellet<'_>, max_gap: Real, out: &mut Vec<Contact>) {
    match a.shape {
        ShapeDesc::Mesh { .. } => samples_wall(container, wall, &a, max_gap, out),
        _ => rims_wall(container, wall, &a, max_gap, out),
    }
}

/// Re-evaluates the wall contact with `feature` at the current pose.
pub fn shape_wall_feature(container: &Container, wall: WallId, a: Pellet<'_>, feature: u32) -> Option<Contact> {
    match a.shape {
        ShapeDesc::Mesh { .. } => {
            let (h, kin) = sample_hit(container, wall, &a, feature as usize)?;
            Some(make(&a, wall, h.pa, h.normal, h.gap, kin, h.feature))
        }
        _ => {
            // Only the feature's own rim: evaluating every rim (each a search
            // on the tube) to keep one contact was 2 % of 20 cylinders in allocations alone.
            let k = rim_of_feature(container, wall, feature);
            a.geom.rims.get(k).filter(|r| r.outer)?;
            let rot = *a.body.orientation.to_rotation_matrix().matrix();
            let mut out = Vec::with_capacity(4);
            rim_wall(container, wall, &a, &rot, k, Real::INFINITY, &mut out);
            out.into_iter().find(|c| c.key.feature == feature)
        }
    }
}
