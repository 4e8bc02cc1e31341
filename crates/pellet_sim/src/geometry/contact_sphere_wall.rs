//! Closed-form contacts of a sphere with the static walls: floor, tube side wall (seen from
//! inside), lid and extra planes (`docs/engine.md`, "Contact generation").

use super::contact::{Contact, ContactKey, Counterpart, GapKinematics};
use crate::container::{Container, WallId};
use crate::math::{Real, Vec3};

fn make(a: usize, wall: WallId, x: &Vec3, r: Real, normal: Vec3, gap: Real, kin: GapKinematics) -> Contact {
    Contact {
        a,
        b: Counterpart::Wall(wall),
        point: x - normal * (r + 0.5 * gap),
        lever_a: -normal * r,
        lever_b: Vec3::zeros(),
        normal,
        gap,
        kinematics: kin,
        key: ContactKey { a: a as u32, b: Counterpart::Wall(wall), feature: 0 },
    }
}

/// Contact of sphere `a` (centre `x`, radius `r`) with wall `wall`, if the gap ≤ `max_gap`.
pub fn sphere_wall(container: &Container, wall: WallId, a: usize, x: &Vec3, r: Real, max_gap: Real) -> Option<Contact> {
    let (normal, gap, kin) = match wall {
        WallId::Floor => (Vec3::z(), x.z - r, GapKinematics::SpherePlane),
        WallId::Lid => {
            let h = container.lid_height?;
            (-Vec3::z(), h - x.z - r, GapKinematics::SpherePlane)
        }
        WallId::Plane(i) => {
            let p = container.planes.get(i as usize)?;
            (p.normal, p.normal.dot(x) - p.offset - r, GapKinematics::SpherePlane)
        }
        WallId::Tube => {
            let rho = (x.x * x.x + x.y * x.y).sqrt();
            // On the axis every radial direction is equally valid; the tube is then far away
            // for any sphere that passed validation, so the choice does not matter.
            let n = if rho > 0.0 { Vec3::new(-x.x / rho, -x.y / rho, 0.0) } else { -Vec3::x() };
            (n, container.tube_radius - rho - r, GapKinematics::SphereTube { rho })
        }
    };
    (gap <= max_gap).then(|| make(a, wall, x, r, normal, gap, kin))
}
