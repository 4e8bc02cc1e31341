//! Loop subdivision with sharp creases and projection onto exact surfaces.
//!
//! The rules are Loop's (1987) with Hoppe et al.'s (1994) crease masks:
//! an edge between faces of different surfaces is a crease; crease edges
//! split at their midpoint and crease vertices use the 1-6-1 curve mask,
//! vertices where creases meet in other numbers (corners) stay put.
//! Every new position is then projected back onto the exact surface (or
//! crease curve) it belongs to, so the limit surface is the real pellet
//! and not Loop's shrunken approximation of its control mesh.

use std::collections::HashMap;

use crate::math::{Point, Real, Vector};
use crate::mesh::TriMesh;
use crate::surface::Surface;

/// A triangle mesh whose faces know which exact surface they approximate.
#[derive(Clone, Debug, Default)]
pub struct FeatureMesh {
    /// The triangles.
    pub mesh: TriMesh,
    /// Index into `surfaces` for each triangle.
    pub face_surface: Vec<u16>,
    /// The exact surfaces.
    pub surfaces: Vec<Surface>,
}

struct EdgeInfo {
    /// Vertices opposite the edge in its (at most two) triangles.
    opposite: [u32; 2],
    /// Surfaces of the two triangles.
    surface: [u16; 2],
    count: u8,
    /// Index of the edge's new (odd) vertex.
    new_vertex: u32,
}

impl FeatureMesh {
    /// Moves every vertex onto its surface or crease curve.
    pub fn project_vertices(&mut self) {
        let info = vertex_surfaces(self);
        for (v, surfaces) in info.iter().enumerate() {
            let p = self.mesh.vertices[v];
            self.mesh.vertices[v] = match surfaces.as_slice() {
                [s] => self.surfaces[*s as usize].project(&p),
                [s, t] => self.surfaces[*s as usize].project_to_edge(&self.surfaces[*t as usize], &p),
                _ => p,
            };
        }
    }

