//! Process-boundary tests of `bedexport`: every format read back by an
//! independent reader (stl_io, roxmltree + base64, the poses CSV reader,
//! the raw bytes and their JSON header) to the same pellets and volume;
//! voxel porosity against the exact one; stdin/stdout; exit codes.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use std::process::{Command, Output, Stdio};

use base64::Engine;
use pellet_analysis::synthetic::random_placement;
use pellet_analysis::{bulk_porosity, Geometry};
use pellet_geom::math::Point;
use pellet_geom::{Bed, Pellet, Resolution, ShapeSpec, TriMesh};
use pellet_io::{PackingFile, Provenance};

const MM: f64 = 1e-3;

fn bedexport(dir: &Path, args: &[&str], stdin: Option<&[u8]>) -> Output {
    use std::io::Write;
    let mut child = Command::new(env!("CARGO_BIN_EXE_bedexport"))
        .args(args)
        .current_dir(dir)
        .stdin(if stdin.is_some() { Stdio::piped() } else { Stdio::null() })
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run bedexport");
    if let Some(data) = stdin {
        child.stdin.take().unwrap().write_all(data).unwrap();
    }
    child.wait_with_output().unwrap()
}

#[track_caller]
fn assert_ok(out: &Output) {
    assert_eq!(out.status.code(), Some(0), "stderr: {}", String::from_utf8_lossy(&out.stderr));
}

#[track_caller]
fn assert_error(out: &Output, needle: &str) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "stderr: {err}");
    assert!(err.starts_with("bedexport: error: "), "{err}");
    assert!(err.contains(needle), "stderr lacks {needle:?}: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "not one line: {err}");
}

fn packing_bytes(bed: &Bed) -> Vec<u8> {
    let file = PackingFile {
        length_unit: "m".into(),
        provenance: Provenance { tool: "test".into(), version: "0".into(), args: vec![] },
        time_s: 0.0,
        verdict: None,
        bed: bed.clone(),
    };
    pellet_io::encode_packing(&file).unwrap()
}

/// 20 cylinders (10 × 10 mm) placed at random in a 40 mm tube, 50 mm high.
fn cylinder_bed() -> Bed {
    let cyl = Pellet::build(ShapeSpec::Cylinder { diameter_mm: 10.0, height_mm: 10.0 }, Resolution::default()).unwrap();
    random_placement(&cyl, 40.0 * MM, 50.0 * MM, 20, 3)
}

fn volume(mesh: &TriMesh) -> f64 {
    (0..mesh.face_count())
        .map(|t| {
            let [a, b, c] = mesh.corners(t);
            a.coords.dot(&b.coords.cross(&c.coords)) / 6.0
        })
        .sum()
}

fn read_stl(path: &Path) -> TriMesh {
    let stl = stl_io::read_stl(&mut std::fs::File::open(path).unwrap()).unwrap();
    TriMesh {
        vertices: stl.vertices.iter().map(|v| Point::new(v[0].into(), v[1].into(), v[2].into())).collect(),
        triangles: stl.faces.iter().map(|f| f.vertices.map(|i| i as u32)).collect(),
    }
}

/// Every DataArray of a VTK XML file by name, decoded (u64 byte count + data).
fn vtk_arrays(path: &Path) -> (String, BTreeMap<String, Vec<u8>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let doc = roxmltree::Document::parse(&text).unwrap();
    let root = doc.root_element();
    assert_eq!(root.attribute("byte_order"), Some("LittleEndian"));
    assert_eq!(root.attribute("header_type"), Some("UInt64"));
    let mut arrays = BTreeMap::new();
    for node in doc.descendants().filter(|n| n.has_tag_name("DataArray")) {
        assert_eq!(node.attribute("format"), Some("binary"));
        let blob = base64::engine::general_purpose::STANDARD.decode(node.text().unwrap_or("").trim()).unwrap();
        let len = u64::from_le_bytes(blob[..8].try_into().unwrap()) as usize;
        assert_eq!(blob.len(), 8 + len);
        arrays.insert(node.attribute("Name").unwrap().to_string(), blob[8..].to_vec());
    }
    (root.attribute("type").unwrap().to_string(), arrays)
}

