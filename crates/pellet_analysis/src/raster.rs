//! Crossings of parallel lines with a closed triangle mesh.
//!
//! Every vertical world line is, in a pellet's body frame, parallel to one
//! direction `d`. The mesh is projected once onto the plane normal to `d`
//! and its triangles are binned in a uniform 2-D grid; a line is then a
//! point query. Each triangle the point falls in is a crossing at the depth
//! interpolated from its corners, entering or leaving by the sign of the
//! projected area (the outward normal against `d`). Sorting the crossings
//! and following the winding count gives the inside intervals, which also
//! tolerates a line that grazes an edge.
//!
//! A point on an edge shared by two triangles must be counted exactly once.
//! Edge functions are evaluated in a canonical vertex order, so both
//! triangles see the same number, and a zero is claimed by one of them only
//! (the rasteriser's top-left rule).

use pellet_geom::math::{Real, Vector};
use pellet_geom::TriMesh;

/// A mesh projected along a direction, binned for point queries.
pub struct MeshRaster {
    /// Projected vertex coordinates on the plane normal to `d` (m).
    planar: Vec<[Real; 2]>,
    /// Vertex depths along `d` (m).
    depth: Vec<Real>,
    /// Triangles with a non-zero projected area, and the sign of that area.
    triangles: Vec<([u32; 3], Real)>,
    /// Basis of the projection plane.
    e1: Vector,
    e2: Vector,
    direction: Vector,
    grid: Grid,
    footprint: Real,
    half_extent: Real,
}

/// A uniform grid of cells, each listing the triangles whose bounding box overlaps it.
struct Grid {
    min: [Real; 2],
    inv_cell: Real,
    dims: [usize; 2],
    starts: Vec<u32>,
    items: Vec<u32>,
}

impl MeshRaster {
    /// Projects `mesh` (body frame) along the unit vector `direction`.
    pub fn new(mesh: &TriMesh, direction: &Vector) -> MeshRaster {
        let d = direction.normalize();
        // Any unit vector not parallel to d starts the basis; (e1, e2, d) is right-handed.
        let helper = if d.x.abs() < 0.6 { Vector::x() } else { Vector::y() };
        let e1 = helper.cross(&d).normalize();
        let e2 = d.cross(&e1);
        let planar: Vec<[Real; 2]> = mesh.vertices.iter().map(|v| [v.coords.dot(&e1), v.coords.dot(&e2)]).collect();
        let depth: Vec<Real> = mesh.vertices.iter().map(|v| v.coords.dot(&d)).collect();
        let mut triangles = Vec::with_capacity(mesh.triangles.len());
        for &t in &mesh.triangles {
            let [a, b, c] = t.map(|i| planar[i as usize]);
            let area2 = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
            // Edge-on triangles have no interior a line can cross.
            if area2 != 0.0 {
                triangles.push((t, area2.signum()));
            }
        }
        let footprint = planar.iter().map(|p| p[0].hypot(p[1])).fold(0.0, Real::max);
        let half_extent = depth.iter().map(|z| z.abs()).fold(0.0, Real::max);
        let grid = Grid::new(&planar, &triangles);
        MeshRaster { planar, depth, triangles, e1, e2, direction: d, grid, footprint, half_extent }
    }

    /// Largest distance of a vertex from the line through the origin along `d` (m).
    pub fn footprint(&self) -> Real {
        self.footprint
    }

    /// Largest |depth| of a vertex along `d` (m).
    pub fn half_extent(&self) -> Real {
        self.half_extent
    }