    /// One level of Loop subdivision with creases and projection: 4× the faces.
    ///
    /// The mesh must be closed (every edge in exactly two triangles).
    pub fn subdivide(&self) -> FeatureMesh {
        let mesh = &self.mesh;
        let n_old = mesh.vertices.len();
        // Edge table, keyed by the sorted vertex pair; lookups only, so the
        // HashMap's iteration order never affects the result.
        let mut edges: HashMap<(u32, u32), EdgeInfo> = HashMap::with_capacity(mesh.triangles.len() * 2);
        let mut edge_order: Vec<(u32, u32)> = Vec::with_capacity(mesh.triangles.len() * 3 / 2);
        for (t, tri) in mesh.triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b, c) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]);
                let key = (a.min(b), a.max(b));
                let s = self.face_surface[t];
                match edges.get_mut(&key) {
                    Some(e) => {
                        let slot = (e.count as usize).min(1);
                        e.opposite[slot] = c;
                        e.surface[slot] = s;
                        e.count += 1;
                    }
                    None => {
                        let new_vertex = (n_old + edge_order.len()) as u32;
                        edge_order.push(key);
                        edges.insert(key, EdgeInfo { opposite: [c, c], surface: [s, s], count: 1, new_vertex });
                    }
                }
            }
        }
        // Vertex neighbourhoods: all neighbours, and neighbours across creases.
        let mut neighbours: Vec<Vec<u32>> = vec![Vec::new(); n_old];
        let mut crease_neighbours: Vec<Vec<u32>> = vec![Vec::new(); n_old];
        for key in &edge_order {
            let e = &edges[key];
            let (a, b) = *key;
            neighbours[a as usize].push(b);
            neighbours[b as usize].push(a);
            if e.surface[0] != e.surface[1] || e.count != 2 {
                crease_neighbours[a as usize].push(b);
                crease_neighbours[b as usize].push(a);
            }
        }
        let old_surfaces = vertex_surfaces(self);
        let mut vertices: Vec<Point> = Vec::with_capacity(n_old + edge_order.len());
        // Even (old) vertices.
        for v in 0..n_old {
            let p = mesh.vertices[v];
            let ring = &neighbours[v];
            let creases = &crease_neighbours[v];
            let moved = match creases.len() {
                0 if !ring.is_empty() => {
                    let n = ring.len() as Real;
                    let beta = if ring.len() == 3 { 3.0 / 16.0 } else { 3.0 / (8.0 * n) };
                    let sum = ring.iter().fold(Vector::zeros(), |acc, &u| acc + mesh.vertices[u as usize].coords);
                    Point::from(p.coords * (1.0 - n * beta) + sum * beta)
                }
                2 => {
                    let a = mesh.vertices[creases[0] as usize].coords;
                    let b = mesh.vertices[creases[1] as usize].coords;
                    Point::from(p.coords * 0.75 + (a + b) * 0.125)
                }
                _ => p,
            };
            let projected = match (creases.len(), old_surfaces[v].as_slice()) {
                (0, [s]) => self.surfaces[*s as usize].project(&moved),
                (2, [s, t]) => self.surfaces[*s as usize].project_to_edge(&self.surfaces[*t as usize], &moved),
                (2, [s]) => self.surfaces[*s as usize].project(&moved),
                _ => moved,
            };
            vertices.push(projected);
        }
        // Odd (edge) vertices.
        for key in &edge_order {
            let e = &edges[key];
            let a = mesh.vertices[key.0 as usize].coords;
            let b = mesh.vertices[key.1 as usize].coords;
            let [s, t] = e.surface;
            let p = if s == t && e.count == 2 {
                let c = mesh.vertices[e.opposite[0] as usize].coords;
                let d = mesh.vertices[e.opposite[1] as usize].coords;
                let q = Point::from((a + b) * 0.375 + (c + d) * 0.125);
                self.surfaces[s as usize].project(&q)
            } else {
                let q = Point::from((a + b) * 0.5);
                self.surfaces[s as usize].project_to_edge(&self.surfaces[t as usize], &q)
            };
            vertices.push(p);
        }
        // Each triangle becomes four, keeping its orientation and surface.
        let mut triangles = Vec::with_capacity(mesh.triangles.len() * 4);
        let mut face_surface = Vec::with_capacity(mesh.triangles.len() * 4);
        for (t, tri) in mesh.triangles.iter().enumerate() {
            let mid = |i: usize, j: usize| {
                let (a, b) = (tri[i], tri[j]);
                edges[&(a.min(b), a.max(b))].new_vertex
            };
            let (m01, m12, m20) = (mid(0, 1), mid(1, 2), mid(2, 0));
            triangles.push([tri[0], m01, m20]);
            triangles.push([tri[1], m12, m01]);
            triangles.push([tri[2], m20, m12]);
            triangles.push([m01, m12, m20]);
            face_surface.extend(std::iter::repeat_n(self.face_surface[t], 4));
        }
        FeatureMesh { mesh: TriMesh { vertices, triangles }, face_surface, surfaces: self.surfaces.clone() }
    }

    /// `levels` rounds of [`FeatureMesh::subdivide`].
    pub fn subdivided(&self, levels: u32) -> FeatureMesh {
        let mut m = self.clone();
        for _ in 0..levels {
            m = m.subdivide();
        }
        m
    }
}

/// For each vertex, the sorted distinct surfaces of the triangles around it.
fn vertex_surfaces(fm: &FeatureMesh) -> Vec<Vec<u16>> {
    let mut out: Vec<Vec<u16>> = vec![Vec::new(); fm.mesh.vertices.len()];
    for (t, tri) in fm.mesh.triangles.iter().enumerate() {
        let s = fm.face_surface[t];
        for &v in tri {
            let list = &mut out[v as usize];
            if !list.contains(&s) {
                list.push(s);
            }
        }
    }
    for list in &mut out {
        list.sort_unstable();
    }
    out
}
