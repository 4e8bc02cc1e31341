//! Signed distances with gradients in the body frame: the closed forms of the
//! paper's three shapes and a sampled grid for any other shape (built outside this crate, e.g.
//! from parry3d's distance to the pellet's triangle mesh, and handed over as plain data so that
//! the world stays serialisable and this crate free of mesh queries).

use crate::error::SimError;
use crate::math::{axial_distance, Real, Vec3};
use crate::shape::ShapeDesc;
use serde::{Deserialize, Serialize};

/// A signed-distance field sampled on a regular grid (body frame), trilinearly interpolated.
///
/// `values[i + nx (j + ny k)]` is the signed distance (m, < 0 inside) at
/// `origin + cell (i, j, k)`. The grid must cover the shape plus `margin` on every side: outside
/// it the distance is taken as `margin` plus the distance to the grid box, a lower bound of the
/// true distance (so culling stays safe) that is never small enough to make a contact.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SdfGrid {
    /// Position of grid node (0, 0, 0), m.
    pub origin: Vec3,
    /// Node spacing, m.
    pub cell: Real,
    /// Nodes per axis.
    pub dims: [usize; 3],
    /// Node values, x fastest, m (f32: 1e-7 relative is far below the interpolation error).
    pub values: Vec<f32>,
    /// Clearance between the shape and the grid box, m.
    pub margin: Real,
}

impl SdfGrid {
    /// Checks sizes and finiteness.
    pub fn validate(&self) -> Result<(), SimError> {
        let n: usize = self.dims.iter().product();
        let ok = self.dims.iter().all(|&d| d >= 2)
            && self.values.len() == n
            && self.cell.is_finite()
            && self.cell > 0.0
            && self.margin.is_finite()
            && self.margin > 0.0
            && self.origin.iter().all(|v| v.is_finite())
            && self.values.iter().all(|v| v.is_finite());
        if ok {
            Ok(())
        } else {
            Err(SimError::InvalidParameter {
                name: "sdf grid",
                value: self.values.len() as Real,
                reason: "needs ≥ 2 nodes per axis, one finite value per node, cell > 0 and margin > 0",
            })
        }
    }

    fn at(&self, i: usize, j: usize, k: usize) -> Real {
        self.values[i + self.dims[0] * (j + self.dims[1] * k)] as Real
    }

    /// Where `p` falls: its offset outside the grid box (m; zero inside), else the values at the
    /// corners of its cell and its fractional position in the cell.
    fn locate(&self, p: &Vec3) -> Result<([Real; 8], [Real; 3]), Vec3> {
        let mut u = [0.0; 3];
        let mut outside = Vec3::zeros();
        for a in 0..3 {
            let hi = (self.dims[a] - 1) as Real;
            let x = (p[a] - self.origin[a]) / self.cell;
            let xc = x.clamp(0.0, hi);
            outside[a] = (x - xc) * self.cell;
            u[a] = xc;
        }
        if outside != Vec3::zeros() {
            return Err(outside);
        }
        let idx = |a: usize| -> (usize, Real) {
            let i = (u[a].floor() as usize).min(self.dims[a] - 2);
            (i, u[a] - i as Real)
        };
        let ((i, fx), (j, fy), (k, fz)) = (idx(0), idx(1), idx(2));
        let c = |di, dj, dk| self.at(i + di, j + dj, k + dk);
        let corners = [c(0, 0, 0), c(1, 0, 0), c(0, 1, 0), c(1, 1, 0), c(0, 0, 1), c(1, 0, 1), c(0, 1, 1), c(1, 1, 1)];
        Ok((corners, [fx, fy, fz]))
    }

    /// Trilinear value and gradient at `p`.
    pub fn eval(&self, p: &Vec3) -> (Real, Vec3) {
        let (c, [fx, fy, fz]) = match self.locate(p) {
            Ok(cell) => cell,
            Err(outside) => {
                let d = outside.norm();
                return (self.margin + d, outside / d);
            }
        };
        let [c000, c100, c010, c110, c001, c101, c011, c111] = c;
        let (x00, x10, x01, x11, y0, y1, v) = trilinear(&c, fx, fy, fz);
        let dx = lerp(lerp(c100 - c000, c110 - c010, fy), lerp(c101 - c001, c111 - c011, fy), fz);
        let dy = lerp(x10 - x00, x11 - x01, fz);
        let dz = y1 - y0;
        let g = Vec3::new(dx, dy, dz) / self.cell;
        let n = g.norm();
        (v, if n > 0.0 { g / n } else { Vec3::z() })
    }

