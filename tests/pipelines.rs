//! End-to-end chains of the real binaries on tiny inputs.

use pellet_tests::Scenario;

#[test]
fn mkpellet_makes_the_three_paper_pellets_and_info_reads_them() {
    let s = Scenario::new();
    s.run("mkpellet", &["sphere", "--diameter", "10", "-o", "s.pellet"]).success();
    s.run("mkpellet", &["cylinder", "--diameter", "10", "--height", "10", "-o", "c.pellet", "--stl", "c.stl"])
        .success();
    s.run("mkpellet", &["ring", "--outer-diameter", "10", "--inner-diameter", "6", "--height", "10", "-o", "r.pellet"])
        .success();
    s.run("mkpellet", &["ring", "--outer-diameter", "10", "--wall", "2", "--height", "10", "-o", "r2.pellet"])
        .success();
    // --wall 2 is the same ring as --inner-diameter 6: same mesh and properties.
    let a = pellet_io::decode_pellet(&std::fs::read(s.file("r.pellet")).unwrap(), "r").unwrap();
    let b = pellet_io::decode_pellet(&std::fs::read(s.file("r2.pellet")).unwrap(), "r2").unwrap();
    assert_eq!(a.pellet, b.pellet);

    let info = s.run("mkpellet", &["info", "c.pellet", "--json"]);
    info.success();
    let v: serde_json::Value = serde_json::from_str(&info.stdout()).unwrap();
    let exact = std::f64::consts::PI * 25.0 * 10.0;
    assert!((v["volume_mm3"].as_f64().unwrap() / exact - 1.0).abs() < 0.005);
    assert_eq!(v["euler_characteristic"], 2);
    s.run("mkpellet", &["info", "r.pellet"]).success().stdout_has("Euler characteristic 0 (genus 1)");
}

#[test]
fn stl_export_reimports_with_the_same_volume() {
    let s = Scenario::new();
    s.run(
        "mkpellet",
        &["ring", "--outer-diameter", "10", "--wall", "2", "--height", "10", "-o", "r.pellet", "--stl", "r.stl"],
    )
    .success();
    s.run("mkpellet", &["import", "r.stl", "--unit", "mm", "-o", "imported.pellet"]).success();
    let orig = pellet_io::decode_pellet(&std::fs::read(s.file("r.pellet")).unwrap(), "r").unwrap().pellet;
    let back = pellet_io::decode_pellet(&std::fs::read(s.file("imported.pellet")).unwrap(), "i").unwrap().pellet;
    // STL stores f32 millimetres: the volume survives to ~1e-6.
    assert!((back.properties.volume / orig.properties.volume - 1.0).abs() < 1e-5);
    assert_eq!(back.mesh.face_count(), orig.mesh.face_count());
    assert_eq!(back.topology().unwrap().euler_characteristic, 0);
    // A nonconvex import is decomposed into several convex pieces.
    assert!(back.pieces.len() > 1);
}

#[test]
fn the_same_command_gives_the_same_bytes() {
    let s = Scenario::new();
    for name in ["a.pellet", "b.pellet"] {
        s.run("mkpellet", &["trilobe", "--lobe-diameter", "1.6", "--size", "2.9", "--height", "5", "-o", name])
            .success();
    }
    // The provenance records -o, so compare the payloads through a decode/encode.
    let a = std::fs::read(s.file("a.pellet")).unwrap();
    let b = std::fs::read(s.file("b.pellet")).unwrap();
    let (fa, fb) = (pellet_io::decode_pellet(&a, "a").unwrap(), pellet_io::decode_pellet(&b, "b").unwrap());
    assert_eq!(fa.pellet, fb.pellet);
    // And with identical arguments the files are byte-identical.
    s.run("mkpellet", &["sphere", "--diameter", "3", "-o", "x.pellet"]).success();
    let first = std::fs::read(s.file("x.pellet")).unwrap();
    s.run("mkpellet", &["sphere", "--diameter", "3", "-o", "x.pellet"]).success();
    assert_eq!(first, std::fs::read(s.file("x.pellet")).unwrap());
}

#[test]
fn pellet_file_streams_through_stdout_and_stdin() {
    let s = Scenario::new();
    let made = s.run("mkpellet", &["sphere", "--diameter", "4"]);
    made.success();
    assert!(made.output.stdout.starts_with(b"PBPELLET"));
    s.run_with_stdin("mkpellet", &["info", "-"], Some(&made.output.stdout)).success().stdout_has("sphere");
}