fn f32s(b: &[u8]) -> Vec<f32> {
    b.chunks_exact(4).map(|c| f32::from_le_bytes(c.try_into().unwrap())).collect()
}
fn i32s(b: &[u8]) -> Vec<i32> {
    b.chunks_exact(4).map(|c| i32::from_le_bytes(c.try_into().unwrap())).collect()
}
fn i64s(b: &[u8]) -> Vec<i64> {
    b.chunks_exact(8).map(|c| i64::from_le_bytes(c.try_into().unwrap())).collect()
}

#[test]
fn every_format_reads_back_to_the_same_pellets_and_volume() {
    let dir = tempfile::tempdir().unwrap();
    let bed = cylinder_bed();
    let n = bed.pellets.len();
    assert!(n >= 10, "{n}");
    std::fs::write(dir.path().join("bed.packing"), packing_bytes(&bed)).unwrap();
    let out = bedexport(
        dir.path(),
        &[
            "bed.packing",
            "--stl",
            "bed.stl",
            "--tube-stl",
            "tube.stl",
            "--vtk",
            "bed.vtp",
            "--vtk-centres",
            "centres.vtp",
            "--csv",
            "poses.csv",
            "--voxels",
            "bed.raw",
            "--vti",
            "bed.vti",
        ],
        None,
    );
    assert_ok(&out);
    let summary = String::from_utf8_lossy(&out.stdout);
    assert!(summary.contains(&format!("pellets: {n} of {n}")), "{summary}");
    let pellet_volume_mm3 = bed.pellet_types[0].properties.volume * 1e9;
    // STL: one closed component per pellet, their total volume.
    let stl = read_stl(&dir.path().join("bed.stl"));
    assert_eq!(stl.check_closed().unwrap().components, n);
    assert!((volume(&stl) / (n as f64 * pellet_volume_mm3) - 1.0).abs() < 1e-5, "{}", volume(&stl));
    // The tube: a closed cylinder from the floor to the bed top, in mm.
    let tube = read_stl(&dir.path().join("tube.stl"));
    let top_mm = pellet_analysis::bed_top(&bed) / MM;
    let tube_volume = std::f64::consts::PI * 20.0 * 20.0 * top_mm;
    assert!(volume(&tube) > tube_volume && volume(&tube) < tube_volume * 1.0001, "{}", volume(&tube));
    // VTK PolyData: the pellet ids and each pellet's volume.
    let (kind, arrays) = vtk_arrays(&dir.path().join("bed.vtp"));
    assert_eq!(kind, "PolyData");
    let points = f32s(&arrays["Points"]);
    let connectivity = i64s(&arrays["connectivity"]);
    let ids = i32s(&arrays["pellet_id"]);
    assert_eq!(ids.iter().collect::<BTreeSet<_>>().len(), n);
    assert_eq!(i64s(&arrays["offsets"]).last(), Some(&(connectivity.len() as i64)));
    let point = |k: i64| {
        let k = 3 * k as usize;
        Point::new(points[k].into(), points[k + 1].into(), points[k + 2].into())
    };
    let mut per_pellet: BTreeMap<i32, f64> = BTreeMap::new();
    for (t, id) in connectivity.chunks_exact(3).zip(&ids) {
        let (a, b, c) = (point(t[0]), point(t[1]), point(t[2]));
        *per_pellet.entry(*id).or_default() += a.coords.dot(&b.coords.cross(&c.coords)) / 6.0;
    }
    for v in per_pellet.values() {
        assert!((v / pellet_volume_mm3 - 1.0).abs() < 1e-4, "{v}");
    }
    // Centres: positions, axes and radial positions.
    let (_, centres) = vtk_arrays(&dir.path().join("centres.vtp"));
    let (xyz, axis, rho) = (f32s(&centres["Points"]), f32s(&centres["axis"]), f32s(&centres["radial_position"]));
    assert_eq!(rho.len(), n);
    for (i, p) in bed.pellets.iter().enumerate() {
        assert!((xyz[3 * i + 2] as f64 - p.position[2] / MM).abs() < 1e-4);
        assert!((rho[i] as f64 - p.position[0].hypot(p.position[1]) / MM).abs() < 1e-4);
        assert!((axis[3 * i + 2] as f64 - p.axis().z).abs() < 1e-6);
    }
    // The poses CSV reads back with the reader voidprof --poses uses.
    let csv = std::fs::read(dir.path().join("poses.csv")).unwrap();
    let poses = pellet_io::decode_poses_csv(&csv, "poses.csv", true).unwrap();
    assert_eq!(poses.len(), n);
    for (a, b) in poses.iter().zip(&bed.pellets) {
        assert!((0..3).all(|k| (a.position[k] - b.position[k]).abs() < 1e-11), "{a:?} {b:?}");
        assert!((0..4).all(|k| (a.orientation[k] - b.orientation[k]).abs() < 1e-11));
    }
    // Voxels: the header describes the raw bytes; the VTI holds the same bytes.
    let header: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("bed.raw.json")).unwrap()).unwrap();
    let dims: Vec<usize> = header["dims"].as_array().unwrap().iter().map(|d| d.as_u64().unwrap() as usize).collect();
    let raw = std::fs::read(dir.path().join("bed.raw")).unwrap();
    assert_eq!(raw.len(), dims.iter().product::<usize>());
    assert_eq!(header["voxel_size"], 1.0);
    assert_eq!(header["unit"], "mm");
    let fluid = raw.iter().filter(|&&v| v == 0).count() as f64;
    let solid = raw.iter().filter(|&&v| v == 1).count() as f64;
    assert!((header["porosity"].as_f64().unwrap() - fluid / (fluid + solid)).abs() < 1e-12);
    let exact = header["exact_porosity"].as_f64().unwrap();
    assert!((fluid / (fluid + solid) - exact).abs() < 0.01, "{} vs {exact}", fluid / (fluid + solid));
    let (kind, image) = vtk_arrays(&dir.path().join("bed.vti"));
    assert_eq!(kind, "ImageData");
    assert_eq!(image["solid"], raw);
}

