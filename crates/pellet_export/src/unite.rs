//! One closed manifold surface from closed meshes that may overlap — the
//! pellets and the bridges joining them, or pellets that touch: their
//! union, by mesh booleans (the `manifold-rust` port of Manifold), so that
//! a mesher sees the real concave edge where a bridge meets a pellet and
//! no surface inside another solid. [`cut`] takes the part of a pellet
//! beyond planes away (the caps treatment) by the same booleans.
//!
//! The union is evaluated as one CSG tree (deterministic: the same meshes
//! in the same order give the same surface), then edges shorter than a
//! tolerance are collapsed: the booleans leave slivers where two surfaces
//! meet at a grazing angle, which fold over once a mesher reads the
//! coordinates in single precision. Its volume is the solid's, overlaps
//! counted once; [`United::volume_in_tube`] clips it to the tube's inside
//! for the fluid volume a mesher should find.

use manifold_rust::csg_tree::CsgNode;
use manifold_rust::linalg::Vec3;
use manifold_rust::manifold::Manifold;
use manifold_rust::types::{Error as ManifoldError, MeshGL64, OpType};

use std::collections::HashMap;

use pellet_geom::math::{Point, Real, Vector};
use pellet_geom::TriMesh;

use crate::ExportError;

/// The union of several closed meshes.
pub struct United {
    solid: Manifold,
    mesh: TriMesh,
    tolerance: Real,
}

impl United {
    /// The union as one triangle mesh (outward triangles, shared vertices).
    pub fn mesh(&self) -> &TriMesh {
        &self.mesh
    }

    /// The tolerance that gave a sound surface (m).
    pub fn tolerance(&self) -> Real {
        self.tolerance
    }

    /// The enclosed volume (overlaps counted once).
    pub fn volume(&self) -> f64 {
        self.solid.volume()
    }

    /// The volume of the union inside the closed mesh `tube` (its inside,
    /// e.g. [`crate::scene::tube_mesh`]): what bridges or pellets poking
    /// into the wall take from the fluid.
    pub fn volume_in_tube(&self, tube: &TriMesh) -> Result<f64, ExportError> {
        let tube = to_manifold(tube, 0.0).map_err(|why| ExportError::Union(format!("the tube surface: {why}")))?;
        Ok(self.solid.intersection(&tube).volume())
    }

    /// How many separate pieces the union has (a bed joined by bridges
    /// may still be several).
    pub fn pieces(&self) -> usize {
        // Union-find over the triangles' vertices: linear, where Manifold's
        // decompose copies every piece (35 s on a 600-sphere bed).
        let mut parent: Vec<u32> = (0..self.mesh.vertices.len() as u32).collect();
        fn root(parent: &mut [u32], mut v: u32) -> u32 {
            while parent[v as usize] != v {
                parent[v as usize] = parent[parent[v as usize] as usize];
                v = parent[v as usize];
            }
            v
        }
        for t in &self.mesh.triangles {
            for k in 1..3 {
                let (a, b) = (root(&mut parent, t[0]), root(&mut parent, t[k]));
                parent[a.max(b) as usize] = a.min(b);
            }
        }
        let mut used = vec![false; parent.len()];
        for t in &self.mesh.triangles {
            for &v in t {
                used[v as usize] = true;
            }
        }
        (0..parent.len() as u32).filter(|&v| used[v as usize] && root(&mut parent, v) == v).count()
    }
}

/// The union of `meshes` (each closed and outward), with edges shorter
/// than a tolerance collapsed and coplanar triangles merged where that
/// moves the surface by less than it. The tolerances (m) are tried in
/// turn until the surface is [`sound_in_single_precision`]: the booleans
/// may leave two sheets meeting along an edge or a sliver that folds
/// over once rounded, and another tolerance resolves them differently.
/// `names` says what each mesh is, for the error if one is not a closed
/// manifold.
pub fn unite(meshes: &[&TriMesh], names: &dyn Fn(usize) -> String, tolerances: &[Real]) -> Result<United, ExportError> {
    let mut faults = String::from("no tolerance given");
    for &tolerance in tolerances {
        let mut leaves = Vec::with_capacity(meshes.len());
        for (k, m) in meshes.iter().enumerate() {
            let solid = to_manifold(m, tolerance).map_err(|why| ExportError::Union(format!("{}: {why}", names(k))))?;
            leaves.push(CsgNode::leaf(solid.as_impl().clone()));
        }
        if leaves.is_empty() {
            return Ok(United { solid: Manifold::empty(), mesh: TriMesh::default(), tolerance });
        }
        let solid = Manifold::from_impl(CsgNode::op_n(OpType::Add, leaves).evaluate()).simplify(tolerance);
        let status = solid.status();
        if status != ManifoldError::NoError {
            return Err(ExportError::Union(format!(
                "the union of the pellet surfaces failed ({status:?}); the pellet meshes may be damaged: rebuild them with mkpellet"
            )));
        }
        let mesh = from_manifold(&solid);
        match sound_in_single_precision(&mesh) {
            Ok(()) => return Ok(United { solid, mesh, tolerance }),
            Err(why) => faults = why,
        }
    }
    Err(ExportError::Union(format!(
        "the union of the pellet surfaces is not one closed surface ({faults}); export with another --treatment or --cell-size"
    )))
}

