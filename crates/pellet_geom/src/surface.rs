//! The exact surfaces pellet meshes are projected onto.
//!
//! Every face of a control mesh is tagged with the smooth surface it
//! approximates. After each subdivision step a vertex is moved back onto
//! its surface, or onto the intersection curve of its two surfaces when it
//! sits on a sharp edge; that keeps flat faces flat, circular rims
//! circular and concave lobe junctions sharp.

use serde::{Deserialize, Serialize};

use crate::math::{Point, Real, Vector2};

/// A smooth surface patch of a pellet, in the body frame (axis along z).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Surface {
    /// The horizontal plane z = `z` (a cap).
    Plane {
        /// Height of the plane.
        z: Real,
    },
    /// The vertical cylinder of the given axis position and radius (a lateral face or a hole wall).
    Cylinder {
        /// (x, y) of the cylinder's axis.
        center: [Real; 2],
        /// Radius.
        radius: Real,
    },
    /// A sphere about the origin.
    Sphere {
        /// Radius.
        radius: Real,
    },
}

impl Surface {
    /// The nearest point of the surface to `p` (radial projection for the
    /// curved ones, which is exact away from the axis).
    pub fn project(&self, p: &Point) -> Point {
        match *self {
            Surface::Plane { z } => Point::new(p.x, p.y, z),
            Surface::Cylinder { center, radius } => {
                let c = Vector2::new(center[0], center[1]);
                let d = Vector2::new(p.x, p.y) - c;
                let n = d.norm();
                if n == 0.0 {
                    return *p;
                }
                let q = c + d * (radius / n);
                Point::new(q.x, q.y, p.z)
            }
            Surface::Sphere { radius } => {
                let n = p.coords.norm();
                if n == 0.0 {
                    *p
                } else {
                    Point::from(p.coords * (radius / n))
                }
            }
        }
    }

    /// The nearest point to `p` on the curve where `self` meets `other`
    /// (a sharp edge). Pairs that do not meet in a curve leave `p` on `self`.
    pub fn project_to_edge(&self, other: &Surface, p: &Point) -> Point {
        match (*self, *other) {
            (Surface::Plane { z }, cyl @ Surface::Cylinder { .. })
            | (cyl @ Surface::Cylinder { .. }, Surface::Plane { z }) => {
                let q = cyl.project(p);
                Point::new(q.x, q.y, z)
            }
            (Surface::Cylinder { center: c1, radius: r1 }, Surface::Cylinder { center: c2, radius: r2 }) => {
                let c1 = Vector2::new(c1[0], c1[1]);
                let c2 = Vector2::new(c2[0], c2[1]);
                match circle_intersection_nearest(c1, r1, c2, r2, Vector2::new(p.x, p.y)) {
                    Some(q) => Point::new(q.x, q.y, p.z),
                    None => self.project(p),
                }
            }
            _ => self.project(p),
        }
    }
}

/// Of the (up to two) intersection points of two circles, the one nearest `near`.
pub fn circle_intersection_nearest(c1: Vector2, r1: Real, c2: Vector2, r2: Real, near: Vector2) -> Option<Vector2> {
    let d = c2 - c1;
    let dist = d.norm();
    if dist == 0.0 || dist > r1 + r2 || dist < (r1 - r2).abs() {
        return None;
    }
    let a = (r1 * r1 - r2 * r2 + dist * dist) / (2.0 * dist);
    let h = (r1 * r1 - a * a).max(0.0).sqrt();
    let mid = c1 + d * (a / dist);
    let perp = Vector2::new(-d.y, d.x) / dist;
    let (p1, p2) = (mid + perp * h, mid - perp * h);
    Some(if (p1 - near).norm_squared() <= (p2 - near).norm_squared() { p1 } else { p2 })
}