#[test]
fn a_window_cuts_and_caps_the_pellets_to_the_exact_slab_volume() {
    let dir = tempfile::tempdir().unwrap();
    let ring = Pellet::build(
        ShapeSpec::Ring { outer_diameter_mm: 10.0, inner_diameter_mm: 6.0, height_mm: 10.0 },
        Resolution::default(),
    )
    .unwrap();
    let bed = random_placement(&ring, 40.0 * MM, 50.0 * MM, 20, 4);
    std::fs::write(dir.path().join("bed.packing"), packing_bytes(&bed)).unwrap();
    let out = bedexport(
        dir.path(),
        &["bed.packing", "--stl", "cut.stl", "--tube-stl", "tube.stl", "--window", "10,30", "--vtk", "cut.vtp"],
        None,
    );
    assert_ok(&out);
    let summary = String::from_utf8_lossy(&out.stdout);
    assert!(summary.contains("cut at the planes and capped"), "{summary}");
    let stl = read_stl(&dir.path().join("cut.stl"));
    stl.check_closed().unwrap();
    assert!(stl.vertices.iter().all(|v| v.z >= 10.0 - 1e-4 && v.z <= 30.0 + 1e-4));
    // The surfaces enclose exactly the pellet volume between the planes: voidprof's bulk porosity on the mesh.
    let bulk = bulk_porosity(&bed, (0.010, 0.030), Geometry::Mesh).unwrap();
    let from_stl = 1.0 - volume(&stl) * 1e-9 / bulk.window_volume;
    assert!((from_stl - bulk.porosity).abs() < 1e-5, "{from_stl} vs {}", bulk.porosity);
    let tube = read_stl(&dir.path().join("tube.stl"));
    assert!(tube.vertices.iter().all(|v| v.z == 10.0 || v.z == 30.0 || v.x.hypot(v.y) < 1e-9));
    // Whole pellets by centroid instead: closed, uncut, one component each.
    let whole =
        bedexport(dir.path(), &["bed.packing", "--stl", "whole.stl", "--window", "10,30", "--whole-pellets"], None);
    assert_ok(&whole);
    let whole_stl = read_stl(&dir.path().join("whole.stl"));
    let inside = bed.pellets.iter().filter(|p| (0.010..0.030).contains(&p.position[2])).count();
    assert_eq!(whole_stl.check_closed().unwrap().components, inside);
}

