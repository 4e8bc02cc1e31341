//! Closed-form signed distances of the paper's three pellet shapes
//! (`docs/engine.md`, "Contact generation"): the engine's fast path.
//!
//! Body frame: origin at the centroid, axis along z. Negative inside,
//! exact Euclidean distance on both sides, 1-Lipschitz.

use serde::{Deserialize, Serialize};

use crate::math::{Point, Real, Vector2};

/// A pellet shape that has an exact signed-distance function. Lengths in metres.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum ClosedForm {
    /// A sphere.
    Sphere {
        /// Radius (m).
        radius: Real,
    },
    /// A solid cylinder.
    Cylinder {
        /// Radius (m).
        radius: Real,
        /// Half of the height (m).
        half_height: Real,
    },
    /// A hollow cylinder (Raschig ring).
    HollowCylinder {
        /// Radius of the hole (m).
        inner_radius: Real,
        /// Outer radius (m).
        outer_radius: Real,
        /// Half of the height (m).
        half_height: Real,
    },
}

/// `sd(q) = min(max(q₁, q₂), 0) + ‖max(q, 0)‖`: the signed distance to a
/// 2-D rectangle corner region, the core of the cylinder SDFs.
fn sd_box2(q: Vector2) -> Real {
    q.x.max(q.y).min(0.0) + Vector2::new(q.x.max(0.0), q.y.max(0.0)).norm()
}

impl ClosedForm {
    /// Signed distance from the surface to `p` (body frame): < 0 inside.
    pub fn signed_distance(&self, p: &Point) -> Real {
        let rho = p.x.hypot(p.y);
        match *self {
            ClosedForm::Sphere { radius } => p.coords.norm() - radius,
            ClosedForm::Cylinder { radius, half_height } => {
                sd_box2(Vector2::new(rho - radius, p.z.abs() - half_height))
            }
            ClosedForm::HollowCylinder { inner_radius, outer_radius, half_height } => {
                let mid = 0.5 * (inner_radius + outer_radius);
                let half_wall = 0.5 * (outer_radius - inner_radius);
                sd_box2(Vector2::new((rho - mid).abs() - half_wall, p.z.abs() - half_height))
            }
        }
    }

    /// Radius of the smallest centroid-centred sphere enclosing the shape.
    pub fn bounding_radius(&self) -> Real {
        match *self {
            ClosedForm::Sphere { radius } => radius,
            ClosedForm::Cylinder { radius, half_height } => radius.hypot(half_height),
            ClosedForm::HollowCylinder { outer_radius, half_height, .. } => outer_radius.hypot(half_height),
        }
    }
}
