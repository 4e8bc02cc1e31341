//! Control mesh of a sphere: the convex hull of a spherical Fibonacci
//! point set.
//!
//! n Fibonacci points (n even, mirrored through the centre) are spread almost uniformly over the sphere; their
//! hull is a near-Delaunay triangulation with exactly 2n − 4 faces, so any
//! face count can be approached (an icosahedral start only gives
//! 20·ν²·4^k). Loop subdivision with projection then refines it:
//! faces = (2n − 4)·4^level.

use crate::math::{Point, Real};
use crate::parry_boundary;
use crate::subdivision::FeatureMesh;
use crate::surface::Surface;
use crate::GeomError;

/// Fewest control points: an octahedron-like start.
pub const MIN_POINTS: usize = 12;

/// Face count of the control mesh of `points` points.
pub fn control_faces(points: usize) -> usize {
    2 * points.max(MIN_POINTS).next_multiple_of(2) - 4
}

/// The control mesh of a sphere of radius `radius` from `points` points.
pub fn control_mesh(radius: Real, points: usize) -> Result<FeatureMesh, GeomError> {
    // An even count, mirrored through the centre: the hull is centrally
    // symmetric, so its centroid is the sphere's centre.
    let n = points.max(MIN_POINTS).next_multiple_of(2);
    let golden_angle = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let upper: Vec<Point> = (0..n / 2)
        .map(|i| {
            let z = 1.0 - (2 * i + 1) as Real / n as Real;
            let rho = (1.0 - z * z).sqrt();
            let a = golden_angle * i as Real;
            Point::new(radius * rho * a.cos(), radius * rho * a.sin(), radius * z)
        })
        .collect();
    let pts: Vec<Point> = upper.iter().copied().chain(upper.iter().map(|p| -p)).collect();
    let hull = parry_boundary::convex_hull(&pts)?;
    if hull.vertices.len() != n || hull.face_count() != control_faces(n) {
        return Err(GeomError::Meshing(format!(
            "the sphere's control hull has {} vertices and {} faces, expected {n} and {}",
            hull.vertices.len(),
            hull.face_count(),
            control_faces(n)
        )));
    }
    Ok(FeatureMesh { face_surface: vec![0; hull.face_count()], mesh: hull, surfaces: vec![Surface::Sphere { radius }] })
}