#[test]
fn shapes_without_closed_forms_export_with_every_treatment() {
    // Trilobes have no closed form: gaps from mesh vertices, voxels and bridge volumes from mesh crossings.
    let dir = tempfile::tempdir().unwrap();
    let trilobe = Pellet::build(
        ShapeSpec::Lobed { lobes: 3, lobe_diameter_mm: 4.0, size_mm: 7.5, height_mm: 8.0 },
        Resolution::default(),
    )
    .unwrap();
    assert!(trilobe.closed_form.is_none());
    let bed = random_placement(&trilobe, 30.0 * MM, 40.0 * MM, 25, 2);
    std::fs::write(dir.path().join("bed.packing"), packing_bytes(&bed)).unwrap();
    // Random placement keeps bounding spheres apart: a gap of dp / 5 (1.5 mm, the largest
    // allowed) still finds neighbours.
    for treatment in [&["--bridge-gap", "1.5", "--shrink", "0.99"][..], &["--cap-gap", "1.5"][..]] {
        let args =
            [&["bed.packing", "--stl", "t.stl", "--voxels", "t.raw", "--window", "5,30"][..], treatment].concat();
        let out = bedexport(dir.path(), &args, None);
        assert_ok(&out);
        let text = String::from_utf8_lossy(&out.stdout);
        let treated: usize = text
            .lines()
            .filter(|l| l.starts_with("bridges:") || l.starts_with("caps:"))
            .map(|l| l.split_whitespace().nth(1).unwrap().trim_end_matches(',').parse::<usize>().unwrap())
            .sum();
        assert!(treated > 0, "{text}");
        read_stl(&dir.path().join("t.stl")).check_closed().unwrap();
        let header: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.path().join("t.raw.json")).unwrap()).unwrap();
        let (voxel, exact) = (header["porosity"].as_f64().unwrap(), header["exact_porosity"].as_f64().unwrap());
        assert!((voxel - exact).abs() < 0.01, "{voxel} vs {exact}");
    }
}

#[test]
fn voxel_porosity_converges_to_voidprofs_exact_porosity() {
    let dir = tempfile::tempdir().unwrap();
    let sphere = Pellet::build(ShapeSpec::Sphere { diameter_mm: 10.0 }, Resolution::default()).unwrap();
    let bed = pellet_analysis::synthetic::close_packed_spheres(&sphere, 40.0 * MM, 10.0 * MM, 40);
    std::fs::write(dir.path().join("bed.packing"), packing_bytes(&bed)).unwrap();
    let mut errors = Vec::new();
    for per_dp in ["4", "8", "16", "32"] {
        let out = bedexport(
            dir.path(),
            &["bed.packing", "--voxels", "v.raw", "--voxels-per-dp", per_dp, "--window", "0,30", "--quiet"],
            None,
        );
        assert_ok(&out);
        let header: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.path().join("v.raw.json")).unwrap()).unwrap();
        let z: Vec<f64> = header["z_range"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap() * MM).collect();
        // The exact porosity of the grid's range, as voidprof computes it.
        let exact = bulk_porosity(&bed, (z[0], z[1]), Geometry::Auto).unwrap().porosity;
        assert!((header["exact_porosity"].as_f64().unwrap() - exact).abs() < 1e-12);
        errors.push((header["porosity"].as_f64().unwrap() - exact).abs());
    }
    assert!(errors[3] < 0.003 && errors[3] < errors[0], "{errors:?}");
    assert!(errors[2] < 0.006, "{errors:?}");
}

