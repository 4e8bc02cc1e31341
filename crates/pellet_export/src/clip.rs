//! Cutting closed meshes at horizontal planes and capping the cut, so that
//! a slice of a bed exports as closed surfaces.
//!
//! Each triangle is clipped to the kept half-space (new vertices on the
//! crossed edges are shared by the two triangles of each edge, so the
//! surface stays watertight); the cut edges form closed loops in the plane
//! (several, nested for holes, e.g. a ring cut across its axis), filled by
//! a constrained Delaunay triangulation (spade) whose faces are taken by
//! parity across the loops.

use std::collections::HashMap;

use pellet_geom::math::{Point, Real};
use pellet_geom::TriMesh;
use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};

use crate::ExportError;

/// Which side of the plane z = `level` is kept.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Keep {
    /// z ≤ level (the cap faces +z).
    Below,
    /// z ≥ level (the cap faces −z).
    Above,
}

/// `mesh` (closed, outward) cut by the plane z = `level`, the part on the
/// `keep` side, closed by a flat cap. `None` when nothing is kept.
pub fn clip_at(mesh: &TriMesh, level: Real, keep: Keep) -> Result<Option<TriMesh>, ExportError> {
    let sign = match keep {
        Keep::Below => 1.0,
        Keep::Above => -1.0,
    };
    // Vertices exactly on the plane would make zero-length cut edges: move
    // the plane by a nanometre-scale step until none lies on it.
    let mut level = level;
    let scale = mesh.max_radius().max(level.abs()).max(1e-3);
    for _ in 0..8 {
        if mesh.vertices.iter().all(|v| (v.z - level).abs() > 1e-9 * scale) {
            break;
        }
        level += 3e-9 * scale * sign;
    }
    let side: Vec<Real> = mesh.vertices.iter().map(|v| sign * (v.z - level)).collect();
    if side.iter().all(|&s| s < 0.0) {
        return Ok(Some(mesh.clone()));
    }
    if side.iter().all(|&s| s > 0.0) {
        return Ok(None);
    }
    let mut vertices: Vec<Point> = Vec::new();
    let kept: Vec<Option<u32>> = mesh
        .vertices
        .iter()
        .zip(&side)
        .map(|(v, &s)| {
            (s < 0.0).then(|| {
                vertices.push(*v);
                (vertices.len() - 1) as u32
            })
        })
        .collect();
    let mut crossing: HashMap<(u32, u32), u32> = HashMap::new();
    let mut cut = |a: u32, b: u32, vertices: &mut Vec<Point>| -> u32 {
        *crossing.entry((a.min(b), a.max(b))).or_insert_with(|| {
            let (pa, pb) = (mesh.vertices[a as usize], mesh.vertices[b as usize]);
            let (sa, sb) = (side[a as usize], side[b as usize]);
            let mut p = pa + (pb - pa) * (sa / (sa - sb));
            p.z = level;
            vertices.push(p);
            (vertices.len() - 1) as u32
        })
    };
    let mut triangles = Vec::new();
    // Boundary edges of the clipped surface, directed as in its triangles.
    let mut next: HashMap<u32, u32> = HashMap::new();
    for t in &mesh.triangles {
        let inside = t.map(|v| side[v as usize] < 0.0);
        match inside.iter().filter(|&&i| i).count() {
            3 => triangles.push(t.map(|v| kept[v as usize].expect("kept"))),
            0 => {}
            count => {
                // Rotate so the triangle reads (a, b, c) with a kept and c not (count 2: b kept; count 1: b not).
                let r = (0..3)
                    .find(|&k| inside[k] && !inside[(k + 2) % 3] && (count == 1 || inside[(k + 1) % 3]))
                    .expect("a kept vertex follows a cut one");
                let [a, b, c] = [t[r], t[(r + 1) % 3], t[(r + 2) % 3]];
                let ka = kept[a as usize].expect("kept");
                if count == 1 {
                    let (ab, ca) = (cut(a, b, &mut vertices), cut(c, a, &mut vertices));
                    triangles.push([ka, ab, ca]);
                    next.insert(ab, ca);
                } else {
                    let kb = kept[b as usize].expect("kept");
                    let (bc, ca) = (cut(b, c, &mut vertices), cut(c, a, &mut vertices));
                    triangles.push([ka, kb, bc]);
                    triangles.push([ka, bc, ca]);
                    next.insert(bc, ca);
                }
            }
        }
    }
    let loops = chain_loops(next)?;
    for tri in cap(&loops, &vertices)
        .map_err(|why| ExportError::BadParameter(format!("capping the cut at z = {} mm failed: {why}", level * 1e3)))?
    {
        // Spade's faces run counter-clockwise seen from +z.
        triangles.push(if keep == Keep::Below { tri } else { [tri[0], tri[2], tri[1]] });
    }
    Ok(Some(TriMesh { vertices, triangles }))
}

/// The closed loops formed by the directed boundary edges.
fn chain_loops(mut next: HashMap<u32, u32>) -> Result<Vec<Vec<u32>>, ExportError> {
    let mut loops = Vec::new();
    let mut starts: Vec<u32> = next.keys().copied().collect();
    starts.sort_unstable();
    for start in starts {
        if !next.contains_key(&start) {
            continue;
        }
        let mut ring = vec![start];
        let mut at = next.remove(&start).expect("present");
        while at != start {
            ring.push(at);
            at = next.remove(&at).ok_or_else(|| {
                ExportError::BadParameter("the cut of a pellet's mesh is not a closed loop: is the mesh closed?".into())
            })?;
        }
        loops.push(ring);
    }
    Ok(loops)
}

