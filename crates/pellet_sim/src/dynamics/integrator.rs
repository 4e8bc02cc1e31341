//! The paper's midpoint rule with quaternion renormalisation, and rotation sub-stepping so that
//! |ω|·δt stays small.

use crate::body::Body;
use crate::math::{Quat, Real, Vec3};
use nalgebra::Quaternion;

/// Time derivative of the orientation, q̇ = ½ (0, ω) ⊗ q.
fn quat_rate(q: &Quaternion<Real>, omega: &Vec3) -> Quaternion<Real> {
    Quaternion::from_imag(*omega) * q * 0.5
}

/// One midpoint step of length `dt` under a constant force and torque.
///
/// Because the force is constant, the translation is exact; only rotation carries error.
pub fn midpoint_step(body: &mut Body, force: &Vec3, torque: &Vec3, dt: Real) {
    let m = body.mass;
    let q0 = *body.orientation.quaternion();
    let omega0 = body.angular_velocity();
    let p_mid = body.linear_momentum + force * (0.5 * dt);
    let l_mid = body.angular_momentum + torque * (0.5 * dt);
    let q_mid = Quat::new_normalize(q0 + quat_rate(&q0, &omega0) * (0.5 * dt));
    let r_mid = q_mid.to_rotation_matrix();
    let omega_mid = r_mid.matrix() * body.inv_inertia_body * r_mid.matrix().transpose() * l_mid;
    body.position += p_mid * (dt / m);
    body.orientation = Quat::new_normalize(q0 + quat_rate(q_mid.quaternion(), &omega_mid) * dt);
    body.linear_momentum += force * dt;
    body.angular_momentum += torque * dt;
}

/// Advances over `dt` with as many midpoint steps as needed to keep |ω|·δt ≤ `max_rot`.
/// Returns the number of steps taken.
pub fn advance(body: &mut Body, force: &Vec3, torque: &Vec3, dt: Real, max_rot: Real) -> u32 {
    // Bound |ω| over the step: ω changes by at most |I⁻¹| |τ| dt.
    let inv_i = body.inv_inertia_world();
    let w_bound = body.angular_velocity().norm() + inv_i.norm() * torque.norm() * dt;
    let n = ((w_bound * dt / max_rot).ceil() as u64).clamp(1, 1_000_000) as u32;
    if n == 1 {
        midpoint_step(body, force, torque, dt);
        return 1;
    }
    // Translation is integrated once, exactly, so that splitting does not add round-off.
    let x_end = body.position + body.linear_momentum * (dt / body.mass) + force * (0.5 * dt * dt / body.mass);
    let p_end = body.linear_momentum + force * dt;
    let h = dt / n as Real;
    for _ in 0..n {
        midpoint_step(body, force, torque, h);
    }
    body.position = x_end;
    body.linear_momentum = p_end;
    n
}
