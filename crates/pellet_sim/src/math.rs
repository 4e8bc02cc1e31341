//! Type aliases for the small-vector maths used throughout the engine (f64 everywhere).

/// Scalar type.
pub type Real = f64;
/// 3-vector (positions in m, velocities in m/s, ...).
pub type Vec3 = nalgebra::Vector3<Real>;
/// 3×3 matrix (inertia tensors, collision matrices).
pub type Mat3 = nalgebra::Matrix3<Real>;
/// Unit quaternion (body orientation, body frame → world frame).
pub type Quat = nalgebra::UnitQuaternion<Real>;

/// Standard gravity used by the default parameters, m/s².
pub const STANDARD_GRAVITY: Real = 9.81;

/// Cross-product matrix `[r]×`, so that `skew(r) * y == r.cross(&y)`.
pub fn skew(r: &Vec3) -> Mat3 {
    Mat3::new(0.0, -r.z, r.y, r.z, 0.0, -r.x, -r.y, r.x, 0.0)
}

/// The angle of the rotation from `then` to `now`, rad, as 2 atan2(|v|, |w|) of the relative
/// quaternion: `UnitQuaternion::angle`'s 2 acos|w| calls a turn of 1e-8 rad (a bed at rest, one
/// substep) zero, because |w| = 1 − θ²/8 rounds to 1.
pub fn turn_angle(now: &Quat, then: &Quat) -> Real {
    let q = (now * then.inverse()).into_inner();
    2.0 * q.imag().norm().atan2(q.w.abs())
}

/// √(x² + y²), the distance from the axis in the hot geometry paths. `f64::hypot` (glibc)
/// guards against overflow and underflow that lengths in metres never reach, and was 15–20 % of
/// a cylinder pour's time in perf; this is within an ulp or two of it.
#[inline]
pub fn axial_distance(x: Real, y: Real) -> Real {
    (x * x + y * y).sqrt()
}
