//! Contacts carried along with their bodies (`docs/engine.md`, "Contacts carried with their
//! bodies"): a contact point found at one pair of poses, moved to nearby ones as body-fixed
//! points with a body-fixed normal, its gap changed by how far the two points moved apart along
//! the normal. Between poses whose relative motion is a drift δ, a carried gap errs by the
//! second-order slide of the deepest point (~δ²/2ρ for surfaces of curvature radius ρ) and
//! never by more than 2δ: every body-fixed point's gap changes by at most δ, so the carried
//! point's gap stays within δ of its old value and the deepest point's within δ of that.

use super::contact::{Contact, Counterpart, GapKinematics, NormalOwner};
use crate::body::Body;
use crate::math::{turn_angle, Quat, Real, Vec3};
use serde::{Deserialize, Serialize};

/// Where a body is: its centre (m) and orientation (body → world).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    /// Centre of mass, m.
    pub position: Vec3,
    /// Orientation, body → world.
    pub orientation: Quat,
}

impl Pose {
    /// The pose of `body`.
    pub fn of(body: &Body) -> Self {
        Self { position: body.position, orientation: body.orientation }
    }
}

/// How far a pair has moved relative to each other between its poses then and now (m):
/// [`relative_drift`] of B against A with B's bounding radius `r`, or, for a pellet A at a wall
/// (`b` = `None`), of A against the world with A's.
pub(crate) fn pair_drift(a: (&Pose, &Pose), b: Option<(&Pose, &Pose)>, r: Real) -> Real {
    match b {
        Some((b_then, b_now)) => relative_drift(b_then, b_now, Some(a), r),
        None => relative_drift(a.0, a.1, None, r),
    }
}

/// How far any point of a body of bounding radius `r_b` has moved, relative to a second
/// body, between two pairs of poses `(a_then, b_then)` and `(a_now, b_now)` (m): the change of
/// its centre in the second body's frame plus its turn there times `r_b`. With `a` = `None`
/// the second body is the world (a wall).
fn relative_drift(b_then: &Pose, b_now: &Pose, a: Option<(&Pose, &Pose)>, r_b: Real) -> Real {
    let (t_then, q_then, t_now, q_now) = match a {
        Some((a_then, a_now)) => {
            let (inv_then, inv_now) = (a_then.orientation.inverse(), a_now.orientation.inverse());
            (
                inv_then * (b_then.position - a_then.position),
                inv_then * b_then.orientation,
                inv_now * (b_now.position - a_now.position),
                inv_now * b_now.orientation,
            )
        }
        None => (b_then.position, b_then.orientation, b_now.position, b_now.orientation),
    };
    (t_now - t_then).norm() + r_b * turn_angle(&q_now, &q_then)
}

/// Whether `c` can be carried: its gap is not a closed form in a sphere's centre (those are
/// cheaper to evaluate again than to carry).
pub(crate) fn carriable(c: &Contact) -> bool {
    matches!(c.kinematics, GapKinematics::Point { .. } | GapKinematics::PointTube { .. })
}

