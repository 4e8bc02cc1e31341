//! Where a vertical world line `(x, y, z)` runs inside one placed pellet.
//!
//! The radial void fraction is an integral of these lengths, so they are
//! computed exactly in z: in closed form for the sphere, the cylinder and
//! the hollow cylinder, and for every other shape from the crossings of the
//! line with the pellet's triangle mesh ([`crate::raster::MeshRaster`]).

use pellet_geom::math::{Real, Vector};
use pellet_geom::{ClosedForm, Pellet, PlacedPellet};

use crate::raster::MeshRaster;

/// How the intersections are computed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Geometry {
    /// The exact shape where the pellet has a closed form, else its mesh.
    #[default]
    Auto,
    /// Always the triangle mesh (what a CFD mesher would see).
    Mesh,
}

/// One pellet, placed, ready to answer line queries.
pub struct LineCaster {
    /// World centroid (m).
    centre: Vector,
    /// Rows of the world→body rotation, so `body = rot · (world − centre)`.
    world_to_body: [Vector; 3],
    kind: Kind,
    /// Radius of the pellet's footprint on the xy plane, from its centroid (m).
    footprint: Real,
    /// Half of the pellet's extent along world z (m).
    half_extent_z: Real,
}

enum Kind {
    Sphere { radius: Real },
    Cylinder { radius: Real, half_height: Real },
    Ring { inner: Real, outer: Real, half_height: Real },
    Mesh(Box<MeshRaster>),
}

impl LineCaster {
    /// Prepares `pellet` placed at `pose` for line queries.
    pub fn new(pellet: &Pellet, pose: &PlacedPellet, geometry: Geometry) -> LineCaster {
        let rotation = pose.rotation().to_rotation_matrix();
        let m = rotation.matrix();
        // Rows of Rᵀ are the columns of R.
        let world_to_body = [m.column(0).into_owned(), m.column(1).into_owned(), m.column(2).into_owned()];
        let axis_world = m.column(2).into_owned();
        let closed = match geometry {
            Geometry::Auto => pellet.closed_form,
            Geometry::Mesh => None,
        };
        let (kind, footprint, half_extent_z) = match closed {
            Some(ClosedForm::Sphere { radius }) => (Kind::Sphere { radius }, radius, radius),
            Some(ClosedForm::Cylinder { radius, half_height }) => {
                let (fp, hz) = cylinder_extent(&axis_world, radius, half_height);
                (Kind::Cylinder { radius, half_height }, fp, hz)
            }
            Some(ClosedForm::HollowCylinder { inner_radius, outer_radius, half_height }) => {
                let (fp, hz) = cylinder_extent(&axis_world, outer_radius, half_height);
                (Kind::Ring { inner: inner_radius, outer: outer_radius, half_height }, fp, hz)
            }
            None => {
                let down = Vector::new(world_to_body[0].z, world_to_body[1].z, world_to_body[2].z);
                let raster = MeshRaster::new(&pellet.mesh, &down);
                let (fp, hz) = (raster.footprint(), raster.half_extent());
                (Kind::Mesh(Box::new(raster)), fp, hz)
            }
        };
        LineCaster { centre: pose.centre().coords, world_to_body, kind, footprint, half_extent_z }
    }

    /// World centroid (m).
    pub fn centre(&self) -> Vector {
        self.centre
    }

    /// Radius about the centroid, in the xy plane, outside which no vertical line meets the pellet (m).
    pub fn footprint(&self) -> Real {
        self.footprint
    }

    /// The pellet lies within `centre.z ± half_extent_z` (m).
    pub fn half_extent_z(&self) -> Real {
        self.half_extent_z
    }

    /// Appends to `out` the world-z intervals `(z_lo, z_hi)` where the line
    /// through `(x, y)` parallel to z runs inside the pellet.
    pub fn intervals(&self, x: Real, y: Real, out: &mut Vec<(Real, Real)>) {
        let (dx, dy) = (x - self.centre.x, y - self.centre.y);
        let cz = self.centre.z;
        match self.kind {
            Kind::Sphere { radius } => {
                let h2 = radius * radius - dx * dx - dy * dy;
                if h2 > 0.0 {
                    let h = h2.sqrt();
                    out.push((cz - h, cz + h));
                }
            }
            Kind::Cylinder { radius, half_height } => {
                let line = self.body_line(dx, dy);
                if let Some(slab) = line.slab(half_height) {
                    if let Some((a, b)) = line.radial(radius) {
                        push_clipped(out, a.max(slab.0), b.min(slab.1), cz);
                    }
                }
            }
            Kind::Ring { inner, outer, half_height } => {
                let line = self.body_line(dx, dy);
                let (Some(slab), Some((a, b))) = (line.slab(half_height), line.radial(outer)) else {
                    return;
                };
                let (a, b) = (a.max(slab.0), b.min(slab.1));
                match line.radial(inner) {
                    // The hole splits the outer interval in two.
                    Some((ia, ib)) => {
                        push_clipped(out, a, b.min(ia), cz);
                        push_clipped(out, a.max(ib), b, cz);
                    }
                    None => push_clipped(out, a, b, cz),
                }
            }
            Kind::Mesh(ref raster) => {
                let line = self.body_line(dx, dy);
                raster.intervals(&line.origin, cz, out);
            }
        }
    }

