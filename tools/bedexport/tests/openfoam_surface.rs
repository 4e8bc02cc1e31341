//! `bedexport --openfoam`: constant/triSurface/pellets.stl is one closed,
//! outward, non-self-intersecting surface enclosing the union of the
//! pellets (and bridges), for each contact treatment, on a small bed of
//! spheres and cylinders that touch and overlap.

use std::collections::HashMap;
use std::path::Path;
use std::process::{Command, Output};

use pellet_geom::math::{Point, Vector};
use pellet_geom::{Bed, Pellet, PlacedPellet, Resolution, ShapeSpec, TriMesh, Tube};
use pellet_io::{PackingFile, Provenance};

const MM: f64 = 1e-3;

fn bedexport(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_bedexport")).args(args).current_dir(dir).output().expect("run bedexport")
}

/// A unit quaternion (w, x, y, z) turning by `degrees` about `axis`.
fn turn(axis: [f64; 3], degrees: f64) -> [f64; 4] {
    let n = Vector::from(axis).normalize();
    let h = 0.5 * degrees.to_radians();
    [h.cos(), n.x * h.sin(), n.y * h.sin(), n.z * h.sin()]
}

/// Nine 10 mm spheres and cylinders (10 mm high) in a 30 mm tube: on the
/// floor, against the wall, touching (gap 0), overlapping by up to 0.4 mm,
/// and one apart from the rest.
fn small_bed() -> Bed {
    let sphere = Pellet::build(ShapeSpec::Sphere { diameter_mm: 10.0 }, Resolution::default()).unwrap();
    let cylinder =
        Pellet::build(ShapeSpec::Cylinder { diameter_mm: 10.0, height_mm: 10.0 }, Resolution::default()).unwrap();
    let at = |type_index: u32, p: [f64; 3], orientation: [f64; 4]| PlacedPellet {
        type_index,
        position: p.map(|c| c * MM),
        orientation,
    };
    let still = [1.0, 0.0, 0.0, 0.0];
    let pellets = vec![
        at(0, [0.0, 0.0, 5.0], still),                         // on the floor
        at(0, [9.8, 0.0, 5.0], still),                         // overlaps the first by 0.2 mm, 0.2 mm from the wall
        at(0, [-5.0, 8.660254037844386, 5.0], still),          // touches the first
        at(0, [0.0, 0.0, 14.6], still),                        // overlaps the first by 0.4 mm
        at(1, [-5.0, -8.0, 7.0], turn([1.0, 0.3, 0.0], 35.0)), // tilted, into the first sphere
        at(1, [6.0, -6.5, 15.0], turn([0.0, 1.0, 0.2], 80.0)), // lying, on the tilted one
        at(1, [-7.0, 4.0, 16.0], still),                       // upright, on the touching sphere
        at(0, [5.0, 6.0, 22.0], still),                        // on the stack
        at(0, [0.0, -8.0, 30.0], still),                       // apart
    ];
    Bed { tube: Tube { diameter: 30.0 * MM, lid_height: None }, pellet_types: vec![sphere, cylinder], pellets }
}

/// The vertices of an ASCII STL, welded by their printed text (the
/// writer prints one vertex the same way each time), and its triangles.
fn read_ascii_stl(text: &str) -> TriMesh {
    let mut index: HashMap<&str, u32> = HashMap::new();
    let mut mesh = TriMesh::default();
    let mut corners = Vec::new();
    for line in text.lines() {
        let Some(xyz) = line.trim().strip_prefix("vertex ") else { continue };
        let next = index.len() as u32;
        let k = *index.entry(xyz).or_insert_with(|| {
            let c: Vec<f64> = xyz.split_whitespace().map(|w| w.parse().unwrap()).collect();
            mesh.vertices.push(Point::new(c[0], c[1], c[2]));
            next
        });
        corners.push(k);
        if corners.len() == 3 {
            mesh.triangles.push([corners[0], corners[1], corners[2]]);
            corners.clear();
        }
    }
    mesh
}

