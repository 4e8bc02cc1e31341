//! The contact point record shared by the narrow phase and the dynamics.

use crate::container::WallId;
use crate::math::{Real, Vec3};
use serde::{Deserialize, Serialize};

/// The other side of a contact.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
pub enum Counterpart {
    /// Another dynamic body (index).
    Body(usize),
    /// A static wall.
    Wall(WallId),
}

/// How the second time derivative of the gap is formed (the b of the resting LCP).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum GapKinematics {
    /// Exact sphere–sphere gap |x_A − x_B| − R_A − R_B (centre distance given).
    SphereSphere {
        /// Centre distance, m.
        distance: Real,
    },
    /// Sphere on a fixed plane: the gap is affine in the centre, no curvature term.
    SpherePlane,
    /// Sphere inside the tube: the gap is R_t − ρ − R, ρ the centre's distance from the axis.
    SphereTube {
        /// The centre's distance from the axis, m.
        rho: Real,
    },
    /// A body-fixed point on a face whose normal is fixed in `owner`: the vertex–face form,
    /// b = n·(ā_A(r_A) − ā_B(r_B)) + 2 ṅ·(ṗ_A − ṗ_B) with ṅ = ω_owner × n.
    /// For points on curved faces (lateral surfaces) this leaves out the O(|u_t|²/ρ) curvature
    /// term, second order in the slip speed; post-stabilisation removes what is left.
    Point {
        /// The body the normal is attached to.
        owner: NormalOwner,
    },
    /// A body-fixed point of A against the tube wall: b = n·ā_A(r_A) − |ṗ_⊥|²/ρ, exact for a
    /// point moving on the (concave) cylinder wall.
    PointTube {
        /// The point's distance from the axis, m.
        rho: Real,
    },
}

/// Which body carries a contact normal (its time derivative is ω_owner × n).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum NormalOwner {
    /// Body A.
    A,
    /// Body B.
    B,
    /// A static wall (ṅ = 0).
    Fixed,
}

/// Persistent identity of a contact point, for warm starting.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
pub struct ContactKey {
    /// Body A.
    pub a: u32,
    /// Body B or wall.
    pub b: Counterpart,
    /// Feature / sample index within the pair.
    pub feature: u32,
}

/// One contact point. The normal points from B into A; `gap` < 0 means penetration.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Contact {
    /// Body A (dynamic).
    pub a: usize,
    /// Body B or a wall.
    pub b: Counterpart,
    /// Contact point (midway across the gap), world frame.
    pub point: Vec3,
    /// Lever arm from A's centre of mass to A's surface point, world frame.
    pub lever_a: Vec3,
    /// Lever arm from B's centre of mass to B's surface point (zero for walls), world frame.
    pub lever_b: Vec3,
    /// Unit normal from B into A.
    pub normal: Vec3,
    /// Signed gap, m.
    pub gap: Real,
    /// Gap kinematics for the resting-contact right-hand side.
    pub kinematics: GapKinematics,
    /// Persistent key.
    pub key: ContactKey,
}

impl Contact {
    /// A contact of key `key` with nothing but its bodies and key set (zero geometry, normal +z):
    /// for tests of what only looks at who touches whom.
    #[cfg(test)]
    pub(crate) fn bare(key: ContactKey) -> Self {
        Self {
            a: key.a as usize,
            b: key.b,
            point: Vec3::zeros(),
            lever_a: Vec3::zeros(),
            lever_b: Vec3::zeros(),
            normal: Vec3::z(),
            gap: 0.0,
            kinematics: GapKinematics::SpherePlane,
            key,
        }
    }

    /// Index of body B if it is dynamic.
    pub fn b_body(&self) -> Option<usize> {
        match self.b {
            Counterpart::Body(j) => Some(j),
            Counterpart::Wall(_) => None,
        }
    }
}
