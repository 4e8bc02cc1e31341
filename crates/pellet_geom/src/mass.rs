//! Exact mass properties of a closed polyhedron, per unit density.
//!
//! The mesh is split into signed tetrahedra against a reference point and
//! the volume, first and second moments are summed in closed form (the
//! divergence theorem, as in Tonon 2004 / Eberly's "Polyhedral mass
//! properties"). The result is exact for the polyhedron: the only error
//! against the smooth pellet is the faceting of its curved surfaces.

use serde::{Deserialize, Serialize};

use crate::math::{Matrix, Point, Real, Vector};
use crate::mesh::TriMesh;
use crate::GeomError;

/// Volume, area, centroid and inertia of a pellet, per unit density.
///
/// Units are those of the mesh: a mesh in metres gives m³, m², m and
/// m⁵ (inertia per unit density: multiply by the density in kg/m³ to get kg·m²).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MassProperties {
    /// Enclosed volume.
    pub volume: Real,
    /// Surface area.
    pub area: Real,
    /// Centre of volume, in the mesh's frame.
    pub centroid: Point,
    /// Inertia tensor about the centroid per unit density (∫ (|r|²1 − r rᵀ) dV).
    pub inertia: Matrix,
    /// Principal moments per unit density, ascending.
    pub principal_moments: Vector,
    /// Principal axes as the columns of a proper rotation (det = +1),
    /// in the order of `principal_moments`.
    pub principal_axes: Matrix,
    /// Diameter of the sphere of equal volume, dpv = (6V/π)^(1/3).
    pub equivalent_diameter: Real,
    /// Wadell sphericity: area of the equal-volume sphere over the area.
    pub sphericity: Real,
}

impl MassProperties {
    /// Computes the properties of a closed, consistently oriented mesh.
    ///
    /// Fails if the enclosed volume is not positive (an inward-oriented or
    /// degenerate mesh): the caller decides whether to flip it.
    pub fn of_mesh(mesh: &TriMesh) -> Result<Self, GeomError> {
        // A reference point inside the bounding box keeps the tetrahedra small
        // and the sums free of cancellation for meshes far from the origin.
        let reference = mean_vertex(mesh);
        let mut volume6 = 0.0; // 6 × volume
        let mut first = Vector::zeros(); // 24 × first moment
        let mut second = Matrix::zeros(); // 120 × ∫ x xᵀ dV
        for t in 0..mesh.triangles.len() {
            let [a, b, c] = mesh.corners(t);
            let (a, b, c) = (a - reference, b - reference, c - reference);
            let det = a.dot(&b.cross(&c));
            let s = a + b + c;
            volume6 += det;
            first += det * s;
            second += det * (a * a.transpose() + b * b.transpose() + c * c.transpose() + s * s.transpose());
        }
        let volume = volume6 / 6.0;
        if !(volume.is_finite() && volume > 0.0) {
            return Err(GeomError::BadMesh(format!(
                "the mesh encloses a volume of {volume:e} (must be > 0): it is inside-out or degenerate"
            )));
        }
        let centroid_rel = first / 24.0 / volume;
        let covariance = second / 120.0 - volume * centroid_rel * centroid_rel.transpose();
        let inertia = Matrix::identity() * covariance.trace() - covariance;
        let inertia = 0.5 * (inertia + inertia.transpose());
        let (principal_moments, principal_axes) = principal_frame(&inertia);
        let area = mesh.area();
        let equivalent_diameter = (6.0 * volume / std::f64::consts::PI).cbrt();
        let sphericity = std::f64::consts::PI * equivalent_diameter * equivalent_diameter / area;
        Ok(MassProperties {
            volume,
            area,
            centroid: reference + centroid_rel,
            inertia,
            principal_moments,
            principal_axes,
            equivalent_diameter,
            sphericity,
        })
    }
}

fn mean_vertex(mesh: &TriMesh) -> Point {
    let n = mesh.vertices.len().max(1) as Real;
    let sum = mesh.vertices.iter().fold(Vector::zeros(), |acc, v| acc + v.coords);
    Point::from(sum / n)
}

/// Eigen-decomposition of a symmetric inertia tensor: moments ascending,
/// axes as a proper rotation.
fn principal_frame(inertia: &Matrix) -> (Vector, Matrix) {
    let eig = nalgebra::SymmetricEigen::new(*inertia);
    let mut order = [0usize, 1, 2];
    order.sort_by(|&i, &j| eig.eigenvalues[i].total_cmp(&eig.eigenvalues[j]));
    let moments = Vector::new(eig.eigenvalues[order[0]], eig.eigenvalues[order[1]], eig.eigenvalues[order[2]]);
    let mut axes = Matrix::from_columns(&[
        eig.eigenvectors.column(order[0]).into_owned(),
        eig.eigenvectors.column(order[1]).into_owned(),
        eig.eigenvectors.column(order[2]).into_owned(),
    ]);
    if axes.determinant() < 0.0 {
        let flipped = -axes.column(2);
        axes.set_column(2, &flipped);
    }
    (moments, axes)
}
