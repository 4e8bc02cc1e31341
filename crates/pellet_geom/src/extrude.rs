//! Control meshes of prismatic pellets: a planar cross-section bounded by
//! circular arcs, extruded along body z.
//!
//! Cylinders, Raschig rings, multi-lobe and multi-hole pellets are all of
//! this kind. The cross-section's loops are sampled at a common target
//! edge length, the caps are a constrained Delaunay triangulation (spade)
//! of the loops plus a hexagonal lattice of interior points, and the
//! lateral walls are quad strips split into triangles. Each face is tagged
//! with its exact surface for [`crate::subdivision`].

use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};

use crate::math::{Point, Real, Vector2};
use crate::mesh::TriMesh;
use crate::subdivision::FeatureMesh;
use crate::surface::Surface;
use crate::GeomError;

/// A circular arc of a cross-section loop.
#[derive(Clone, Copy, Debug)]
pub struct Arc {
    /// Centre of the circle.
    pub center: Vector2,
    /// Radius of the circle.
    pub radius: Real,
    /// Start angle (rad).
    pub start: Real,
    /// Signed sweep (rad): positive counter-clockwise.
    pub sweep: Real,
}

impl Arc {
    /// A full circle, counter-clockwise (`ccw`) or clockwise.
    pub fn circle(center: Vector2, radius: Real, ccw: bool) -> Arc {
        let sweep = if ccw { std::f64::consts::TAU } else { -std::f64::consts::TAU };
        Arc { center, radius, start: 0.0, sweep }
    }

    fn point(&self, angle: Real) -> Vector2 {
        self.center + Vector2::new(angle.cos(), angle.sin()) * self.radius
    }
}

/// A closed loop of arcs, each starting where the previous one ends. The
/// material is on the left: outer boundaries run counter-clockwise,
/// holes clockwise.
pub type ArcLoop = Vec<Arc>;

/// A cross-section: one outer loop and any number of holes.
#[derive(Clone, Debug)]
pub struct Profile {
    /// Outer boundary, counter-clockwise.
    pub outer: ArcLoop,
    /// Holes, each clockwise.
    pub holes: Vec<ArcLoop>,
}

/// A sampled loop: polygon vertices and, per segment, the arc it follows.
struct Polygon {
    points: Vec<Vector2>,
    /// Index (into all arcs of the profile) of the arc of segment i → i+1.
    segment_arc: Vec<usize>,
}

impl Profile {
    fn loops(&self) -> impl Iterator<Item = &ArcLoop> {
        std::iter::once(&self.outer).chain(self.holes.iter())
    }

    /// Length of the outer loop.
    pub fn outer_perimeter(&self) -> Real {
        self.outer.iter().map(|a| a.radius * a.sweep.abs()).sum()
    }

    fn sample(&self, edge: Real) -> Vec<Polygon> {
        let mut arc_index = 0;
        let mut out = Vec::new();
        for lp in self.loops() {
            let mut points = Vec::new();
            let mut segment_arc = Vec::new();
            let full_circle = lp.len() == 1;
            for arc in lp {
                let min = if full_circle { 6 } else { 2 };
                let n = ((arc.radius * arc.sweep.abs() / edge).round() as usize).max(min);
                for k in 0..n {
                    points.push(arc.point(arc.start + arc.sweep * k as Real / n as Real));
                    segment_arc.push(arc_index);
                }
                arc_index += 1;
            }
            out.push(Polygon { points, segment_arc });
        }
        out
    }

