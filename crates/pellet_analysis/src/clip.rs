//! The volume of a placed pellet between two horizontal planes, exactly.
//!
//! For the sphere, the cylinder and the hollow cylinder the volume on one
//! side of a plane has a closed form (spherical caps; for the cylinder the
//! integral of circular-segment areas along the axis, whose antiderivative
//! is elementary). For a mesh, the triangles are clipped to the slab and
//! the divergence theorem is applied with the field ½(x − cx, y − cy, 0):
//! its divergence is 1 and its flux through the horizontal cut faces is
//! zero, so the caps of the clipped solid never need to be built.

use pellet_geom::math::{Real, Vector};
use pellet_geom::{ClosedForm, Pellet, PlacedPellet};

use crate::line::Geometry;

/// Volume of `pellet` placed at `pose` with world `z0 ≤ z ≤ z1` (m³).
pub fn volume_in_slab(pellet: &Pellet, pose: &PlacedPellet, z0: Real, z1: Real, geometry: Geometry) -> Real {
    if z1 <= z0 {
        return 0.0;
    }
    let closed = match geometry {
        Geometry::Auto => pellet.closed_form,
        Geometry::Mesh => None,
    };
    match closed {
        Some(shape) => volume_above(&shape, pose, z0) - volume_above(&shape, pose, z1),
        None => mesh_volume_in_slab(pellet, pose, z0, z1),
    }
}

/// Volume of a closed-form shape at `pose` with world z ≥ `z` (m³).
fn volume_above(shape: &ClosedForm, pose: &PlacedPellet, z: Real) -> Real {
    let c = z - pose.position[2];
    match *shape {
        ClosedForm::Sphere { radius } => sphere_above(radius, c),
        ClosedForm::Cylinder { radius, half_height } => cylinder_above(radius, half_height, &pose.axis(), c),
        ClosedForm::HollowCylinder { inner_radius, outer_radius, half_height } => {
            let axis = pose.axis();
            cylinder_above(outer_radius, half_height, &axis, c) - cylinder_above(inner_radius, half_height, &axis, c)
        }
    }
}

/// Volume of a sphere of `radius` about the origin with z ≥ `c`: a cap.
pub fn sphere_above(radius: Real, c: Real) -> Real {
    let h = (radius - c).clamp(0.0, 2.0 * radius);
    std::f64::consts::PI * h * h * (3.0 * radius - h) / 3.0
}

/// Volume of a cylinder (radius, half-height, centred on the origin, axis
/// along the unit vector `axis`) with world z ≥ `c`.
pub fn cylinder_above(radius: Real, half_height: Real, axis: &Vector, c: Real) -> Real {
    // In the cylinder's frame the plane is a·u + b·s = c, with s along the
    // axis and u the radial direction towards world z.
    let b = axis.z.clamp(-1.0, 1.0);
    let a = (1.0 - b * b).max(0.0).sqrt();
    let area = std::f64::consts::PI * radius * radius;
    if a < 1e-9 {
        // Upright: the part of [−h, h] with b·s ≥ c.
        let (lo, hi) = if b > 0.0 { (c / b, half_height) } else { (-half_height, c / b) };
        return area * (hi.min(half_height) - lo.max(-half_height)).max(0.0);
    }
    let w = |s: Real| (c - b * s) / a;
    if b.abs() < 1e-7 {
        // Lying: the segment is the same all along the axis.
        return 2.0 * half_height * segment_area(radius, w(0.0));
    }
    a / b * (segment_integral(radius, w(-half_height)) - segment_integral(radius, w(half_height)))
}

/// Area of the part of a disk of `radius` with u ≥ `w`.
fn segment_area(radius: Real, w: Real) -> Real {
    if w <= -radius {
        std::f64::consts::PI * radius * radius
    } else if w >= radius {
        0.0
    } else {
        radius * radius * (w / radius).acos() - w * (radius * radius - w * w).sqrt()
    }
}

/// An antiderivative of [`segment_area`] in `w`, zero for w ≥ radius.
fn segment_integral(radius: Real, w: Real) -> Real {
    let r2 = radius * radius;
    if w <= -radius {
        std::f64::consts::PI * r2 * w
    } else if w >= radius {
        0.0
    } else {
        let root = (r2 - w * w).sqrt();
        r2 * w * (w / radius).acos() - r2 * root + root * root * root / 3.0
    }
}