    /// Appends the intervals where the line `origin + s·d` is inside the
    /// mesh, as `(offset + s_in, offset + s_out)`.
    pub fn intervals(&self, origin: &Vector, offset: Real, out: &mut Vec<(Real, Real)>) {
        let p = [origin.dot(&self.e1), origin.dot(&self.e2)];
        let shift = origin.dot(&self.direction);
        let Some(cell) = self.grid.cell(p) else { return };
        let mut crossings: Vec<(Real, i32)> = Vec::new();
        for &t in self.grid.items_in(cell) {
            let (tri, sign) = self.triangles[t as usize];
            if let Some(depth) = self.crossing(tri, sign, p) {
                // Positive projected area: the outward normal points along d, the line leaves.
                crossings.push((depth - shift, if sign > 0.0 { -1 } else { 1 }));
            }
        }
        if crossings.is_empty() {
            return;
        }
        crossings.sort_by(|a, b| a.0.total_cmp(&b.0).then(b.1.cmp(&a.1)));
        let mut winding = 0;
        let mut start = 0.0;
        for (s, step) in crossings {
            let before = winding;
            winding += step;
            if before <= 0 && winding > 0 {
                start = s;
            } else if before > 0 && winding <= 0 && s > start {
                out.push((offset + start, offset + s));
            }
        }
    }

    /// The depth at which the line through the planar point `p` crosses
    /// triangle `tri`, if it does (top-left rule on edges).
    fn crossing(&self, tri: [u32; 3], sign: Real, p: [Real; 2]) -> Option<Real> {
        let mut weights = [0.0; 3];
        for k in 0..3 {
            let (a, b) = (tri[(k + 1) % 3], tri[(k + 2) % 3]);
            // Canonical order: both triangles sharing the edge get the same value.
            let (u, v, flip) = if a < b { (a, b, 1.0) } else { (b, a, -1.0) };
            let (pu, pv) = (self.planar[u as usize], self.planar[v as usize]);
            let g = (pv[0] - pu[0]) * (p[1] - pu[1]) - (pv[1] - pu[1]) * (p[0] - pu[0]);
            let f = flip * g * sign;
            if f < 0.0 {
                return None;
            }
            if f == 0.0 {
                // The edge a→b as seen by a counter-clockwise copy of the triangle.
                let (pa, pb) = (self.planar[a as usize], self.planar[b as usize]);
                let e = [(pb[0] - pa[0]) * sign, (pb[1] - pa[1]) * sign];
                let owned = e[1] > 0.0 || (e[1] == 0.0 && e[0] < 0.0);
                if !owned {
                    return None;
                }
            }
            weights[k] = f;
        }
        let total: Real = weights.iter().sum();
        if total <= 0.0 {
            return None;
        }
        let z = tri.iter().zip(weights).map(|(&i, w)| w * self.depth[i as usize]).sum::<Real>();
        Some(z / total)
    }
}

impl Grid {
    fn new(planar: &[[Real; 2]], triangles: &[([u32; 3], Real)]) -> Grid {
        let mut min = [Real::INFINITY; 2];
        let mut max = [Real::NEG_INFINITY; 2];
        for p in planar {
            for k in 0..2 {
                min[k] = min[k].min(p[k]);
                max[k] = max[k].max(p[k]);
            }
        }
        let span = (max[0] - min[0]).max(max[1] - min[1]).max(Real::MIN_POSITIVE);
        // About one cell per triangle keeps the lists short.
        let per_side = ((triangles.len() as Real).sqrt().ceil() as usize).clamp(1, 256);
        let inv_cell = per_side as Real / span;
        let dims = [
            (((max[0] - min[0]) * inv_cell) as usize + 1).min(per_side),
            (((max[1] - min[1]) * inv_cell) as usize + 1).min(per_side),
        ];
        let mut grid = Grid { min, inv_cell, dims, starts: Vec::new(), items: Vec::new() };
        let ranges: Vec<[usize; 4]> = triangles
            .iter()
            .map(|(t, _)| {
                let pts = t.map(|i| planar[i as usize]);
                let lo = grid.index([pts[0][0].min(pts[1][0]).min(pts[2][0]), pts[0][1].min(pts[1][1]).min(pts[2][1])]);
                let hi = grid.index([pts[0][0].max(pts[1][0]).max(pts[2][0]), pts[0][1].max(pts[1][1]).max(pts[2][1])]);
                [lo[0], hi[0], lo[1], hi[1]]
            })
            .collect();
        let mut counts = vec![0u32; dims[0] * dims[1] + 1];
        for r in &ranges {
            for i in r[0]..=r[1] {
                for j in r[2]..=r[3] {
                    counts[i * dims[1] + j + 1] += 1;
                }
            }
        }
        for c in 1..counts.len() {
            counts[c] += counts[c - 1];
        }
        let mut fill = counts.clone();
        let mut items = vec![0u32; *counts.last().unwrap_or(&0) as usize];
        for (t, r) in ranges.iter().enumerate() {
            for i in r[0]..=r[1] {
                for j in r[2]..=r[3] {
                    let c = i * dims[1] + j;
                    items[fill[c] as usize] = t as u32;
                    fill[c] += 1;
                }
            }
        }
        grid.starts = counts;
        grid.items = items;
        grid
    }