#[test]
fn stdin_stdout_units_treatments_and_per_pellet_solids() {
    let dir = tempfile::tempdir().unwrap();
    let sphere = Pellet::build(ShapeSpec::Sphere { diameter_mm: 10.0 }, Resolution::default()).unwrap();
    let bed = pellet_analysis::synthetic::simple_cubic(&sphere, 40.0 * MM, 10.0 * MM, 2);
    let bytes = packing_bytes(&bed);
    std::fs::write(dir.path().join("bed.packing"), &bytes).unwrap();
    let piped = bedexport(dir.path(), &["-", "--stl", "-", "--units", "m"], Some(&bytes));
    assert_ok(&piped);
    let in_mm = bedexport(dir.path(), &["bed.packing", "--stl", "mm.stl"], None);
    assert_ok(&in_mm);
    std::fs::write(dir.path().join("m.stl"), &piped.stdout).unwrap();
    let (m, mm) = (read_stl(&dir.path().join("m.stl")), read_stl(&dir.path().join("mm.stl")));
    assert!((volume(&m) * 1e9 / volume(&mm) - 1.0).abs() < 1e-5);
    // ASCII, merged into one solid: stl_io reads it whole.
    assert_ok(&bedexport(dir.path(), &["bed.packing", "--stl", "merged.stl", "--ascii"], None));
    let merged = read_stl(&dir.path().join("merged.stl"));
    assert_eq!(merged.check_closed().unwrap().components, 18);
    assert!((volume(&merged) / volume(&mm) - 1.0).abs() < 1e-6);
    // The summary goes to stderr when the STL goes to stdout.
    assert!(String::from_utf8_lossy(&piped.stderr).contains("pellets: 18 of 18"));
    // Simple-cubic spheres touch their neighbours: bridges join every touching pair.
    let out = bedexport(
        dir.path(),
        &[
            "bed.packing",
            "--stl",
            "b.stl",
            "--ascii",
            "--solids",
            "per-pellet",
            "--bridge-gap",
            "0.01",
            "--shrink",
            "0.99",
        ],
        None,
    );
    assert_ok(&out);
    let text = String::from_utf8_lossy(&out.stdout);
    // 9 spheres per layer on a 3 × 3 square: 12 touching pairs in each of
    // the 2 layers, 9 between them; none within 0.1 mm of the wall; the
    // bottom 9 on the floor. Shrunk by 1 %, no gap is under 0.01 mm.
    assert!(text.contains("shrink: 33 pellet-pellet, 0 pellet-wall and 9 pellet-floor"), "{text}");
    assert!(text.contains("bridges: 0 pellet-pellet, 0 pellet-wall and 0 pellet-floor"), "{text}");
    let out = bedexport(
        dir.path(),
        &["bed.packing", "--stl", "b.stl", "--ascii", "--solids", "per-pellet", "--bridge-gap", "0.01"],
        None,
    );
    assert_ok(&out);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("bridges: 33 pellet-pellet, 0 pellet-wall and 9 pellet-floor"), "{text}");
    let stl = std::fs::read_to_string(dir.path().join("b.stl")).unwrap();
    assert_eq!(stl.matches("endsolid pellet_").count(), 18);
    assert_eq!(stl.matches("endsolid bridge_").count(), 42);
    // The pellet solids, parsed by hand (stl_io reads only an ASCII file's first solid), hold 18 pellets' volume.
    let (mut solid, mut corners, mut pellet_volume) = (String::new(), Vec::new(), 0.0);
    for line in stl.lines().map(str::trim) {
        if let Some(name) = line.strip_prefix("solid ") {
            solid = name.to_string();
        } else if let Some(v) = line.strip_prefix("vertex ") {
            let c: Vec<f64> = v.split_whitespace().map(|x| x.parse().unwrap()).collect();
            corners.push(Point::new(c[0], c[1], c[2]));
            if corners.len() == 3 {
                if solid.starts_with("pellet_") {
                    pellet_volume += corners[0].coords.dot(&corners[1].coords.cross(&corners[2].coords)) / 6.0;
                }
                corners.clear();
            }
        }
    }
    let expected = 18.0 * bed.pellet_types[0].properties.volume * 1e9;
    assert!((pellet_volume / expected - 1.0).abs() < 1e-6, "{pellet_volume} vs {expected}");
}

