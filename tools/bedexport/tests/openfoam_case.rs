//! `bedexport --openfoam`: the case directory without OpenFOAM (make
//! test-openfoam meshes it for real).

use std::path::Path;
use std::process::{Command, Output};

use pellet_analysis::synthetic::random_placement;
use pellet_geom::{Pellet, Resolution, ShapeSpec};
use pellet_io::{PackingFile, Provenance};

const MM: f64 = 1e-3;

fn bedexport(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_bedexport")).args(args).current_dir(dir).output().expect("run bedexport")
}

#[test]
fn the_case_holds_every_file_with_named_tube_regions_and_refuses_bad_flags() {
    let dir = tempfile::tempdir().unwrap();
    let sphere = Pellet::build(ShapeSpec::Sphere { diameter_mm: 10.0 }, Resolution::default()).unwrap();
    let bed = random_placement(&sphere, 30.0 * MM, 40.0 * MM, 10, 1);
    let file = PackingFile {
        length_unit: "m".into(),
        provenance: Provenance { tool: "test".into(), version: "0".into(), args: vec![] },
        time_s: 0.0,
        verdict: None,
        bed,
    };
    std::fs::write(dir.path().join("b.packing"), pellet_io::encode_packing(&file).unwrap()).unwrap();
    let out = bedexport(dir.path(), &["b.packing", "--openfoam", "case", "--inlet", "5", "--cap-gap", "0.1"]);
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    // A 0.1 mm gap changes the porosity far less than 0.01: no warning.
    assert!(!stderr.contains("warning"), "{stderr}");
    assert!(stdout.contains("inlet 5.000 mm, outlet 10.000 mm") && stdout.contains("fluid volume:"), "{stdout}");
    let case = dir.path().join("case");
    for f in [
        "README",
        "constant/triSurface/pellets.stl",
        "constant/triSurface/tube.stl",
        "system/controlDict",
        "system/blockMeshDict",
        "system/surfaceFeatureExtractDict",
        "system/snappyHexMeshDict",
        "system/meshQualityDict",
    ] {
        assert!(case.join(f).is_file(), "{f} missing");
    }
    let tube = std::fs::read_to_string(case.join("constant/triSurface/tube.stl")).unwrap();
    let solids: Vec<&str> = tube.lines().filter_map(|l| l.strip_prefix("solid ")).collect();
    assert_eq!(solids, ["wall", "inlet", "outlet"]);
    // Metres: the inlet starts 5 mm below the floor.
    assert!(tube.contains("-5.00000000e-3"), "no vertex at z = -0.005 m");
    let snappy = std::fs::read_to_string(case.join("system/snappyHexMeshDict")).unwrap();
    assert!(snappy.contains("locationInMesh (") && snappy.contains("wall   { name wall; }"));
    // No staging directory is left beside the case.
    let names: Vec<String> =
        std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into()).collect();
    assert!(names.iter().all(|n| !n.contains(".part")), "{names:?}");
    for (args, needle) in [
        (vec!["b.packing", "--openfoam", "case"], "already exists"),
        (vec!["b.packing", "--openfoam", "c2", "--stl", "x.stl"], "without the other outputs"),
        (vec!["b.packing", "--openfoam", "c2", "--shrink", "0.99"], "--treatment shrink"),
    ] {
        let out = bedexport(dir.path(), &args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(err.contains(needle) && err.trim_end().lines().count() == 1, "{err}");
    }
    assert!(!dir.path().join("c2").exists());
}