/// Volume of the pellet's mesh between the planes, by clipping its triangles.
fn mesh_volume_in_slab(pellet: &Pellet, pose: &PlacedPellet, z0: Real, z1: Real) -> Real {
    let centre = pose.centre();
    let rotation = pose.rotation();
    let world: Vec<Vector> = pellet.mesh.vertices.iter().map(|v| rotation * v.coords).collect();
    let (cz, mut total) = (centre.z, 0.0);
    let (lo, hi) = (z0 - cz, z1 - cz);
    let mut poly: Vec<Vector> = Vec::with_capacity(8);
    let mut next: Vec<Vector> = Vec::with_capacity(8);
    for t in &pellet.mesh.triangles {
        let corners = t.map(|i| world[i as usize]);
        let (zmin, zmax) =
            corners.iter().fold((Real::INFINITY, Real::NEG_INFINITY), |(a, b), p| (a.min(p.z), b.max(p.z)));
        if zmax <= lo || zmin >= hi {
            continue;
        }
        poly.clear();
        poly.extend_from_slice(&corners);
        if zmin < lo {
            clip(&poly, &mut next, |p| p.z - lo);
            std::mem::swap(&mut poly, &mut next);
        }
        if zmax > hi {
            clip(&poly, &mut next, |p| hi - p.z);
            std::mem::swap(&mut poly, &mut next);
        }
        for k in 1..poly.len().saturating_sub(1) {
            let (p0, p1, p2) = (poly[0], poly[k], poly[k + 1]);
            let area = 0.5 * (p1 - p0).cross(&(p2 - p0));
            let g = (p0 + p1 + p2) / 3.0;
            total += 0.5 * (area.x * g.x + area.y * g.y);
        }
    }
    total
}

/// Sutherland–Hodgman: the part of the convex polygon where `keep(p) ≥ 0`.
fn clip(input: &[Vector], out: &mut Vec<Vector>, keep: impl Fn(&Vector) -> Real) {
    out.clear();
    for (k, p) in input.iter().enumerate() {
        let q = &input[(k + 1) % input.len()];
        let (fp, fq) = (keep(p), keep(q));
        if fp >= 0.0 {
            out.push(*p);
        }
        if (fp >= 0.0) != (fq >= 0.0) {
            out.push(p + (q - p) * (fp / (fp - fq)));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pellet_geom::{Resolution, ShapeSpec};

    fn tilted(angle: Real) -> PlacedPellet {
        let (s, c) = (0.5 * angle).sin_cos();
        PlacedPellet { type_index: 0, position: [0.0, 0.0, 0.01], orientation: [c, s, 0.0, 0.0] }
    }

    #[test]
    fn closed_form_slab_volumes_match_the_clipped_fine_mesh() {
        let specs = [
            ShapeSpec::Sphere { diameter_mm: 10.0 },
            ShapeSpec::Cylinder { diameter_mm: 10.0, height_mm: 8.0 },
            ShapeSpec::Ring { outer_diameter_mm: 10.0, inner_diameter_mm: 6.0, height_mm: 10.0 },
        ];
        for spec in specs {
            let fine = Pellet::build(spec.clone(), Resolution { level: 3, faces: None }).unwrap();
            for angle in [0.0, 0.3, 1.0, std::f64::consts::FRAC_PI_2, 2.5] {
                let pose = tilted(angle);
                for (z0, z1) in [(0.0, 0.02), (0.0085, 0.02), (0.0, 0.0101), (0.007, 0.0123)] {
                    let exact = volume_in_slab(&fine, &pose, z0, z1, Geometry::Auto);
                    let mesh = volume_in_slab(&fine, &pose, z0, z1, Geometry::Mesh);
                    let scale = fine.properties.volume;
                    assert!(
                        (exact - mesh).abs() < 2e-3 * scale,
                        "{} at {angle} rad, [{z0}, {z1}]: closed form {exact:e}, mesh {mesh:e}",
                        spec.kind()
                    );
                }
            }
            // The whole pellet: the mesh clip gives the mesh's own volume.
            let whole = volume_in_slab(&fine, &tilted(0.7), -1.0, 1.0, Geometry::Mesh);
            assert!((whole / fine.properties.volume - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn cylinder_segments_integrate_to_the_cylinder() {
        let axis = Vector::new(0.6, 0.0, 0.8);
        let full = cylinder_above(1.0, 2.0, &axis, -10.0);
        assert!((full - 4.0 * std::f64::consts::PI).abs() < 1e-12, "{full}");
        // Symmetry: the plane through the centre halves it.
        assert!((cylinder_above(1.0, 2.0, &axis, 0.0) - 2.0 * std::f64::consts::PI).abs() < 1e-12);
        assert_eq!(cylinder_above(1.0, 2.0, &axis, 10.0), 0.0);
        assert!((sphere_above(1.0, 0.0) - 2.0 * std::f64::consts::PI / 3.0).abs() < 1e-15);
    }
}