/// Whether `mesh` stays a closed, consistently oriented surface that does
/// not cross itself once its coordinates are rounded to single precision
/// (as OpenFOAM reads STL): vertices welded by position, every edge is
/// used once in each direction, no triangle collapses, and no two
/// triangles that share no vertex cross (an edge of one through the
/// other, over a grid of their bounding boxes).
pub fn sound_in_single_precision(mesh: &TriMesh) -> Result<(), String> {
    let mut welded: HashMap<[u32; 3], u32> = HashMap::new();
    let mut points: Vec<Point> = Vec::new();
    let ids: Vec<u32> = mesh
        .vertices
        .iter()
        .map(|p| {
            let key = [p.x, p.y, p.z].map(|c| (c as f32).to_bits());
            *welded.entry(key).or_insert_with(|| {
                points.push(Point::new(p.x as f32 as Real, p.y as f32 as Real, p.z as f32 as Real));
                points.len() as u32 - 1
            })
        })
        .collect();
    let triangles: Vec<[u32; 3]> = mesh.triangles.iter().map(|t| t.map(|v| ids[v as usize])).collect();
    let mut directed: HashMap<(u32, u32), u32> = HashMap::new();
    for t in &triangles {
        if t[0] == t[1] || t[1] == t[2] || t[2] == t[0] {
            return Err(format!("a triangle collapses at {:?}", points[t[0] as usize]));
        }
        for k in 0..3 {
            *directed.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
        }
    }
    for (&(a, b), &n) in &directed {
        if n != 1 || directed.get(&(b, a)) != Some(&1) {
            return Err(format!("an edge is not shared by exactly two triangles at {:?}", points[a as usize]));
        }
    }
    let corners = |t: usize| triangles[t].map(|v| points[v as usize]);
    if let Some((s, _)) = crossing_pair(&triangles, &corners) {
        return Err(format!("two triangles cross at {:?}", corners(s)[0]));
    }
    Ok(())
}

/// Some pair of triangles sharing no vertex whose interiors cross.
fn crossing_pair(triangles: &[[u32; 3]], corners: &dyn Fn(usize) -> [Point; 3]) -> Option<(usize, usize)> {
    let boxes: Vec<(Point, Point)> = (0..triangles.len())
        .map(|t| {
            let c = corners(t);
            (c[0].inf(&c[1]).inf(&c[2]), c[0].sup(&c[1]).sup(&c[2]))
        })
        .collect();
    if boxes.is_empty() {
        return None;
    }
    let cell = 2.0 * boxes.iter().map(|(lo, hi)| (hi - lo).norm()).sum::<Real>() / boxes.len() as Real;
    let key = |p: &Point| [p.x, p.y, p.z].map(|c| (c / cell).floor() as i64);
    let mut grid: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
    for (t, (lo, hi)) in boxes.iter().enumerate() {
        let (l, h) = (key(lo), key(hi));
        for i in l[0]..=h[0] {
            for j in l[1]..=h[1] {
                for k in l[2]..=h[2] {
                    grid.entry([i, j, k]).or_default().push(t);
                }
            }
        }
    }
    let mut cells: Vec<(&[i64; 3], &Vec<usize>)> = grid.iter().collect();
    // A fixed order: the first crossing found is the same every run.
    cells.sort_unstable_by_key(|(k, _)| **k);
    for (_, list) in cells {
        for (x, &s) in list.iter().enumerate() {
            for &t in &list[x + 1..] {
                let (bs, bt) = (&boxes[s], &boxes[t]);
                if (0..3).any(|d| bs.1[d] < bt.0[d] || bt.1[d] < bs.0[d])
                    || triangles[s].iter().any(|v| triangles[t].contains(v))
                {
                    continue;
                }
                let (cs, ct) = (corners(s), corners(t));
                if (0..3).any(|k| segment_crosses(&cs[k], &cs[(k + 1) % 3], &ct))
                    || (0..3).any(|k| segment_crosses(&ct[k], &ct[(k + 1) % 3], &cs))
                {
                    return Some((s, t));
                }
            }
        }
    }
    None
}

