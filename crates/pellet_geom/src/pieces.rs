//! Convex collision pieces: what a parry3d-based narrow phase collides.
//!
//! Each pellet file carries its shape as a list of convex pieces whose
//! union is the pellet: the hull for convex pellets, an exact analytic
//! decomposition for the catalogue's nonconvex shapes (ring sectors,
//! lobes, prisms around holes) and V-HACD for user meshes. Pieces are
//! plain data here; [`crate::parry_boundary`] turns them into parry shapes.
//!
//! Polygonal pieces use *area-preserving* radii: a circle of radius r
//! drawn as an n-gon through radius r·k, k = √(2π / (n·sin(2π/n))), has the
//! circle's area, so the union's volume equals the exact pellet's.

use serde::{Deserialize, Serialize};

use crate::math::{Point, Real, Vector2};

/// One convex piece, in the pellet's body frame (metres).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum ConvexPiece {
    /// A ball.
    Ball {
        /// Centre.
        center: Point,
        /// Radius.
        radius: Real,
    },
    /// A solid cylinder with its axis along body z (parry's implicit cylinder:
    /// exact round caps and contact manifolds).
    Cylinder {
        /// Centre.
        center: Point,
        /// Radius.
        radius: Real,
        /// Half of the height.
        half_height: Real,
    },
    /// The convex hull of these points.
    Hull {
        /// Points whose hull is the piece.
        points: Vec<Point>,
    },
}

/// Area-preserving radius factor of a regular n-gon.
pub fn polygon_radius_factor(n: usize) -> Real {
    let n = n as Real;
    (std::f64::consts::TAU / (n * (std::f64::consts::TAU / n).sin())).sqrt()
}

/// A Raschig ring as `sectors` prisms between the area-preserving inner
/// and outer polygons: 8 points, every face a quad, so parry's manifolds
/// are not truncated.
pub fn ring_sectors(inner_radius: Real, outer_radius: Real, half_height: Real, sectors: usize) -> Vec<ConvexPiece> {
    let k = polygon_radius_factor(sectors);
    (0..sectors)
        .map(|i| {
            let a0 = std::f64::consts::TAU * i as Real / sectors as Real;
            let a1 = std::f64::consts::TAU * (i + 1) as Real / sectors as Real;
            let mut points = Vec::with_capacity(8);
            for &z in &[-half_height, half_height] {
                for &a in &[a0, a1] {
                    for &r in &[inner_radius * k, outer_radius * k] {
                        points.push(Point::new(r * a.cos(), r * a.sin(), z));
                    }
                }
            }
            ConvexPiece::Hull { points }
        })
        .collect()
}

/// Prisms over a set of convex 2-D polygons, from z = −h to h.
pub fn prisms(polygons: &[Vec<Vector2>], half_height: Real) -> Vec<ConvexPiece> {
    polygons
        .iter()
        .map(|poly| ConvexPiece::Hull {
            points: [-half_height, half_height]
                .iter()
                .flat_map(|&z| poly.iter().map(move |q| Point::new(q.x, q.y, z)))
                .collect(),
        })
        .collect()
}

/// Greedily merges pairs of adjacent triangles into convex quadrilaterals
/// (fewer, fatter pieces; faces stay at ≤ 4 vertices for parry).
pub fn merge_into_quads(points: &[Vector2], triangles: &[[usize; 3]]) -> Vec<Vec<Vector2>> {
    use std::collections::BTreeMap;
    let mut owners: BTreeMap<(usize, usize), Vec<usize>> = BTreeMap::new();
    for (t, tri) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            owners.entry((a.min(b), a.max(b))).or_default().push(t);
        }
    }
    let mut used = vec![false; triangles.len()];
    let mut out = Vec::new();
    for (t, tri) in triangles.iter().enumerate() {
        if used[t] {
            continue;
        }
        used[t] = true;
        let mut merged = None;
        for k in 0..3 {
            let (a, b, c) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]);
            let neighbour = owners[&(a.min(b), a.max(b))].iter().copied().find(|&u| u != t && !used[u]);
            let Some(u) = neighbour else { continue };
            let Some(&d) = triangles[u].iter().find(|&&v| v != a && v != b) else { continue };
            // Triangle a-b-c is counter-clockwise and d lies across a-b, so
            // a-d-b-c is the counter-clockwise quad.
            let quad = [points[a], points[d], points[b], points[c]];
            if is_convex(&quad) {
                used[u] = true;
                merged = Some(quad.to_vec());
                break;
            }
        }
        out.push(merged.unwrap_or_else(|| tri.iter().map(|&i| points[i]).collect()));
    }
    out
}

/// Strict convexity of a counter-clockwise polygon.
fn is_convex(poly: &[Vector2]) -> bool {
    let n = poly.len();
    (0..n).all(|i| {
        let (a, b, c) = (poly[i], poly[(i + 1) % n], poly[(i + 2) % n]);
        (b - a).perp(&(c - b)) > 1e-12 * (b - a).norm() * (c - b).norm()
    })
}
