//! Closed triangle meshes and their topological checks.
//!
//! A pellet surface must be closed, 2-manifold and consistently oriented
//! with outward normals: the mass integrals (divergence theorem), the
//! point-in-pellet test (winding number) and every CFD mesher downstream
//! rely on it. [`TriMesh::check_closed`] verifies all three and reports the
//! first defect it finds with the numbers needed to locate it.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::math::{Point, Real, Vector};
use crate::GeomError;

/// An indexed triangle mesh. Triangles are counter-clockwise seen from
/// outside (right-hand rule gives the outward normal).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TriMesh {
    /// Vertex positions.
    pub vertices: Vec<Point>,
    /// Vertex indices of each triangle.
    pub triangles: Vec<[u32; 3]>,
}

/// What [`TriMesh::check_closed`] found out about a valid closed mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Topology {
    /// Number of vertices used by triangles.
    pub vertices: usize,
    /// Number of undirected edges.
    pub edges: usize,
    /// Number of triangles.
    pub faces: usize,
    /// Number of connected components.
    pub components: usize,
    /// Euler characteristic V − E + F (2 per sphere-like component, 0 for a torus).
    pub euler_characteristic: i64,
}

impl Topology {
    /// The genus of a single-component surface: (2 − χ)/2.
    pub fn genus(&self) -> i64 {
        (2 * self.components as i64 - self.euler_characteristic) / 2
    }
}

impl TriMesh {
    /// Number of triangles.
    pub fn face_count(&self) -> usize {
        self.triangles.len()
    }

    /// The three corners of triangle `t`.
    pub fn corners(&self, t: usize) -> [Point; 3] {
        let [a, b, c] = self.triangles[t];
        [self.vertices[a as usize], self.vertices[b as usize], self.vertices[c as usize]]
    }

    /// Area-weighted (unnormalised, length = 2·area) normal of triangle `t`.
    pub fn area_normal(&self, t: usize) -> Vector {
        let [a, b, c] = self.corners(t);
        (b - a).cross(&(c - a))
    }

    /// Total surface area.
    pub fn area(&self) -> Real {
        (0..self.triangles.len()).map(|t| 0.5 * self.area_normal(t).norm()).sum()
    }

    /// Reverses every triangle (flips all normals).
    pub fn flip(&mut self) {
        for t in &mut self.triangles {
            t.swap(1, 2);
        }
    }

    /// Moves every vertex by `offset`.
    pub fn translate(&mut self, offset: &Vector) {
        for v in &mut self.vertices {
            *v += offset;
        }
    }

    /// Multiplies every coordinate by `factor` (unit conversion).
    pub fn scale(&mut self, factor: Real) {
        for v in &mut self.vertices {
            *v *= factor;
        }
    }

    /// Largest distance of a vertex from the origin.
    pub fn max_radius(&self) -> Real {
        self.vertices.iter().map(|v| v.coords.norm()).fold(0.0, Real::max)
    }