fn orient(a: &Point, b: &Point, c: &Point, d: &Point) -> Real {
    (b - a).cross(&(c - a)).dot(&(d - a))
}

/// Whether the segment pq passes through the inside of triangle abc
/// (touching is not crossing).
fn segment_crosses(p: &Point, q: &Point, [a, b, c]: &[Point; 3]) -> bool {
    if orient(a, b, c, p) * orient(a, b, c, q) >= 0.0 {
        return false;
    }
    let (u, v, w) = (orient(p, q, a, b), orient(p, q, b, c), orient(p, q, c, a));
    (u > 0.0 && v > 0.0 && w > 0.0) || (u < 0.0 && v < 0.0 && w < 0.0)
}

/// One cap: the part of a pellet with `n·x > offset` is taken away, everywhere or only inside a
/// ball (centre, radius).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cap {
    /// Unit normal, out of the pellet towards its partner.
    pub normal: Vector,
    /// The plane's offset: the pellet keeps `normal·x ≤ offset`.
    pub offset: Real,
    /// Where the cut is limited to, if anywhere.
    pub within: Option<(Point, Real)>,
}

/// `mesh` (closed and outward) less its parts beyond the caps' planes (within their balls, for
/// the caps limited to one). The cut faces are flat and the surface stays closed.
pub fn cut(mesh: &TriMesh, caps: &[Cap]) -> Result<TriMesh, String> {
    let mut solid = to_manifold(mesh, 0.0)?;
    let v = |p: &Vector| Vec3::new(p.x, p.y, p.z);
    let everywhere: Vec<&Cap> = caps.iter().filter(|c| c.within.is_none()).collect();
    if !everywhere.is_empty() {
        // One boolean with a convex cutter (a box around the mesh trimmed by
        // every plane) instead of one per plane: a pellet of a dense bed has
        // about ten caps, and the cutter's booleans cost next to nothing.
        let b = solid.bounding_box();
        let (lo, hi) = (b.min, b.max);
        let size = Vec3::new(hi.x - lo.x, hi.y - lo.y, hi.z - lo.z) * 1.5;
        let centre = Vec3::new(0.5 * (lo.x + hi.x), 0.5 * (lo.y + hi.y), 0.5 * (lo.z + hi.z));
        let mut cutter = Manifold::cube(size, true).translate(centre);
        for c in everywhere {
            cutter = cutter.trim_by_plane(-v(&c.normal), -c.offset);
        }
        solid = solid.intersection(&cutter);
    }
    for c in caps {
        if let Some((centre, radius)) = c.within {
            // The ball's part beyond the plane: a lens-shaped cutter.
            let ball = Manifold::sphere(radius, 48).translate(v(&centre.coords));
            solid = solid.difference(&ball.trim_by_plane(v(&c.normal), c.offset));
        }
    }
    match solid.status() {
        ManifoldError::NoError => Ok(from_manifold(&solid)),
        status => Err(format!("cutting its caps failed ({status:?}); give another --cap-gap")),
    }
}

fn to_manifold(mesh: &TriMesh, tolerance: Real) -> Result<Manifold, String> {
    let gl = MeshGL64 {
        num_prop: 3,
        vert_properties: mesh.vertices.iter().flat_map(|p| [p.x, p.y, p.z]).collect(),
        tri_verts: mesh.triangles.iter().flat_map(|t| t.map(u64::from)).collect(),
        tolerance,
        ..MeshGL64::default()
    };
    let solid = Manifold::from_mesh_gl64(&gl);
    match solid.status() {
        ManifoldError::NoError => Ok(solid),
        ManifoldError::NotManifold => Err(
            "the mesh is not a closed manifold (an edge without exactly one opposite); rebuild the pellet with mkpellet"
                .into(),
        ),
        ManifoldError::NonFiniteVertex => Err("a vertex has a non-finite coordinate".into()),
        status => Err(format!("the mesh was refused ({status:?})")),
    }
}