/// `c`, found with A at `a_then` and B (a body, or `None` for a wall) at `b_then`, carried to
/// `a_now` and `b_now`; `None` if it is not [`carriable`].
pub(crate) fn carried(c: &Contact, a_then: &Pose, a_now: &Pose, b: Option<(&Pose, &Pose)>) -> Option<Contact> {
    let owner = match c.kinematics {
        GapKinematics::Point { owner } => owner,
        GapKinematics::PointTube { .. } => NormalOwner::Fixed,
        _ => return None,
    };
    let turn_a = a_now.orientation * a_then.orientation.inverse();
    let pa_then = a_then.position + c.lever_a;
    let lever_a = turn_a * c.lever_a;
    let pa = a_now.position + lever_a;
    let (pb_then, pb, lever_b, turn_b) = match (c.b, b) {
        (Counterpart::Body(_), Some((b_then, b_now))) => {
            let turn_b = b_now.orientation * b_then.orientation.inverse();
            let lever_b = turn_b * c.lever_b;
            (b_then.position + c.lever_b, b_now.position + lever_b, lever_b, Some(turn_b))
        }
        // A wall's point stays where it was: 2·point − p_A is B's point of the midway point.
        (Counterpart::Wall(_), None) => {
            let pb = 2.0 * c.point - pa_then;
            (pb, pb, Vec3::zeros(), None)
        }
        _ => return None,
    };
    let normal = match (owner, turn_b) {
        (NormalOwner::A, _) => turn_a * c.normal,
        (NormalOwner::B, Some(turn_b)) => turn_b * c.normal,
        _ => c.normal,
    };
    let gap = c.gap + (pa - pb).dot(&normal) - (pa_then - pb_then).dot(&c.normal);
    let kinematics = match c.kinematics {
        GapKinematics::PointTube { .. } => GapKinematics::PointTube { rho: pa.xy().norm() },
        k => k,
    };
    Some(Contact { point: 0.5 * (pa + pb), lever_a, lever_b, normal, gap, kinematics, ..c.clone() })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::contact::ContactKey;

    fn body(position: Vec3, orientation: Quat) -> Pose {
        Pose { position, orientation }
    }

    fn pair_contact(a: &Pose, b: &Pose, pa: Vec3, pb: Vec3, normal: Vec3, owner: NormalOwner) -> Contact {
        Contact {
            a: 0,
            b: Counterpart::Body(1),
            point: 0.5 * (pa + pb),
            lever_a: pa - a.position,
            lever_b: pb - b.position,
            normal,
            gap: (pa - pb).dot(&normal),
            kinematics: GapKinematics::Point { owner },
            key: ContactKey { a: 0, b: Counterpart::Body(1), feature: 7 },
        }
    }

    #[test]
    fn a_rigid_motion_of_both_bodies_changes_no_gap() {
        let a = body(Vec3::new(0.0, 0.0, 0.01), Quat::identity());
        let b = body(Vec3::new(0.0, 0.0, 0.0), Quat::from_euler_angles(0.1, 0.0, 0.3));
        let c = pair_contact(
            &a,
            &b,
            Vec3::new(0.001, 0.0, 0.005),
            Vec3::new(0.001, 0.0, 0.00499),
            Vec3::z(),
            NormalOwner::B,
        );
        let m = Quat::from_euler_angles(0.4, -0.2, 1.0);
        let shift = Vec3::new(0.3, -0.1, 0.2);
        let moved = |x: &Pose| body(m * x.position + shift, m * x.orientation);
        let (a2, b2) = (moved(&a), moved(&b));
        let got = carried(&c, &a, &a2, Some((&b, &b2))).unwrap();
        assert!((got.gap - c.gap).abs() < 1e-15, "{} vs {}", got.gap, c.gap);
        assert!((got.normal - m * c.normal).norm() < 1e-14);
        assert!((got.point - (m * c.point + shift)).norm() < 1e-14);
        assert_eq!(got.key, c.key);
        assert!(relative_drift(&b, &b2, Some((&a, &a2)), 0.007) < 1e-14);
    }

    #[test]
    fn a_push_along_the_normal_changes_the_gap_by_its_length() {
        let a = body(Vec3::new(0.0, 0.0, 0.01), Quat::identity());
        let b = body(Vec3::zeros(), Quat::identity());
        let c = pair_contact(&a, &b, Vec3::new(0.0, 0.0, 0.005), Vec3::new(0.0, 0.0, 0.005), Vec3::z(), NormalOwner::B);
        let a2 = body(a.position + Vec3::new(2e-6, -1e-6, 3e-6), Quat::identity());
        let got = carried(&c, &a, &a2, Some((&b, &b))).unwrap();
        assert!((got.gap - 3e-6).abs() < 1e-18);
        let drift = relative_drift(&a, &a2, Some((&b, &b)), 0.007);
        assert!((drift - 14e-12_f64.sqrt()).abs() < 1e-15);
    }

    #[test]
    fn a_point_on_a_turning_sphere_errs_to_second_order() {
        // A's point on a sphere of radius 5 mm resting on B's plane; A turns about the
        // contact's tangent by θ: the carried point rises by r(1 − cos θ) ≈ rθ²/2 while the
        // sphere's true gap stays zero, within the 2δ bound.
        let r = 0.005;
        let a = body(Vec3::new(0.0, 0.0, r), Quat::identity());
        let b = body(Vec3::zeros(), Quat::identity());
        let c = pair_contact(&a, &b, Vec3::zeros(), Vec3::zeros(), Vec3::z(), NormalOwner::B);
        let theta = 1e-4;
        let a2 = body(a.position, Quat::from_euler_angles(theta, 0.0, 0.0));
        let got = carried(&c, &a, &a2, Some((&b, &b))).unwrap();
        let expected = r * (1.0 - theta.cos());
        assert!((got.gap - expected).abs() < 1e-18, "{} vs {}", got.gap, expected);
        assert!(got.gap <= 2.0 * relative_drift(&a, &a2, Some((&b, &b)), r));
    }

    #[test]
    fn a_wall_contact_keeps_the_walls_point_and_normal() {
        let a = body(Vec3::new(0.01, 0.0, 0.005), Quat::identity());
        let pa = Vec3::new(0.01, 0.0, -1e-6);
        let c = Contact {
            a: 0,
            b: Counterpart::Wall(crate::container::WallId::Floor),
            point: Vec3::new(0.01, 0.0, -0.5e-6),
            lever_a: pa - a.position,
            lever_b: Vec3::zeros(),
            normal: Vec3::z(),
            gap: -1e-6,
            kinematics: GapKinematics::Point { owner: NormalOwner::Fixed },
            key: ContactKey { a: 0, b: Counterpart::Wall(crate::container::WallId::Floor), feature: 0 },
        };
        let a2 = body(a.position + Vec3::new(1e-6, 0.0, 4e-6), Quat::identity());
        let got = carried(&c, &a, &a2, None).unwrap();
        assert!((got.gap - 3e-6).abs() < 1e-18);
        assert_eq!(got.normal, Vec3::z());
        assert_eq!(got.lever_b, Vec3::zeros());
    }
}