    /// The control mesh of this cross-section extruded from z = −h/2 to
    /// h/2, with the outer loop split into about `segments` edges.
    pub fn control_mesh(&self, height: Real, segments: usize) -> Result<FeatureMesh, GeomError> {
        let edge = self.outer_perimeter() / segments.max(3) as Real;
        let polygons = self.sample(edge);
        let half = 0.5 * height;
        let layers = ((height / edge).round() as usize).max(1);

        let mut surfaces = vec![Surface::Plane { z: -half }, Surface::Plane { z: half }];
        for arc in self.loops().flatten() {
            surfaces.push(Surface::Cylinder { center: [arc.center.x, arc.center.y], radius: arc.radius });
        }
        let mut vertices: Vec<Point> = Vec::new();
        let mut triangles: Vec<[u32; 3]> = Vec::new();
        let mut face_surface: Vec<u16> = Vec::new();

        // Lateral walls: rows of loop vertices from bottom (row 0) to top (row `layers`).
        let mut rows_start: Vec<usize> = Vec::new(); // first vertex index of each loop's grid
        for poly in &polygons {
            let n = poly.points.len();
            let start = vertices.len();
            rows_start.push(start);
            for j in 0..=layers {
                let z = -half + height * j as Real / layers as Real;
                vertices.extend(poly.points.iter().map(|q| Point::new(q.x, q.y, z)));
            }
            for j in 0..layers {
                for i in 0..n {
                    let i1 = (i + 1) % n;
                    let b0 = (start + j * n + i) as u32;
                    let b1 = (start + j * n + i1) as u32;
                    let t0 = (start + (j + 1) * n + i) as u32;
                    let t1 = (start + (j + 1) * n + i1) as u32;
                    let s = (2 + poly.segment_arc[i]) as u16;
                    triangles.push([b0, b1, t1]);
                    triangles.push([b0, t1, t0]);
                    face_surface.extend([s, s]);
                }
            }
        }

        // Caps: one 2-D triangulation, used at both ends.
        let loops: Vec<Vec<Vector2>> = polygons.iter().map(|p| p.points.clone()).collect();
        let (all_points, cap_triangles) = triangulate_region(&loops, Some(edge))?;
        let interior = &all_points[loops.iter().map(Vec::len).sum::<usize>()..];
        // Map a cap vertex (loop l, index i) or an interior point to mesh vertices.
        let loop_offsets: Vec<usize> = polygons
            .iter()
            .scan(0, |acc, p| {
                let o = *acc;
                *acc += p.points.len();
                Some(o)
            })
            .collect();
        let loop_count: usize = polygons.iter().map(|p| p.points.len()).sum();
        let bottom_interior = vertices.len();
        vertices.extend(interior.iter().map(|q| Point::new(q.x, q.y, -half)));
        let top_interior = vertices.len();
        vertices.extend(interior.iter().map(|q| Point::new(q.x, q.y, half)));
        let to_mesh = |k: usize, top: bool| -> u32 {
            if k < loop_count {
                let l = loop_offsets.iter().rposition(|&o| o <= k).unwrap_or(0);
                let i = k - loop_offsets[l];
                let n = polygons[l].points.len();
                let row = if top { layers } else { 0 };
                (rows_start[l] + row * n + i) as u32
            } else {
                let base = if top { top_interior } else { bottom_interior };
                (base + k - loop_count) as u32
            }
        };
        for tri in &cap_triangles {
            triangles.push([to_mesh(tri[0], true), to_mesh(tri[1], true), to_mesh(tri[2], true)]);
            face_surface.push(1);
            triangles.push([to_mesh(tri[0], false), to_mesh(tri[2], false), to_mesh(tri[1], false)]);
            face_surface.push(0);
        }
        let mut fm = FeatureMesh { mesh: TriMesh { vertices, triangles }, face_surface, surfaces };
        fm.project_vertices();
        Ok(fm)
    }
}