    /// The value of [`Self::eval`] alone, to the bit.
    pub fn distance(&self, p: &Vec3) -> Real {
        match self.locate(p) {
            Ok((c, [fx, fy, fz])) => trilinear(&c, fx, fy, fz).6,
            Err(outside) => self.margin + outside.norm(),
        }
    }
}

fn lerp(a: Real, b: Real, t: Real) -> Real {
    a + (b - a) * t
}

/// Trilinear interpolation of a cell's corner values (order of [`SdfGrid::locate`]): the
/// partial sums along x (x00, x10, x01, x11) and y (y0, y1), which the gradient reuses, and
/// the value.
#[inline]
fn trilinear(c: &[Real; 8], fx: Real, fy: Real, fz: Real) -> (Real, Real, Real, Real, Real, Real, Real) {
    let [c000, c100, c010, c110, c001, c101, c011, c111] = *c;
    let x00 = lerp(c000, c100, fx);
    let x10 = lerp(c010, c110, fx);
    let x01 = lerp(c001, c101, fx);
    let x11 = lerp(c011, c111, fx);
    let y0 = lerp(x00, x10, fy);
    let y1 = lerp(x01, x11, fy);
    (x00, x10, x01, x11, y0, y1, lerp(y0, y1, fz))
}

/// The signed distance to the cross-section's rectangle at a point whose offsets past its side
/// and its cap are (qx, qy), with its gradient in (radial, axial) components.
fn sd_box2(qx: Real, qy: Real) -> (Real, Real, Real) {
    if qx > 0.0 && qy > 0.0 {
        let d = axial_distance(qx, qy);
        (d, qx / d, qy / d)
    } else if qx >= qy {
        (qx, 1.0, 0.0)
    } else {
        (qy, 0.0, 1.0)
    }
}

/// Unit radial direction of `p` (x when on the axis, a fixed choice: any is valid there).
fn radial(p: &Vec3) -> (Real, Vec3) {
    let rho = axial_distance(p.x, p.y);
    if rho > 0.0 {
        (rho, Vec3::new(p.x / rho, p.y / rho, 0.0))
    } else {
        (0.0, Vec3::x())
    }
}

/// Signed distance and unit outward gradient of `shape` at body-frame point `p`.
pub fn eval(shape: &ShapeDesc, p: &Vec3) -> (Real, Vec3) {
    match shape {
        ShapeDesc::Sphere { radius } => {
            let d = p.norm();
            (d - radius, if d > 0.0 { p / d } else { Vec3::z() })
        }
        ShapeDesc::Cylinder { radius, half_height } => {
            let (rho, er) = radial(p);
            let ez = Vec3::new(0.0, 0.0, if p.z >= 0.0 { 1.0 } else { -1.0 });
            let (d, gr, gz) = sd_box2(rho - radius, p.z.abs() - half_height);
            (d, er * gr + ez * gz)
        }
        ShapeDesc::HollowCylinder { inner_radius, outer_radius, half_height } => {
            let (rho, er) = radial(p);
            let mid = 0.5 * (inner_radius + outer_radius);
            let half_wall = 0.5 * (outer_radius - inner_radius);
            let s = if rho >= mid { er } else { -er };
            let ez = Vec3::new(0.0, 0.0, if p.z >= 0.0 { 1.0 } else { -1.0 });
            let (d, gr, gz) = sd_box2((rho - mid).abs() - half_wall, p.z.abs() - half_height);
            (d, s * gr + ez * gz)
        }
        ShapeDesc::Mesh { grid, .. } => grid.eval(p),
    }
}

/// The signed distance of [`eval`] without its gradient, to the bit: the narrow phase's culling
/// and rim searches read only the value, and the gradient's divisions were a third of a
/// cylinder pour's SDF time.
pub fn distance(shape: &ShapeDesc, p: &Vec3) -> Real {
    match shape {
        ShapeDesc::Sphere { radius } => p.norm() - radius,
        ShapeDesc::Cylinder { radius, half_height } => {
            box2_distance(axial_distance(p.x, p.y) - radius, p.z.abs() - half_height)
        }
        ShapeDesc::HollowCylinder { inner_radius, outer_radius, half_height } => {
            let rho = axial_distance(p.x, p.y);
            let mid = 0.5 * (inner_radius + outer_radius);
            let half_wall = 0.5 * (outer_radius - inner_radius);
            box2_distance((rho - mid).abs() - half_wall, p.z.abs() - half_height)
        }
        ShapeDesc::Mesh { grid, .. } => grid.distance(p),
    }
}