#[test]
fn bad_input_exits_2_with_one_line_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let bytes = packing_bytes(&cylinder_bed());
    std::fs::write(dir.path().join("bed.packing"), &bytes).unwrap();
    std::fs::write(dir.path().join("cut.packing"), &bytes[..bytes.len() / 2]).unwrap();
    std::fs::write(dir.path().join("text.packing"), b"not a packing").unwrap();
    let cases: &[(&[&str], &str)] = &[
        (&["missing.packing", "--stl", "o.stl"], "missing.packing"),
        (&["cut.packing", "--stl", "o.stl"], "is truncated (its data ends early)"),
        (&["text.packing", "--stl", "o.stl"], "not a packbed packing file"),
        (&["bed.packing"], "nothing to export"),
        (&["bed.packing", "--stl", "o.stl", "--solids", "per-pellet"], "needs --ascii"),
        (&["bed.packing", "--stl", "o.stl", "--shrink", "2"], "--shrink must be 0.5 to 1"),
        (&["bed.packing", "--stl", "o.stl", "--window", "abc"], "--window"),
        (&["bed.packing", "--stl", "o.stl", "--window", "200,300"], "no pellet lies in --window"),
        (&["bed.packing", "--voxels", "o.raw", "--voxel-size", "0"], "--voxel-size must be a finite number > 0"),
        (&["bed.packing", "--voxels", "o.raw", "--voxels-per-dp", "-3"], "--voxels-per-dp"),
        (&["bed.packing", "--voxels", "o.raw", "--voxel-size", "0.001"], "choose larger voxels"),
        (&["bed.packing", "--stl", "o.stl", "--bridge-gap", "-1"], "--bridge-gap must be in (0, "),
        (&["bed.packing", "--stl", "o.stl", "--bridge-gap", "1e300"], "(0 to dp / 5 for these pellets) (got 1e300)"),
        (&["bed.packing", "--stl", "o.stl", "--bridge-gap", "0.1", "--bridge-diameter", "1e3"], "0 to dp / 2"),
        (&["bed.packing", "--stl", "o.stl", "--contact-gap", "1e300"], "--contact-gap must be in (0, "),
        (&["bed.packing", "--openfoam", "c", "--cell-size", "1e-6"], "--cell-size must be in ["),
        (&["bed.packing", "--openfoam", "c", "--cell-size", "1e9"], "(got 1000000000)"),
        (&["bed.packing", "--openfoam", "c", "--inlet", "1e300"], "(0 to 100 dp for these pellets) (got 1e300)"),
        (&["bed.packing", "--openfoam", "c", "--outlet", "-1"], "--outlet must be in [0, "),
        (&["bed.packing", "--stl", "-", "--csv", "-"], "--stl and --csv both name - (stdout)"),
        (&["bed.packing", "--voxels", "-"], "--voxels needs a file name"),
        (
            &["bed.packing", "--tube-stl", "t.stl", "--tube-segments", "4294967295"],
            "--tube-segments must be in [8, 65536]",
        ),
    ];
    for (args, needle) in cases {
        let out = bedexport(dir.path(), args, None);
        assert_error(&out, needle);
    }
    assert!(!dir.path().join("o.stl").exists() && !dir.path().join("o.raw").exists());
    assert!(!dir.path().join("c").exists(), "a refused case left a directory");
    // Usage errors (clap's) are one line too, with the flag and where to read more.
    assert_error(
        &bedexport(dir.path(), &["--no-such-flag"], None),
        "unknown flag '--no-such-flag' (see bedexport --help)",
    );
    let whole = bedexport(dir.path(), &["bed.packing", "--stl", "o.stl", "--whole-pellets"], None);
    assert_error(&whole, "missing --window (see bedexport --help)");
    let help = bedexport(dir.path(), &["--help"], None);
    assert_ok(&help);
    assert!(String::from_utf8_lossy(&help.stdout).contains("x fastest"));
}

