//! The math types every packbed crate shares: f64 nalgebra aliases.
//!
//! Only this module names nalgebra types directly, so a later switch of the
//! math backend touches one file.

/// The scalar type of all geometry: f64 everywhere.
pub type Real = f64;
/// A 3-vector.
pub type Vector = nalgebra::Vector3<Real>;
/// A point in 3-space.
pub type Point = nalgebra::Point3<Real>;
/// A 3×3 matrix (inertia tensors, rotations).
pub type Matrix = nalgebra::Matrix3<Real>;
/// A 2-vector (cross-sections of extruded shapes).
pub type Vector2 = nalgebra::Vector2<Real>;
/// A unit quaternion (body-to-world rotations).
pub type UnitQuaternion = nalgebra::UnitQuaternion<Real>;

/// `x` for a message: as Rust prints it for everyday magnitudes, in scientific notation far
/// from them, where a damaged file's 1e300 or 1e-300 would print some 300 digits.
pub fn shown(x: Real) -> String {
    if x == 0.0 || !x.is_finite() || (1e-6..1e15).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}
