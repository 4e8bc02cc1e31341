//! Rigid-body state (x, q, P, L) and the quantities derived from it.

use crate::math::{Mat3, Quat, Real, Vec3};
use serde::{Deserialize, Serialize};

/// Index of a body in its world.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub struct BodyId(pub u32);

/// Index of a registered body type.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub struct TypeId(pub u32);

/// One dynamic pellet. Mass data are copied from its type and material at creation so that the
/// hot loops need no lookups.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Body {
    /// Registered type.
    pub type_id: TypeId,
    /// Centre of mass, m.
    pub position: Vec3,
    /// Orientation (body → world), kept unit by renormalisation every step.
    pub orientation: Quat,
    /// Linear momentum P, kg·m/s.
    pub linear_momentum: Vec3,
    /// Angular momentum L about the centre of mass, world frame, kg·m²/s.
    pub angular_momentum: Vec3,
    /// Mass, kg.
    pub mass: Real,
    /// Body-frame inertia about the centre of mass, kg·m².
    pub inertia_body: Mat3,
    /// Its inverse.
    pub inv_inertia_body: Mat3,
    /// Bounding radius about the centre of mass, m.
    pub bounding_radius: Real,
}

impl Body {
    /// Inverse mass, 1/kg.
    pub fn inv_mass(&self) -> Real {
        1.0 / self.mass
    }

    /// Linear velocity v = P/m.
    pub fn velocity(&self) -> Vec3 {
        self.linear_momentum / self.mass
    }

    /// World inverse inertia R Ib⁻¹ Rᵀ.
    pub fn inv_inertia_world(&self) -> Mat3 {
        rotated(&self.inv_inertia_body, &self.orientation)
    }

    /// World inertia R Ib Rᵀ.
    pub fn inertia_world(&self) -> Mat3 {
        rotated(&self.inertia_body, &self.orientation)
    }

    /// Angular velocity ω = I⁻¹ L.
    pub fn angular_velocity(&self) -> Vec3 {
        self.inv_inertia_world() * self.angular_momentum
    }

    /// Velocity of the material point at world position `p`.
    pub fn point_velocity(&self, p: &Vec3) -> Vec3 {
        self.velocity() + self.angular_velocity().cross(&(p - self.position))
    }

    /// Translational kinetic energy ½ P²/m, J.
    pub fn kinetic_translational(&self) -> Real {
        0.5 * self.linear_momentum.norm_squared() / self.mass
    }

    /// Rotational kinetic energy ½ Lᵀ I⁻¹ L, J.
    pub fn kinetic_rotational(&self) -> Real {
        0.5 * self.angular_momentum.dot(&self.angular_velocity())
    }

    /// Potential energy −m g·x relative to the origin, J.
    pub fn potential(&self, gravity: &Vec3) -> Real {
        -self.mass * gravity.dot(&self.position)
    }

    /// Applies impulse `j` at world point `p` (momentum form: P and L change).
    pub fn apply_impulse(&mut self, j: &Vec3, p: &Vec3) {
        self.linear_momentum += j;
        self.angular_momentum += (p - self.position).cross(j);
    }

    /// Applies impulse `j` at lever arm `r` from the centre of mass.
    pub fn apply_impulse_at_lever(&mut self, j: &Vec3, r: &Vec3) {
        self.linear_momentum += j;
        self.angular_momentum += r.cross(j);
    }

    /// True if every state component is finite.
    pub fn is_finite(&self) -> bool {
        self.position.iter().all(|v| v.is_finite())
            && self.orientation.coords.iter().all(|v| v.is_finite())
            && self.linear_momentum.iter().all(|v| v.is_finite())
            && self.angular_momentum.iter().all(|v| v.is_finite())
    }
}

/// R m Rᵀ for the rotation of `q`; an isotropic m (c·1, a sphere's inertia) is returned as it
/// is, which R c·1 Rᵀ equals but for round-off. Why: this product was 3.7 % of a 690-sphere
/// bed's CPU time (perf), as ω = I⁻¹L is needed at every contact.
fn rotated(m: &Mat3, q: &Quat) -> Mat3 {
    if *m == Mat3::from_diagonal_element(m[(0, 0)]) {
        return *m;
    }
    let r = q.to_rotation_matrix();
    r.matrix() * m * r.matrix().transpose()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn body(inertia: Mat3) -> Body {
        Body {
            type_id: TypeId(0),
            position: Vec3::zeros(),
            orientation: Quat::from_euler_angles(0.3, -1.1, 2.0),
            linear_momentum: Vec3::zeros(),
            angular_momentum: Vec3::new(1e-6, -2e-6, 3e-6),
            mass: 1e-3,
            inertia_body: inertia,
            inv_inertia_body: inertia.try_inverse().unwrap(),
            bounding_radius: 5e-3,
        }
    }

    /// The isotropic shortcut agrees with R I Rᵀ to round-off; other tensors are rotated.
    #[test]
    fn world_inertia_is_r_i_rt() {
        for inertia in [Mat3::from_diagonal_element(1e-8), Mat3::from_diagonal(&Vec3::new(1e-8, 1.2e-8, 0.8e-8))] {
            let b = body(inertia);
            let r = *b.orientation.to_rotation_matrix().matrix();
            let want = r * b.inv_inertia_body * r.transpose();
            assert!((b.inv_inertia_world() - want).norm() <= 1e-12 * want.norm(), "{inertia}");
            assert!((b.inertia_world() - r * inertia * r.transpose()).norm() <= 1e-12 * inertia.norm());
            let l = b.angular_momentum;
            assert!((b.angular_velocity() - want * l).norm() <= 1e-12 * (want * l).norm());
        }
    }
}
