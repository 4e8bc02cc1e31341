//! The geometry that is exported: each pellet's mesh at its pose, the tube
//! as a closed cylinder, and the choice of pellets by an axial window.

use pellet_geom::math::{Point, Real, Vector};
use pellet_geom::{Bed, Pellet, PlacedPellet, TriMesh};

/// The axial range exported (m): the window if given, else the floor to
/// the top of the bed (its highest pellet point).
pub fn axial_range(bed: &Bed, window: Option<(Real, Real)>) -> (Real, Real) {
    window.unwrap_or_else(|| (0.0, pellet_analysis::bed_top(bed)))
}

/// Indices of the pellets whose centroid lies in `[z0, z1)` (all of them
/// without a window): the pellets to export whole.
pub fn select(bed: &Bed, window: Option<(Real, Real)>) -> Vec<usize> {
    (0..bed.pellets.len())
        .filter(|&i| window.is_none_or(|(z0, z1)| (z0..z1).contains(&bed.pellets[i].position[2])))
        .collect()
}

/// Indices of the pellets with any part strictly between z0 and z1: the
/// pellets to export cut to the window ([`crate::clip::clip_to_slab`]).
pub fn select_overlapping(bed: &Bed, window: (Real, Real)) -> Vec<usize> {
    (0..bed.pellets.len())
        .filter(|&i| {
            let pose = &bed.pellets[i];
            let h = pellet_analysis::half_extent_z(&bed.pellet_types[pose.type_index as usize], pose);
            pose.position[2] + h > window.0 && pose.position[2] - h < window.1
        })
        .collect()
}

/// `pellet`'s mesh placed at `pose` in world coordinates, scaled by
/// `shrink` about its centroid first (1 for none).
pub fn world_mesh(pellet: &Pellet, pose: &PlacedPellet, shrink: Real) -> TriMesh {
    let rotation = pose.rotation();
    let centre = pose.centre();
    TriMesh {
        vertices: pellet.mesh.vertices.iter().map(|v| centre + rotation * (v.coords * shrink)).collect(),
        triangles: pellet.mesh.triangles.clone(),
    }
}

/// The world meshes of the pellets `indices` of `bed`, unscaled.
pub fn world_meshes(bed: &Bed, indices: &[usize]) -> Vec<TriMesh> {
    indices
        .iter()
        .map(|&i| {
            let pose = &bed.pellets[i];
            world_mesh(&bed.pellet_types[pose.type_index as usize], pose, 1.0)
        })
        .collect()
}

/// The tube's inside as a closed cylinder from `z0` to `z1` (m): a prism of
/// `segments` sides whose faces touch the circle of `radius` at their
/// middles (circumscribed), so that no pellet inside the round tube pokes
/// through the polygon; outward normals. The fluid region of a CFD model is
/// this solid minus the pellets.
pub fn tube_mesh(radius: Real, z0: Real, z1: Real, segments: usize) -> TriMesh {
    let n = segments.max(3);
    let corner = radius / (std::f64::consts::PI / n as Real).cos();
    let mut vertices = Vec::with_capacity(2 * n + 2);
    for z in [z0, z1] {
        for k in 0..n {
            // Corners half a step off the x axis, so a face's middle is on it.
            let angle = (k as Real + 0.5) * std::f64::consts::TAU / n as Real;
            vertices.push(Point::new(corner * angle.cos(), corner * angle.sin(), z));
        }
    }
    let (bottom, top) = (2 * n as u32, 2 * n as u32 + 1);
    vertices.push(Point::new(0.0, 0.0, z0));
    vertices.push(Point::new(0.0, 0.0, z1));
    let mut triangles = Vec::with_capacity(4 * n);
    for k in 0..n as u32 {
        let next = (k + 1) % n as u32;
        let (b0, b1, t0, t1) = (k, next, k + n as u32, next + n as u32);
        triangles.push([b0, b1, t1]);
        triangles.push([b0, t1, t0]);
        triangles.push([bottom, b1, b0]);
        triangles.push([top, t0, t1]);
    }
    TriMesh { vertices, triangles }
}

/// Signed volume enclosed by a closed mesh (divergence theorem; positive
/// for outward triangles).
pub fn enclosed_volume(mesh: &TriMesh) -> Real {
    (0..mesh.face_count())
        .map(|t| {
            let [a, b, c] = mesh.corners(t);
            a.coords.dot(&b.coords.cross(&c.coords)) / 6.0
        })
        .sum()
}

/// Unit vector from the tube axis towards `p` in the xy plane (x if `p` is on the axis).
pub fn radial_direction(p: &Point) -> Vector {
    let rho = p.x.hypot(p.y);
    if rho > 0.0 {
        Vector::new(p.x / rho, p.y / rho, 0.0)
    } else {
        Vector::x()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tube_is_closed_outward_and_contains_the_circle() {
        let mesh = tube_mesh(0.02, 0.0, 0.05, 64);
        let topology = mesh.check_closed().unwrap();
        assert_eq!(topology.components, 1);
        let volume = enclosed_volume(&mesh);
        let circle = std::f64::consts::PI * 0.02 * 0.02 * 0.05;
        // A circumscribed 64-gon is 0.08 % larger than the circle.
        assert!(volume > circle && volume < circle * 1.001, "{volume} vs {circle}");
        // The face middles touch the circle.
        let mid = (mesh.vertices[0].coords + mesh.vertices[63].coords) * 0.5;
        assert!((mid.xy().norm() - 0.02).abs() < 1e-12);
    }
}