/// Triangles (counter-clockwise seen from +z) filling the region the
/// loops bound in their plane: a constrained Delaunay triangulation whose
/// faces are classified by parity, flooding from the outside and toggling
/// at every loop edge crossed (no point-in-polygon test, which slivers
/// between nearly collinear cut points would fool).
fn cap(loops: &[Vec<u32>], vertices: &[Point]) -> Result<Vec<[u32; 3]>, String> {
    let mut cdt: ConstrainedDelaunayTriangulation<Point2<Real>> = ConstrainedDelaunayTriangulation::new();
    let mut ours: HashMap<usize, u32> = HashMap::new();
    let mut handles = Vec::with_capacity(loops.len());
    for ring in loops {
        let mut ring_handles = Vec::with_capacity(ring.len());
        for &v in ring {
            let p = vertices[v as usize];
            let h = cdt.insert(Point2::new(p.x, p.y)).map_err(|e| format!("{e:?}"))?;
            if ours.insert(h.index(), v).is_some() {
                return Err("two cut points coincide; move the window by a fraction of a millimetre".into());
            }
            ring_handles.push(h);
        }
        handles.push(ring_handles);
    }
    for ring in &handles {
        for k in 0..ring.len() {
            let (a, b) = (ring[k], ring[(k + 1) % ring.len()]);
            if !cdt.can_add_constraint(a, b) {
                return Err("the cut's loops cross each other".into());
            }
            cdt.add_constraint(a, b);
        }
    }
    let mut inside: Vec<Option<bool>> = vec![None; cdt.num_all_faces()];
    let mut queue = std::collections::VecDeque::new();
    for face in cdt.inner_faces() {
        for edge in face.adjacent_edges() {
            if edge.rev().face().is_outer() && inside[face.fix().index()].is_none() {
                inside[face.fix().index()] = Some(cdt.is_constraint_edge(edge.as_undirected().fix()));
                queue.push_back(face.fix());
            }
        }
    }
    while let Some(f) = queue.pop_front() {
        let state = inside[f.index()].expect("set when queued");
        for edge in cdt.face(f).adjacent_edges() {
            if let Some(next) = edge.rev().face().as_inner() {
                if inside[next.fix().index()].is_none() {
                    inside[next.fix().index()] = Some(state ^ cdt.is_constraint_edge(edge.as_undirected().fix()));
                    queue.push_back(next.fix());
                }
            }
        }
    }
    Ok(cdt
        .inner_faces()
        .filter(|f| inside[f.fix().index()] == Some(true))
        .map(|f| f.vertices().map(|v| ours[&v.fix().index()]))
        .collect())
}

/// `mesh` cut to the slab z0 ≤ z ≤ z1 and capped; `None` if nothing is left.
pub fn clip_to_slab(mesh: &TriMesh, z0: Real, z1: Real) -> Result<Option<TriMesh>, ExportError> {
    match clip_at(mesh, z1, Keep::Below)? {
        Some(below) => clip_at(&below, z0, Keep::Above),
        None => Ok(None),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{enclosed_volume, world_mesh};
    use pellet_analysis::clip::volume_in_slab;
    use pellet_analysis::Geometry;
    use pellet_geom::{Pellet, PlacedPellet, Resolution, ShapeSpec};

    #[test]
    fn cut_pellets_are_closed_and_hold_the_slab_volume() {
        let ring = Pellet::build(
            ShapeSpec::Ring { outer_diameter_mm: 10.0, inner_diameter_mm: 6.0, height_mm: 10.0 },
            Resolution::default(),
        )
        .unwrap();
        let sphere = Pellet::build(ShapeSpec::Sphere { diameter_mm: 10.0 }, Resolution::default()).unwrap();
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let upright = [1.0, 0.0, 0.0, 0.0];
        let lying = [s, s, 0.0, 0.0];
        let tilted = [0.9238795325112867, 0.0, 0.3826834323650898, 0.0];
        // Rings cut across the hole (a loop with a hole), along it (two
        // loops), tilted; a sphere cut through its middle and near a pole.
        let cases = [
            (&ring, upright, 0.0061, 0.0200),
            (&ring, lying, 0.0050, 0.0200),
            (&ring, lying, 0.0030, 0.0071),
            (&ring, tilted, 0.0, 0.0064),
            (&sphere, upright, 0.0050, 0.0200),
            (&sphere, upright, 0.0001, 0.0095),
        ];
        for (pellet, orientation, z0, z1) in cases {
            let pose = PlacedPellet { type_index: 0, position: [0.0, 0.0, 0.005], orientation };
            let mesh = world_mesh(pellet, &pose, 1.0);
            let cut = clip_to_slab(&mesh, z0, z1).unwrap().unwrap();
            let topology = cut.check_closed().unwrap_or_else(|e| panic!("{z0} {z1}: {e}"));
            assert!(topology.components >= 1);
            let exact = volume_in_slab(pellet, &pose, z0, z1, Geometry::Mesh);
            assert!(
                (enclosed_volume(&cut) / exact - 1.0).abs() < 1e-7,
                "{z0} {z1}: {} vs {exact}",
                enclosed_volume(&cut)
            );
        }
        // Wholly inside: unchanged; wholly outside: nothing.
        let pose = PlacedPellet { type_index: 0, position: [0.0, 0.0, 0.005], orientation: upright };
        let mesh = world_mesh(&sphere, &pose, 1.0);
        assert_eq!(clip_to_slab(&mesh, -0.001, 0.011).unwrap().unwrap(), mesh);
        assert!(clip_to_slab(&mesh, 0.011, 0.02).unwrap().is_none());
    }
}