fn from_manifold(solid: &Manifold) -> TriMesh {
    let gl = solid.get_mesh_gl64(-1);
    let stride = gl.num_prop as usize;
    let vertices = gl.vert_properties.chunks_exact(stride).map(|p| Point::new(p[0], p[1], p[2])).collect();
    let triangles = gl.tri_verts.chunks_exact(3).map(|t| [t[0] as u32, t[1] as u32, t[2] as u32]).collect();
    TriMesh { vertices, triangles }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{enclosed_volume, tube_mesh};
    use pellet_geom::{Pellet, Resolution, ShapeSpec};
    use std::f64::consts::PI;

    fn sphere_at(d_mm: f64, centre: [f64; 3]) -> TriMesh {
        let p = Pellet::build(ShapeSpec::Sphere { diameter_mm: d_mm }, Resolution::default()).unwrap();
        let mut m = p.mesh.clone();
        for v in &mut m.vertices {
            *v += pellet_geom::math::Vector::from(centre);
        }
        m
    }

    #[test]
    fn two_overlapping_spheres_count_their_lens_once() {
        // Spheres of radius r whose centres are a apart overlap in a lens
        // of volume π (4r + a)(2r − a)² / 12.
        let (r, a) = (0.005, 0.008);
        let (s1, s2) = (sphere_at(10.0, [0.0, 0.0, 0.0]), sphere_at(10.0, [a, 0.0, 0.0]));
        let u = unite(&[&s1, &s2], &|k| format!("sphere {k}"), &[1e-9]).unwrap();
        let each = enclosed_volume(&s1);
        // The mesh's own lens, scaled from the exact one by the mesh's volume deficit.
        let lens = PI * (4.0 * r + a) * (2.0 * r - a).powi(2) / 12.0 * each / (4.0 / 3.0 * PI * r.powi(3));
        let expected = 2.0 * each - lens;
        assert!((u.volume() - expected).abs() < 2e-3 * expected, "{} vs {expected}", u.volume());
        let mesh = u.mesh();
        mesh.check_closed().unwrap();
        assert!((enclosed_volume(mesh) - u.volume()).abs() < 1e-9 * expected);
        assert_eq!(u.pieces(), 1);
    }

    #[test]
    fn apart_spheres_stay_two_pieces_and_a_bridge_joins_them() {
        let (s1, s2) = (sphere_at(10.0, [0.0, 0.0, 0.0]), sphere_at(10.0, [0.0102, 0.0, 0.0]));
        let two = unite(&[&s1, &s2], &|k| format!("sphere {k}"), &[1e-9]).unwrap();
        assert_eq!(two.pieces(), 2);
        assert!((two.volume() - 2.0 * enclosed_volume(&s1)).abs() < 1e-12);
        let contact = crate::Contact {
            pellet: 0,
            partner: crate::Partner::Pellet(1),
            point: Point::new(0.005, 0.0, 0.0),
            partner_point: Point::new(0.0052, 0.0, 0.0),
            normal: pellet_geom::math::Vector::x(),
            gap: 0.0002,
        };
        let bridge = crate::treatment::bridge_mesh(&contact, 0.001, 16);
        let joined = unite(&[&s1, &s2, &bridge], &|k| format!("surface {k}"), &[1e-9]).unwrap();
        assert_eq!(joined.pieces(), 1);
        joined.mesh().check_closed().unwrap();
        assert!(joined.volume() > two.volume());
        assert!(joined.volume() < two.volume() + enclosed_volume(&bridge));
    }

    #[test]
    fn the_part_inside_the_tube_excludes_what_pokes_through_the_wall() {
        // A sphere centred on a 20 mm tube's wall: about half inside.
        let s = sphere_at(10.0, [0.01, 0.0, 0.02]);
        let u = unite(&[&s], &|_| "sphere".into(), &[1e-9]).unwrap();
        let inside = u.volume_in_tube(&tube_mesh(0.01, 0.0, 0.04, 256)).unwrap();
        let half = 0.5 * enclosed_volume(&s);
        assert!(inside < half && inside > 0.8 * half, "{inside} vs {half}");
    }

    #[test]
    fn an_open_mesh_is_refused_by_name() {
        let mut s = sphere_at(10.0, [0.0, 0.0, 0.0]);
        s.triangles.pop();
        let err = unite(&[&s], &|k| format!("pellet {k}"), &[1e-9]).err().unwrap().to_string();
        assert!(err.starts_with("pellet 0: the mesh is not a closed manifold"), "{err}");
    }
}