/// Every edge is used once in each direction: closed, and the triangles
/// of each piece are consistently oriented.
fn assert_closed_and_oriented(mesh: &TriMesh, what: &str) {
    let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
    for t in &mesh.triangles {
        assert!(t[0] != t[1] && t[1] != t[2] && t[2] != t[0], "{what}: a triangle repeats a vertex: {t:?}");
        for k in 0..3 {
            *directed.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
        }
    }
    for (&(a, b), &n) in &directed {
        assert_eq!(n, 1, "{what}: the edge {a}-{b} is used {n} times in one direction");
        assert_eq!(directed.get(&(b, a)), Some(&1), "{what}: the edge {a}-{b} has no opposite (an open surface)");
    }
}

fn volume(mesh: &TriMesh) -> f64 {
    pellet_export::scene::enclosed_volume(mesh)
}

fn orient(a: &Point, b: &Point, c: &Point, d: &Point) -> f64 {
    (b - a).cross(&(c - a)).dot(&(d - a))
}

/// Whether the segment pq passes through the inside of triangle abc
/// (strictly: touching counts as not crossing).
fn segment_crosses(p: &Point, q: &Point, [a, b, c]: &[Point; 3]) -> bool {
    let (sp, sq) = (orient(a, b, c, p), orient(a, b, c, q));
    if sp * sq >= 0.0 {
        return false;
    }
    let (u, v, w) = (orient(p, q, a, b), orient(p, q, b, c), orient(p, q, c, a));
    (u > 0.0 && v > 0.0 && w > 0.0) || (u < 0.0 && v < 0.0 && w < 0.0)
}

/// Pairs of triangles sharing no vertex whose interiors cross (an edge of
/// one passes through the other), over a grid of their bounding boxes.
fn crossing_pairs(mesh: &TriMesh) -> Vec<(usize, usize)> {
    let n = mesh.face_count();
    let boxes: Vec<(Point, Point)> = (0..n)
        .map(|t| {
            let c = mesh.corners(t);
            (c[0].inf(&c[1]).inf(&c[2]), c[0].sup(&c[1]).sup(&c[2]))
        })
        .collect();
    let mean = boxes.iter().map(|(lo, hi)| (hi - lo).norm()).sum::<f64>() / n as f64;
    let cell = 2.0 * mean;
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
    let mut found = Vec::new();
    let mut seen = std::collections::HashSet::new();
    for list in grid.values() {
        for (x, &s) in list.iter().enumerate() {
            for &t in &list[x + 1..] {
                let (s, t) = (s.min(t), s.max(t));
                let (bs, bt) = (&boxes[s], &boxes[t]);
                let apart = (0..3).any(|d| bs.1[d] < bt.0[d] || bt.1[d] < bs.0[d]);
                let (ts, tt) = (mesh.triangles[s], mesh.triangles[t]);
                if apart || ts.iter().any(|v| tt.contains(v)) || !seen.insert((s, t)) {
                    continue;
                }
                let (cs, ct) = (mesh.corners(s), mesh.corners(t));
                let crosses = (0..3).any(|k| segment_crosses(&cs[k], &cs[(k + 1) % 3], &ct))
                    || (0..3).any(|k| segment_crosses(&ct[k], &ct[(k + 1) % 3], &cs));
                if crosses {
                    found.push((s, t));
                }
            }
        }
    }
    found
}

/// The volume of the union of the pellets' (convex) meshes, by a jittered
/// grid of `n`³ points over the bed's box: a point is in a pellet when it
/// is behind every one of its triangles' planes.
fn union_volume_sampled(bed: &Bed, n: usize) -> f64 {
    struct Convex {
        centre: Point,
        reach: f64,
        planes: Vec<(Vector, f64)>,
    }
    let solids: Vec<Convex> = bed
        .pellets
        .iter()
        .map(|pose| {
            let m = pellet_export::scene::world_mesh(&bed.pellet_types[pose.type_index as usize], pose, 1.0);
            let centre = pose.centre();
            let reach = m.vertices.iter().map(|v| (v - centre).norm()).fold(0.0, f64::max);
            let planes = (0..m.face_count())
                .map(|t| {
                    let n = m.area_normal(t).normalize();
                    (n, n.dot(&m.corners(t)[0].coords))
                })
                .collect();
            Convex { centre, reach, planes }
        })
        .collect();
    let first = solids[0].centre;
    let lo = solids.iter().map(|s| s.centre - Vector::repeat(s.reach)).fold(first, |a, b| a.inf(&b));
    let hi = solids.iter().map(|s| s.centre + Vector::repeat(s.reach)).fold(first, |a, b| a.sup(&b));
    let step = (hi - lo) / n as f64;
    // A fixed linear congruential sequence: the same points every run.
    let mut state: u64 = 0x9e37_79b9_7f4a_7c15;
    let mut jitter = || {
        state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut inside = 0usize;
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                let p = Point::new(
                    lo.x + (i as f64 + jitter()) * step.x,
                    lo.y + (j as f64 + jitter()) * step.y,
                    lo.z + (k as f64 + jitter()) * step.z,
                );
                let hit = solids
                    .iter()
                    .any(|s| (p - s.centre).norm() <= s.reach && s.planes.iter().all(|(n, d)| n.dot(&p.coords) <= *d));
                inside += usize::from(hit);
            }
        }
    }
    inside as f64 * step.x * step.y * step.z
}