    /// Cell coordinates of a point, clamped to the grid.
    fn index(&self, p: [Real; 2]) -> [usize; 2] {
        let f = |k: usize| (((p[k] - self.min[k]) * self.inv_cell).max(0.0) as usize).min(self.dims[k] - 1);
        [f(0), f(1)]
    }

    /// The cell holding `p`, or `None` outside the grid.
    fn cell(&self, p: [Real; 2]) -> Option<usize> {
        for (k, &x) in p.iter().enumerate() {
            let u = (x - self.min[k]) * self.inv_cell;
            if !(u >= 0.0 && u <= self.dims[k] as Real) {
                return None;
            }
        }
        let [i, j] = self.index(p);
        Some(i * self.dims[1] + j)
    }

    fn items_in(&self, cell: usize) -> &[u32] {
        &self.items[self.starts[cell] as usize..self.starts[cell + 1] as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pellet_geom::{Pellet, Resolution, ShapeSpec};

    #[test]
    fn a_line_through_a_ring_mesh_meets_both_walls() {
        let spec = ShapeSpec::Ring { outer_diameter_mm: 10.0, inner_diameter_mm: 6.0, height_mm: 10.0 };
        let ring = Pellet::build(spec, Resolution::default()).unwrap();
        // Along body x through the centre: walls at |x| in [3, 5] mm.
        let raster = MeshRaster::new(&ring.mesh, &Vector::x());
        let mut out = Vec::new();
        raster.intervals(&Vector::new(0.0, 0.0, 0.001), 0.0, &mut out);
        assert_eq!(out.len(), 2, "{out:?}");
        for (got, want) in out.iter().zip([(-0.005, -0.003), (0.003, 0.005)]) {
            assert!((got.0 - want.0).abs() < 2e-5 && (got.1 - want.1).abs() < 2e-5, "{got:?} vs {want:?}");
        }
        // Along the axis through the hole: nothing; through the wall: the full height.
        out.clear();
        let axial = MeshRaster::new(&ring.mesh, &Vector::z());
        axial.intervals(&Vector::zeros(), 0.0, &mut out);
        assert!(out.is_empty(), "{out:?}");
        axial.intervals(&Vector::new(0.004, 0.0, 0.0), 1.0, &mut out);
        assert_eq!(out.len(), 1);
        assert!((out[0].0 - (1.0 - 0.005)).abs() < 1e-12 && (out[0].1 - 1.005).abs() < 1e-12, "{out:?}");
    }

    #[test]
    fn lines_through_vertices_and_edges_are_counted_once() {
        // Level-0 cylinder: few, large triangles, and lines through the cap's vertices.
        let cyl = Pellet::build(
            ShapeSpec::Cylinder { diameter_mm: 10.0, height_mm: 10.0 },
            Resolution { level: 0, faces: Some(100) },
        )
        .unwrap();
        let raster = MeshRaster::new(&cyl.mesh, &Vector::z());
        let mut out = Vec::new();
        for v in &cyl.mesh.vertices {
            out.clear();
            let point = Vector::new(v.x * 0.999_999, v.y * 0.999_999, 0.0);
            raster.intervals(&Vector::new(v.x, v.y, 0.0), 0.0, &mut out);
            let inner = out.clone();
            out.clear();
            raster.intervals(&point, 0.0, &mut out);
            let total: Real = inner.iter().map(|(a, b)| b - a).sum();
            assert!(total <= 0.010 + 1e-12, "vertex line counted twice: {inner:?}");
            assert_eq!(out.len(), 1, "{out:?}");
        }
    }
}