/// The flow files: u_s = Re_p ν / dp on the inlet (dp the volume-equivalent diameter), the
/// laminar Newtonian set-up, and --reynolds refused outside (0, 300] with one line.
#[test]
fn the_case_sets_up_the_laminar_flow_from_the_reynolds_number() {
    let dir = tempfile::tempdir().unwrap();
    let sphere = Pellet::build(ShapeSpec::Sphere { diameter_mm: 10.0 }, Resolution::default()).unwrap();
    let dpv = sphere.properties.equivalent_diameter;
    let bed = random_placement(&sphere, 30.0 * MM, 40.0 * MM, 6, 2);
    let file = PackingFile {
        length_unit: "m".into(),
        provenance: Provenance { tool: "test".into(), version: "0".into(), args: vec![] },
        time_s: 0.0,
        verdict: None,
        bed,
    };
    std::fs::write(dir.path().join("b.packing"), pellet_io::encode_packing(&file).unwrap()).unwrap();
    let nu = pellet_export::openfoam::WATER_20C.nu;
    for (extra, re) in [(None, 10.0), (Some("50"), 50.0), (Some("0.5"), 0.5)] {
        let case = format!("case{re}");
        let mut args = vec!["b.packing", "--openfoam", &case, "--cell-size", "2"];
        if let Some(v) = extra {
            args.extend(["--reynolds", v]);
        }
        let out = bedexport(dir.path(), &args);
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
        let u = re * nu / dpv;
        let read = |f: &str| std::fs::read_to_string(dir.path().join(&case).join(f)).unwrap();
        let field = read("0/U");
        let line = field.lines().find(|l| l.contains("value           uniform (0 0 ")).expect("an inlet velocity");
        let written: f64 = line.split("(0 0 ").nth(1).unwrap().trim_end_matches(");").parse().unwrap();
        assert!((written / u - 1.0).abs() < 1e-8, "{line}: expected {u}");
        assert!(stdout.contains(&format!("u_s {u:.6e} m/s along +z")), "{stdout}");
        for patch in ["inlet", "outlet", "wall", "pellets"] {
            assert!(field.contains(&format!("    {patch}\n")) && read("0/p").contains(&format!("    {patch}\n")));
        }
        assert!(field.contains("type            noSlip;") && read("0/p").contains("uniform 0;"));
        assert!(read("constant/transportProperties").contains("transportModel  Newtonian;"));
        assert!(read("constant/turbulenceProperties").contains("simulationType  laminar;"));
        assert!(read("system/fvSolution").contains("consistent      yes;"));
        assert!(read("system/fvSchemes").contains("div(phi,U)"));
        assert!(read("system/controlDict").contains("application     simpleFoam;"));
        assert!(read("README").contains("simpleFoam > log.simpleFoam"));
    }
    for bad in ["0", "-1", "nan", "inf", "300.5", "1e9"] {
        let out = bedexport(dir.path(), &["b.packing", "--openfoam", "bad", "--reynolds", bad]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{bad}: {err}");
        assert!(err.starts_with("bedexport: error: --reynolds must be above 0 and at most 300"), "{bad}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{bad}: {err}");
    }
    assert!(!dir.path().join("bad").exists());
    // --reynolds belongs to --openfoam.
    let out = bedexport(dir.path(), &["b.packing", "--stl", "b.stl", "--reynolds", "10"]);
    assert_eq!(out.status.code(), Some(2));
}

/// Nine touching and overlapping spheres: the default caps (a gap of dp/100) change the porosity
/// by under 0.01, the snappyHexMeshDict refines a sphere around each treated contact at the level
/// whose cells fit the gap, and an oversized --cap-gap warns with the figure (exit code 0).
#[test]
fn the_default_treatment_keeps_the_porosity_and_refines_the_contacts() {
    let dir = tempfile::tempdir().unwrap();
    let sphere = Pellet::build(ShapeSpec::Sphere { diameter_mm: 10.0 }, Resolution::default()).unwrap();
    let at = |p: [f64; 3]| pellet_geom::PlacedPellet {
        type_index: 0,
        position: p.map(|c| c * MM),
        orientation: [1.0, 0.0, 0.0, 0.0],
    };
    // A touching triangle on the floor, one on top of it, one more beside the first.
    let pellets = vec![
        at([0.0, 0.0, 5.0]),
        at([10.0, 0.0, 5.0]),
        at([5.0, 8.660254037844386, 5.0]),
        at([5.0, 2.886751345948129, 13.16496580927726]),
        at([-5.0, -8.660254037844386, 5.0]),
    ];
    let bed = pellet_geom::Bed {
        tube: pellet_geom::Tube { diameter: 30.0 * MM, lid_height: None },
        pellet_types: vec![sphere],
        pellets,
    };
    let file = PackingFile {
        length_unit: "m".into(),
        provenance: Provenance { tool: "test".into(), version: "0".into(), args: vec![] },
        time_s: 0.0,
        verdict: None,
        bed,
    };
    std::fs::write(dir.path().join("b.packing"), pellet_io::encode_packing(&file).unwrap()).unwrap();
    let change = |stdout: &str, name: &str| -> f64 {
        let line = stdout.lines().find(|l| l.starts_with(&format!("{name}:"))).expect("a treatment line");
        line.split("porosity change ").nth(1).unwrap().split(' ').next().unwrap().parse().unwrap()
    };
    // 2 mm cells: background 4 mm; a 0.1 mm gap would need level 6, capped at 3 (0.5 mm).
    for (treatment, case) in [("caps", "caps"), ("bridges", "bridges")] {
        let out =
            bedexport(dir.path(), &["b.packing", "--openfoam", case, "--treatment", treatment, "--cell-size", "2"]);
        let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
        assert_eq!(out.status.code(), Some(0), "{stderr}");
        let dphi = change(&stdout, treatment);
        assert!(dphi.abs() < 0.01 && dphi != 0.0, "{treatment}: porosity change {dphi}: {stdout}");
        assert!(!stderr.contains("warning"), "{treatment}: {stderr}");
        let contacts = stdout.lines().find(|l| l.starts_with(&format!("{treatment}:"))).unwrap();
        assert!(contacts.contains("7 pellet-pellet, 3 pellet-wall and 4 pellet-floor"), "{contacts}");
        let dict = std::fs::read_to_string(dir.path().join(case).join("system/snappyHexMeshDict")).unwrap();
        assert_eq!(dict.matches("type searchableSphere;").count(), 14, "{dict}");
        assert!(dict.contains("contact_00000 { mode inside; levels ((1e15 3)); }"), "{dict}");
        assert!(stdout.contains("at level 3 (cells 0.5000 mm; the treatment's gap 0.1000 mm)"), "{stdout}");
        let r = if treatment == "caps" { 1.0 } else { (1.0f64 + 0.75 * 0.75).sqrt() };
        assert!(dict.contains(&format!("radius {:.9e};", r * MM)), "{treatment}: radius {r} mm: {dict}");
    }
    // 0.5 mm cells and a 0.25 mm gap: background 1 mm, level 2 fits it exactly, no note.
    let out = bedexport(dir.path(), &["b.packing", "--openfoam", "fits", "--cap-gap", "0.25", "--cell-size", "0.5"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    assert!(stderr.is_empty(), "{stderr}");
    let dict = std::fs::read_to_string(dir.path().join("fits/system/snappyHexMeshDict")).unwrap();
    assert!(dict.contains("levels ((1e15 2))"), "{dict}");
    // An oversized gap (dp/5) flattens the spheres: a warning with the figure, exit code 0.
    let out = bedexport(dir.path(), &["b.packing", "--openfoam", "wide", "--cap-gap", "2", "--cell-size", "2"]);
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    let dphi = change(&stdout, "caps");
    assert!(dphi > 0.01, "{dphi}");
    let warning =
        stderr.lines().find(|l| l.starts_with("bedexport: warning: caps change the porosity")).expect(&stderr);
    assert!(warning.contains(&format!("{dphi:+.5}")) && warning.contains("a smaller --cap-gap"), "{warning}");
    // --stl exports warn the same way.
    let out = bedexport(dir.path(), &["b.packing", "--stl", "w.stl", "--cap-gap", "2"]);
    assert_eq!(out.status.code(), Some(0));
    assert!(String::from_utf8_lossy(&out.stderr).contains("bedexport: warning: caps change the porosity by +"));
}