/// Exports the bed with `treatment` and returns (pellets.stl, stdout).
fn export(dir: &Path, treatment: &str) -> (TriMesh, String, Vec<u8>) {
    let case = format!("case-{treatment}");
    let out = bedexport(dir, &["b.packing", "--openfoam", &case, "--treatment", treatment, "--cell-size", "0.5"]);
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert_eq!(out.status.code(), Some(0), "{treatment}: {stderr}");
    let bytes = std::fs::read(dir.join(&case).join("constant/triSurface/pellets.stl")).unwrap();
    let mesh = read_ascii_stl(std::str::from_utf8(&bytes).unwrap());
    (mesh, stdout.into_owned(), bytes)
}

fn check_surface(mesh: &TriMesh, treatment: &str) {
    assert!(mesh.face_count() > 1000, "{treatment}: {} triangles", mesh.face_count());
    assert_closed_and_oriented(mesh, treatment);
    assert!(volume(mesh) > 0.0, "{treatment}: the surface encloses a negative volume (inside out)");
    let crossing = crossing_pairs(mesh);
    assert!(crossing.is_empty(), "{treatment}: {} pairs of triangles cross, e.g. {:?}", crossing.len(), crossing[0]);
}

#[test]
fn pellets_stl_is_one_closed_surface_around_the_union_for_every_treatment() {
    let dir = tempfile::tempdir().unwrap();
    let bed = small_bed();
    let file = PackingFile {
        length_unit: "m".into(),
        provenance: Provenance { tool: "test".into(), version: "0".into(), args: vec![] },
        time_s: 0.0,
        verdict: None,
        bed: bed.clone(),
    };
    std::fs::write(dir.path().join("b.packing"), pellet_io::encode_packing(&file).unwrap()).unwrap();
    let sampled = union_volume_sampled(&bed, 100);
    let separate: f64 =
        pellet_export::scene::world_meshes(&bed, &(0..bed.pellets.len()).collect::<Vec<_>>()).iter().map(volume).sum();
    // The overlaps are a real part of the bed's volume: the check below tells a union from a sum.
    assert!(separate - sampled > 0.002 * sampled, "{separate} vs {sampled}");

    let (none, stdout, bytes) = export(dir.path(), "none");
    check_surface(&none, "none");
    let united = volume(&none);
    assert!((united - sampled).abs() < 0.01 * sampled, "union {united} m3 vs sampled {sampled} m3");
    assert!(united < separate, "{united} vs {separate}");
    assert!(stdout.contains("pellets.stl: 9 pellets united into one closed surface"), "{stdout}");
    // The same input writes the same bytes.
    let out =
        bedexport(dir.path(), &["b.packing", "--openfoam", "case-repeat", "--treatment", "none", "--cell-size", "0.5"]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(std::fs::read(dir.path().join("case-repeat/constant/triSurface/pellets.stl")).unwrap() == bytes);

    let (bridged, stdout, _) = export(dir.path(), "bridges");
    check_surface(&bridged, "bridges");
    assert!(stdout.contains("bridges united into one closed surface"), "{stdout}");
    assert!(volume(&bridged) > united, "bridges add solid: {} vs {united}", volume(&bridged));

    let (capped, _, _) = export(dir.path(), "caps");
    check_surface(&capped, "caps");
    assert!(volume(&capped) < united, "caps take solid away: {} vs {united}", volume(&capped));
}