    /// The world line through `(centre.x + dx, centre.y + dy)` in the body
    /// frame, parametrised by `s = z − centre.z`.
    fn body_line(&self, dx: Real, dy: Real) -> BodyLine {
        let w = &self.world_to_body;
        BodyLine {
            origin: Vector::new(w[0].x * dx + w[0].y * dy, w[1].x * dx + w[1].y * dy, w[2].x * dx + w[2].y * dy),
            direction: Vector::new(w[0].z, w[1].z, w[2].z),
        }
    }
}

/// Footprint radius and half z-extent of a cylinder of `radius` and
/// `half_height` whose axis points along the unit vector `axis`.
fn cylinder_extent(axis: &Vector, radius: Real, half_height: Real) -> (Real, Real) {
    let sin_tilt = axis.x.hypot(axis.y).min(1.0);
    let cos_tilt = axis.z.abs().min(1.0);
    // The farthest rim point in xy: the disk contributes `radius`, the axis `half_height · sin`.
    (radius + half_height * sin_tilt, half_height * cos_tilt + radius * sin_tilt)
}

fn push_clipped(out: &mut Vec<(Real, Real)>, a: Real, b: Real, offset: Real) {
    if b > a {
        out.push((a + offset, b + offset));
    }
}

/// `origin + s · direction` in the body frame (`direction` is a unit vector).
struct BodyLine {
    origin: Vector,
    direction: Vector,
}

impl BodyLine {
    /// The `s` range where `|z_body| ≤ half_height`.
    fn slab(&self, half_height: Real) -> Option<(Real, Real)> {
        let (oz, dz) = (self.origin.z, self.direction.z);
        if dz.abs() < 1e-12 {
            return (oz.abs() <= half_height).then_some((Real::NEG_INFINITY, Real::INFINITY));
        }
        let (a, b) = ((-half_height - oz) / dz, (half_height - oz) / dz);
        Some(if a <= b { (a, b) } else { (b, a) })
    }

    /// The `s` range where `x_body² + y_body² ≤ radius²`.
    fn radial(&self, radius: Real) -> Option<(Real, Real)> {
        let (o, d) = (&self.origin, &self.direction);
        let a = d.x * d.x + d.y * d.y;
        let half_b = o.x * d.x + o.y * d.y;
        let c = o.x * o.x + o.y * o.y - radius * radius;
        if a < 1e-24 {
            // The line runs parallel to the axis: inside everywhere or nowhere.
            return (c < 0.0).then_some((Real::NEG_INFINITY, Real::INFINITY));
        }
        let disc = half_b * half_b - a * c;
        if disc <= 0.0 {
            return None;
        }
        // The cancellation-free pair of roots.
        let q = -(half_b + half_b.signum() * disc.sqrt());
        let (r1, r2) = if q == 0.0 { (-disc.sqrt() / a, disc.sqrt() / a) } else { (q / a, c / q) };
        Some(if r1 <= r2 { (r1, r2) } else { (r2, r1) })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pellet_geom::{Resolution, ShapeSpec};

    fn pose(p: [Real; 3], q: [Real; 4]) -> PlacedPellet {
        PlacedPellet { type_index: 0, position: p, orientation: q }
    }

    #[test]
    fn standing_and_lying_cylinders_give_their_exact_chords() {
        let cyl =
            Pellet::build(ShapeSpec::Cylinder { diameter_mm: 10.0, height_mm: 10.0 }, Resolution::default()).unwrap();
        let mut out = Vec::new();
        let standing = LineCaster::new(&cyl, &pose([0.01, 0.0, 0.02], [1.0, 0.0, 0.0, 0.0]), Geometry::Auto);
        standing.intervals(0.012, 0.001, &mut out);
        assert_eq!(out.len(), 1);
        assert!((out[0].0 - 0.015).abs() < 1e-12 && (out[0].1 - 0.025).abs() < 1e-12, "{out:?}");
        // Lying along world x (90° about y): the chord through y offset 3 mm is 2·4 mm.
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let lying = LineCaster::new(&cyl, &pose([0.0, 0.0, 0.005], [s, 0.0, s, 0.0]), Geometry::Auto);
        out.clear();
        lying.intervals(0.004, 0.003, &mut out);
        assert_eq!(out.len(), 1);
        assert!((out[0].0 - 0.001).abs() < 1e-12 && (out[0].1 - 0.009).abs() < 1e-12, "{out:?}");
        out.clear();
        lying.intervals(0.0051, 0.0, &mut out);
        assert!(out.is_empty());
    }

    #[test]
    fn a_ring_line_through_the_hole_gives_two_intervals() {
        let spec = ShapeSpec::Ring { outer_diameter_mm: 10.0, inner_diameter_mm: 6.0, height_mm: 10.0 };
        let ring = Pellet::build(spec, Resolution::default()).unwrap();
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let lying = LineCaster::new(&ring, &pose([0.0, 0.0, 0.0], [s, s, 0.0, 0.0]), Geometry::Auto);
        let mut out = Vec::new();
        lying.intervals(0.0, 0.0, &mut out);
        assert_eq!(out.len(), 2, "{out:?}");
        assert!((out[0].0 + 0.005).abs() < 1e-12 && (out[0].1 + 0.003).abs() < 1e-12, "{out:?}");
        assert!((out[1].0 - 0.003).abs() < 1e-12 && (out[1].1 - 0.005).abs() < 1e-12, "{out:?}");
    }
}