/// Triangulates the region bounded by the polygons (first the outer one,
/// the rest holes), with a hexagonal lattice of interior points of spacing
/// `lattice` if given. Returns all points (the loops' in order, then the
/// interior ones) and counter-clockwise triangles indexing them.
pub fn triangulate_region(
    loops: &[Vec<Vector2>],
    lattice: Option<Real>,
) -> Result<(Vec<Vector2>, Vec<[usize; 3]>), GeomError> {
    let boundary: Vec<Vector2> = loops.iter().flatten().copied().collect();
    let segments: Vec<(Vector2, Vector2)> = loops
        .iter()
        .flat_map(|p| {
            let n = p.len();
            (0..n).map(move |i| (p[i], p[(i + 1) % n]))
        })
        .collect();
    let inside = |q: &Vector2| -> bool { loops.iter().enumerate().all(|(l, p)| point_in_polygon(q, p) == (l == 0)) };
    // Hexagonal lattice of interior points, kept half an edge away from the loops.
    let (mut lo, mut hi) = (boundary[0], boundary[0]);
    for q in &boundary {
        lo = lo.inf(q);
        hi = hi.sup(q);
    }
    let mut interior = Vec::new();
    let edge = lattice.unwrap_or(Real::INFINITY);
    let dy = edge * 3f64.sqrt() / 2.0;
    let rows = if lattice.is_some() { ((hi.y - lo.y) / dy).ceil() as i64 } else { -1 };
    for r in 0..=rows {
        let y = lo.y + r as Real * dy;
        let shift = if r % 2 == 0 { 0.0 } else { 0.5 * edge };
        let cols = ((hi.x - lo.x) / edge).ceil() as i64;
        for c in 0..=cols {
            let q = Vector2::new(lo.x + shift + c as Real * edge, y);
            if inside(&q) && segments.iter().all(|(a, b)| segment_distance(&q, a, b) > 0.6 * edge) {
                interior.push(q);
            }
        }
    }
    let mut cdt: ConstrainedDelaunayTriangulation<Point2<Real>> = ConstrainedDelaunayTriangulation::new();
    let mut handles = Vec::new();
    for q in boundary.iter().chain(interior.iter()) {
        let h = cdt
            .insert(Point2::new(q.x, q.y))
            .map_err(|e| GeomError::Meshing(format!("cap triangulation failed: {e:?}")))?;
        handles.push(h);
    }
    if cdt.num_vertices() != handles.len() {
        return Err(GeomError::Meshing(
            "cap triangulation merged coincident points: the shape's features are too small for the resolution".into(),
        ));
    }
    // No point was merged, so spade's vertex indices are the insertion order.
    debug_assert!(handles.iter().enumerate().all(|(i, h)| h.index() == i));
    let mut offset = 0;
    for p in loops {
        let n = p.len();
        for i in 0..n {
            let (a, b) = (handles[offset + i], handles[offset + (i + 1) % n]);
            if cdt.can_add_constraint(a, b) {
                cdt.add_constraint(a, b);
            } else {
                return Err(GeomError::Meshing(
                    "cap boundary segments cross: the cross-section's loops overlap".into(),
                ));
            }
        }
        offset += n;
    }
    let mut triangles = Vec::new();
    for face in cdt.inner_faces() {
        let [a, b, c] = face.vertices().map(|v| v.fix().index());
        let pa = point_at(a, &boundary, &interior);
        let pb = point_at(b, &boundary, &interior);
        let pc = point_at(c, &boundary, &interior);
        let centroid = (pa + pb + pc) / 3.0;
        if !inside(&centroid) {
            continue;
        }
        let orient = (pb - pa).perp(&(pc - pa));
        triangles.push(if orient > 0.0 { [a, b, c] } else { [a, c, b] });
    }
    let mut all = boundary;
    all.extend(interior);
    Ok((all, triangles))
}

fn point_at(k: usize, boundary: &[Vector2], interior: &[Vector2]) -> Vector2 {
    if k < boundary.len() {
        boundary[k]
    } else {
        interior[k - boundary.len()]
    }
}

/// Even-odd point-in-polygon test.
pub fn point_in_polygon(q: &Vector2, poly: &[Vector2]) -> bool {
    let mut inside = false;
    let n = poly.len();
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        if (a.y > q.y) != (b.y > q.y) {
            let x = a.x + (q.y - a.y) * (b.x - a.x) / (b.y - a.y);
            if q.x < x {
                inside = !inside;
            }
        }
    }
    inside
}

fn segment_distance(q: &Vector2, a: &Vector2, b: &Vector2) -> Real {
    let ab = b - a;
    let t = ((q - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
    (q - (a + ab * t)).norm()
}