/// The value of [`sd_box2`] alone.
fn box2_distance(qx: Real, qy: Real) -> Real {
    // The branches of sd_box2, not max: the same sign of a zero.
    if qx > 0.0 && qy > 0.0 {
        axial_distance(qx, qy)
    } else if qx >= qy {
        qx
    } else {
        qy
    }
}

/// The two faces (depth, outward normal) of a cylinder or ring that meet at the edge nearest to
/// `p`, when `p` is inside or within `eps` of that edge: there the Euclidean SDF's choice (the
/// shallower face, or the direction to the edge) is ambiguous or round-off noise, and the narrow
/// phase may prefer the face that faces the other body (see `contact_sampled`).
pub fn edge_faces(shape: &ShapeDesc, p: &Vec3, eps: Real) -> Option<[(Real, Vec3); 2]> {
    let (qx, qy, s) = match shape {
        ShapeDesc::Cylinder { radius, half_height } => {
            let (rho, er) = radial(p);
            (rho - radius, p.z.abs() - half_height, er)
        }
        ShapeDesc::HollowCylinder { inner_radius, outer_radius, half_height } => {
            let (rho, er) = radial(p);
            let mid = 0.5 * (inner_radius + outer_radius);
            let s = if rho >= mid { er } else { -er };
            ((rho - mid).abs() - 0.5 * (outer_radius - inner_radius), p.z.abs() - half_height, s)
        }
        _ => return None,
    };
    if axial_distance(qx.max(0.0), qy.max(0.0)) > eps {
        return None;
    }
    let ez = Vec3::new(0.0, 0.0, if p.z >= 0.0 { 1.0 } else { -1.0 });
    Some([(qx, s), (qy, ez)])
}

/// The normal cone (outward, two unit vectors) of the cylinder or ring edge nearest to `p` when
/// `p` lies outside in the edge's corner region (both the radial and the axial excess > 0).
pub fn edge_cone(shape: &ShapeDesc, p: &Vec3) -> Option<(Vec3, Vec3)> {
    let faces = edge_faces(shape, p, Real::INFINITY)?;
    (faces[0].0 > 0.0 && faces[1].0 > 0.0).then_some((faces[0].1, faces[1].1))
}

/// Lipschitz constant of [`eval`]'s value: 1 for exact distances; √3 bounds the trilinear
/// interpolant of a 1-Lipschitz grid (each partial derivative is a node difference over a cell).
pub fn lipschitz(shape: &ShapeDesc) -> Real {
    match shape {
        ShapeDesc::Mesh { .. } => 3f64.sqrt(),
        _ => 1.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// `distance` is `eval`'s value to the bit, for every shape, at points inside, outside, on
    /// the axis, on the mid-plane and off a grid's box.
    #[test]
    fn distance_is_the_value_of_eval_to_the_bit() {
        let n = 9;
        let cell = 2e-3;
        let origin = Vec3::repeat(-0.5 * cell * (n - 1) as Real);
        let sphere = |p: Vec3| (p.norm() - 5e-3) as f32;
        let values = (0..n * n * n)
            .map(|i| sphere(origin + cell * Vec3::new((i % n) as Real, ((i / n) % n) as Real, (i / (n * n)) as Real)))
            .collect();
        let grid = SdfGrid { origin, cell, dims: [n; 3], values, margin: 1e-3 };
        let shapes = [
            ShapeDesc::Sphere { radius: 5e-3 },
            ShapeDesc::Cylinder { radius: 5e-3, half_height: 5e-3 },
            ShapeDesc::HollowCylinder { inner_radius: 3e-3, outer_radius: 5e-3, half_height: 5e-3 },
            ShapeDesc::Mesh { name: "grid sphere".into(), samples: Vec::new(), grid },
        ];
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let mut points =
            vec![Vec3::zeros(), Vec3::new(0.0, 0.0, 5e-3), Vec3::new(4e-3, 0.0, 0.0), Vec3::new(0.0, 0.0, -0.0)];
        for _ in 0..20_000 {
            points.push(Vec3::new(
                rng.random_range(-0.012..0.012),
                rng.random_range(-0.012..0.012),
                rng.random_range(-0.012..0.012),
            ));
        }
        for shape in &shapes {
            for p in &points {
                assert_eq!(distance(shape, p).to_bits(), eval(shape, p).0.to_bits(), "{shape:?} at {p:?}");
            }
        }
    }
}