    /// Checks that the mesh is a closed, edge- and vertex-manifold,
    /// consistently oriented surface without degenerate triangles.
    ///
    /// Orientation *direction* (outward or inward) is not checked here;
    /// a closed consistently oriented mesh is outward iff its signed volume
    /// is positive (see [`crate::mass::MassProperties`]).
    pub fn check_closed(&self) -> Result<Topology, GeomError> {
        if self.triangles.is_empty() {
            return Err(GeomError::BadMesh("the mesh has no triangles".into()));
        }
        let n = self.vertices.len();
        for (t, tri) in self.triangles.iter().enumerate() {
            if tri.iter().any(|&i| i as usize >= n) {
                return Err(GeomError::BadMesh(format!(
                    "triangle {t} refers to vertex {} but the mesh has {n} vertices",
                    tri.iter().max().unwrap_or(&0)
                )));
            }
            if tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] {
                return Err(GeomError::BadMesh(format!("triangle {t} repeats a vertex ({tri:?})")));
            }
        }
        if let Some(v) = self.vertices.iter().position(|p| !p.coords.iter().all(|c| c.is_finite())) {
            return Err(GeomError::BadMesh(format!("vertex {v} has a non-finite coordinate")));
        }
        // Each directed edge must occur exactly once, and its reverse exactly once.
        let mut directed: BTreeMap<(u32, u32), usize> = BTreeMap::new();
        for (t, tri) in self.triangles.iter().enumerate() {
            for k in 0..3 {
                let e = (tri[k], tri[(k + 1) % 3]);
                if let Some(other) = directed.insert(e, t) {
                    return Err(GeomError::BadMesh(format!(
                        "edge {}–{} is used in the same direction by triangles {other} and {t}: \
                         the mesh is not consistently oriented or not 2-manifold",
                        e.0, e.1
                    )));
                }
            }
        }
        for (&(a, b), &t) in &directed {
            if !directed.contains_key(&(b, a)) {
                return Err(GeomError::BadMesh(format!(
                    "edge {a}–{b} of triangle {t} has no neighbour across it: the mesh is not closed \
                     (or neighbouring triangles disagree in orientation)"
                )));
            }
        }
        // Vertex manifoldness: the triangles around each vertex form one fan.
        let mut around: Vec<Vec<(u32, u32)>> = vec![Vec::new(); n];
        for tri in &self.triangles {
            for k in 0..3 {
                around[tri[k] as usize].push((tri[(k + 1) % 3], tri[(k + 2) % 3]));
            }
        }
        let mut used = 0usize;
        for (v, fan) in around.iter().enumerate() {
            if fan.is_empty() {
                continue;
            }
            used += 1;
            let next: BTreeMap<u32, u32> = fan.iter().copied().collect();
            let start = fan[0].0;
            let mut cur = start;
            let mut steps = 0usize;
            loop {
                cur = next[&cur];
                steps += 1;
                if cur == start || steps > fan.len() {
                    break;
                }
            }
            if steps != fan.len() {
                return Err(GeomError::BadMesh(format!(
                    "vertex {v} joins {} separate fans of triangles: the mesh is not 2-manifold there",
                    if steps < fan.len() { "several" } else { "broken" }
                )));
            }
        }
        let components = self.components();
        let faces = self.triangles.len();
        let edges = directed.len() / 2;
        Ok(Topology {
            vertices: used,
            edges,
            faces,
            components,
            euler_characteristic: used as i64 - edges as i64 + faces as i64,
        })
    }

    /// Number of edge-connected components (union-find over triangles' vertices).
    fn components(&self) -> usize {
        let mut parent: Vec<u32> = (0..self.vertices.len() as u32).collect();
        fn find(parent: &mut [u32], mut x: u32) -> u32 {
            while parent[x as usize] != x {
                parent[x as usize] = parent[parent[x as usize] as usize];
                x = parent[x as usize];
            }
            x
        }
        for tri in &self.triangles {
            let a = find(&mut parent, tri[0]);
            for &o in &tri[1..] {
                let b = find(&mut parent, o);
                if a != b {
                    parent[b as usize] = a;
                }
            }
        }
        let mut roots = std::collections::BTreeSet::new();
        for tri in &self.triangles {
            roots.insert(find(&mut parent, tri[0]));
        }
        roots.len()
    }

    /// Generalised winding number of the closed surface around `p`
    /// (1 inside, 0 outside for an outward mesh), from the sum of the
    /// triangles' signed solid angles (Van Oosterom & Strackee 1983).
    pub fn winding_number(&self, p: &Point) -> Real {
        let mut total = 0.0;
        for t in 0..self.triangles.len() {
            let [a, b, c] = self.corners(t);
            let (a, b, c) = (a - p, b - p, c - p);
            let (la, lb, lc) = (a.norm(), b.norm(), c.norm());
            let det = a.dot(&b.cross(&c));
            let den = la * lb * lc + a.dot(&b) * lc + b.dot(&c) * la + c.dot(&a) * lb;
            total += 2.0 * det.atan2(den);
        }
        total / (4.0 * std::f64::consts::PI)
    }

    /// Whether `p` lies inside the closed surface (winding number > ½).
    pub fn contains(&self, p: &Point) -> bool {
        self.winding_number(p) > 0.5
    }
}
