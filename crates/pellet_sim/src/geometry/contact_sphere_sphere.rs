//! Closed-form sphere–sphere contact (`docs/engine.md`, "Contact generation"): one point, exact
//! gap and normal.

use super::contact::{Contact, ContactKey, Counterpart, GapKinematics};
use crate::math::{Real, Vec3};

/// Contact between sphere A (index `a`, centre `xa`, radius `ra`) and sphere B, if the gap is at
/// most `max_gap`. Coincident centres fall back to the +z normal rather than producing NaN.
pub fn sphere_sphere(a: usize, xa: &Vec3, ra: Real, b: usize, xb: &Vec3, rb: Real, max_gap: Real) -> Option<Contact> {
    let d = xa - xb;
    let dist = d.norm();
    let gap = dist - ra - rb;
    if gap > max_gap {
        return None;
    }
    let normal = if dist > 1e-15 * (ra + rb) { d / dist } else { Vec3::z() };
    // The point halfway across the gap, so that both lever arms are parallel to n.
    let point = xb + normal * (rb + 0.5 * gap);
    Some(Contact {
        a,
        b: Counterpart::Body(b),
        point,
        // Surface points of each sphere, so that impulses act at the true lever arms even when
        // the contact is generated slightly ahead of touching.
        lever_a: -normal * ra,
        lever_b: normal * rb,
        normal,
        gap,
        kinematics: GapKinematics::SphereSphere { distance: dist },
        key: ContactKey { a: a as u32, b: Counterpart::Body(b), feature: 0 },
    })
}