/// Runs bedexport with its stdout closed, as `bedexport … >&-` does; `Stdio::null()` would be
/// an open stdout.
fn bedexport_stdout_closed(dir: &Path, args: &[&str]) -> Output {
    Command::new("sh")
        .args(["-c", r#""$0" "$@" >&-"#, env!("CARGO_BIN_EXE_bedexport")])
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run bedexport through sh")
}

#[test]
fn two_outputs_naming_one_file_are_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("bed.packing"), packing_bytes(&cylinder_bed())).unwrap();
    std::fs::create_dir(dir.path().join("sub")).unwrap();
    std::fs::write(dir.path().join("old.stl"), b"old").unwrap();
    std::os::unix::fs::symlink("old.stl", dir.path().join("link.stl")).unwrap();
    let cases: &[(&[&str], &str)] = &[
        (&["--stl", "x", "--csv", "./x"], "--stl x and --csv ./x are the same file; give each output its own file"),
        (&["--vtk", "x", "--vti", "x"], "--vtk and --vti both name x"),
        (&["--tube-stl", "sub/../x", "--vtk-centres", "x"], "--tube-stl sub/../x and --vtk-centres x"),
        (&["--stl", "link.stl", "--tube-stl", "old.stl"], "--stl link.stl and --tube-stl old.stl"),
        (&["--voxels", "v.raw", "--csv", "v.raw.json"], "--csv and --voxels (its header) both name v.raw.json"),
        (&["--vtk", "-", "--csv", "-"], "--vtk and --csv both name - (stdout)"),
    ];
    for (flags, needle) in cases {
        let args: Vec<&str> = std::iter::once("bed.packing").chain(flags.iter().copied()).collect();
        let out = bedexport(dir.path(), &args, None);
        assert_error(&out, needle);
        assert!(out.stdout.is_empty(), "{flags:?}: something was written to stdout");
        for name in ["x", "v.raw", "v.raw.json"] {
            assert!(!dir.path().join(name).exists(), "{flags:?}: {name} was written");
        }
        assert_eq!(std::fs::read(dir.path().join("old.stl")).unwrap(), b"old");
    }
}

#[test]
fn a_closed_stdout_is_an_error_not_a_silent_success() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("bed.packing"), packing_bytes(&cylinder_bed())).unwrap();
    // An output on stdout, and the summary that goes there when no output does.
    for args in [&["bed.packing", "--csv", "-"][..], &["bed.packing", "--csv", "poses.csv"]] {
        let out = bedexport_stdout_closed(dir.path(), args);
        assert_error(&out, "cannot write to standard output: it is closed");
    }
    // --quiet prints no summary: nothing needs stdout.
    assert_ok(&bedexport_stdout_closed(dir.path(), &["bed.packing", "--csv", "poses.csv", "--quiet"]));
}
