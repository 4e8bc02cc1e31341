//! Bad input and faults: a full stdout, outputs that are inputs, a killed run's
//! file, an unsettled bed in the default pipeline, impossible inputs.

use std::path::Path;
use std::process::{Command, Stdio};

use pellet_tests::{bin, Scenario};

/// A few spheres packed for 0.3 s (not settled): the trajectory, its last frame
/// as a packing, and that bed's profile and summary.
fn small_bed() -> Scenario {
    let s = Scenario::new();
    s.run("mkpellet", &["sphere", "--diameter", "10", "--faces", "500", "-o", "s.pellet"]).success();
    let pack = ["--pellet", "s.pellet", "--tube-diameter", "30", "--count", "3", "--max-time", "0.3", "--quiet"];
    s.run("pack", &[&pack[..], &["-o", "b.mcap"]].concat()).code(1);
    s.run("settle-check", &["b.mcap", "-o", "b.packing"]).code(1);
    s.run("voidprof", &["b.packing", "--window", "0,10", "-o", "p.csv", "--summary", "v.json"]).success();
    s
}

fn full() -> Stdio {
    Stdio::from(std::fs::OpenOptions::new().write(true).open("/dev/full").expect("/dev/full"))
}

#[test]
fn a_full_stdout_is_a_one_line_error_and_a_closed_one_is_quiet() {
    let s = small_bed();
    let cases: &[(&str, &[&str])] = &[
        ("settle-check", &["b.mcap"]),
        ("settle-check", &["b.mcap", "--json"]),
        ("compare", &["--list-refs"]),
        ("compare", &["--profile", "p.csv", "--summary", "v.json", "--ref", "mueller-1992", "-o", "r", "--no-plots"]),
        ("bedexport", &["b.packing", "--csv", "e.csv"]),
        ("mkpellet", &["info", "s.pellet"]),
        ("pack", &["--help"]),
        ("voidprof", &["--version"]),
    ];
    for (tool, args) in cases {
        s.run_with_stdout(tool, args, full()).fails_with("No space left on device");
    }
    // A reader that went away (`| head`) ends the tool quietly with exit 0.
    for (tool, args) in [("compare", "--list-refs"), ("settle-check", "b.mcap --json"), ("pack", "--help")] {
        let script = format!("{{ {} {args}; echo $? > status; }} | true", bin(tool).display());
        let out = Command::new("sh").args(["-c", &script]).current_dir(s.path()).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        let status = std::fs::read_to_string(s.file("status")).unwrap();
        // settle-check's verdict (1: not settled) when its report fit in the pipe first.
        assert!(["0", "1"].contains(&status.trim()), "{tool} {args} exited {status}: {err}");
        assert!(tool == "settle-check" || status.trim() == "0", "{tool} {args} exited {status}: {err}");
        assert!(!err.contains("panicked") && !err.contains("error"), "{tool} {args}: {err}");
    }
}

/// Every tool refuses an output that is one of its inputs (by the same path, another path or a
/// link) before writing anything, and the input is left as it was.
#[test]
fn an_output_that_is_an_input_is_refused_and_the_input_kept() {
    let s = small_bed();
    std::os::unix::fs::symlink("b.packing", s.file("link.packing")).unwrap();
    s.run("mkpellet", &["sphere", "--diameter", "10", "--stl", "s.stl", "-o", "t.pellet"]).success();
    let cases: &[(&str, &[&str], &str)] = &[
        ("settle-check", &["b.mcap", "-o", "b.mcap"], "b.mcap"),
        ("settle-check", &["b.mcap", "--csv", "./b.mcap"], "b.mcap"),
        ("voidprof", &["b.packing", "-o", "b.packing"], "b.packing"),
        ("voidprof", &["b.packing", "-o", "x.csv", "--summary", "link.packing"], "b.packing"),
        (
            "voidprof",
            &["--poses", "p.csv", "--pellet", "s.pellet", "--tube-diameter", "30", "--plot", "s.pellet"],
            "s.pellet",
        ),
        ("bedexport", &["b.packing", "--csv", "b.packing"], "b.packing"),
        ("bedexport", &["link.packing", "--stl", "b.packing"], "b.packing"),
        ("pack", &["--pellet", "s.pellet", "--tube-diameter", "30", "--count", "3", "-o", "s.pellet"], "s.pellet"),
        (
            "pack",
            &["--pellet", "s.pellet", "--tube-diameter", "30", "--count", "3", "-o", "s", "--park", "s.pellet"],
            "s.pellet",
        ),
        (
            "pack",
            &["--pellet", "s.pellet", "--tube-diameter", "30", "--count", "3", "-o", "b.mcap", "--park", "b.mcap"],
            "b.mcap",
        ),
        ("mkpellet", &["import", "s.stl", "-o", "s.stl"], "s.stl"),
        ("mkpellet", &["info", "s.pellet", "--stl", "s.pellet"], "s.pellet"),
        ("compare", &["--profile", "r/scores.csv", "--ref", "mueller-1992", "-o", "r"], "r/scores.csv"),
    ];
    std::fs::create_dir(s.file("r")).unwrap();
    std::fs::copy(s.file("p.csv"), s.file("r/scores.csv")).unwrap();
    for (tool, args, input) in cases {
        let before = std::fs::read(s.file(input)).unwrap();
        s.run(tool, args).fails_with("would destroy the input");
        assert_eq!(std::fs::read(s.file(input)).unwrap(), before, "{tool} {args:?} changed {input}");
    }
}

/// A killed run's `.part` is the only copy of what it simulated: the same pack without
/// --resume refuses and keeps it; --force starts over.
#[test]
fn a_killed_runs_part_file_is_kept_unless_forced() {
    let s = Scenario::new();
    s.run("mkpellet", &["sphere", "--diameter", "10", "--faces", "500", "-o", "s.pellet"]).success();
    std::fs::write(s.file("k.mcap.part"), b"a killed run").unwrap();
    let args = ["--pellet", "s.pellet", "--tube-diameter", "30", "--count", "2", "--max-time", "0.1", "--quiet"];
    s.run("pack", &[&args[..], &["-o", "k.mcap"]].concat()).fails_with("add --resume");
    assert_eq!(std::fs::read(s.file("k.mcap.part")).unwrap(), b"a killed run");
    let forced = s.run("pack", &[&args[..], &["-o", "k.mcap", "--force"]].concat());
    assert!(forced.stderr().contains("did not settle within --max-time"), "{}", forced.stderr());
    assert!(!s.file("k.mcap.part").exists() && s.file("k.mcap").exists());
}

fn default_make(s: &Scenario, bed_args: &str, target: &str) -> std::process::Output {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("workspace root").to_path_buf();
    let bin_dir = bin("pack").parent().expect("binary directory").to_path_buf();
    Command::new("make")
        .arg("--no-print-directory")
        .arg("-f")
        .arg(root.join("pipelines/default.mk"))
        .arg(format!("BIN={}", bin_dir.display()))
        .arg("OUT=out")
        .arg(format!("BED_ARGS={bed_args}"))
        .arg(target)
        .current_dir(s.path())
        .output()
        .expect("run make (is GNU make installed?)")
}

/// A bed that did not settle never becomes a target of the default pipeline, however often
/// make runs, and the next make resumes the run.
#[test]
fn the_default_pipeline_never_scores_an_unsettled_bed_and_resumes_its_pack() {
    let s = Scenario::new();
    let short = "--tube-diameter 40 --count 20 --seed 1 --max-time 0.3";
    for _ in 0..2 {
        let out = default_make(&s, short, "out/report/scores.json");
        assert!(!out.status.success(), "make scored an unsettled bed");
        // The failing step's message reaches the terminal, with its log's path.
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("--max-time") && err.contains("out/log/bed.mcap.log"), "{err}");
        for name in ["out/bed.mcap", "out/bed.packing", "out/profile.csv", "out/report/scores.json"] {
            assert!(!s.file(name).exists(), "{name} made from an unsettled bed");
        }
    }
    assert!(s.file("out/bed.run.mcap").exists(), "the unsettled run is kept for --resume");
    let out = default_make(&s, "--tube-diameter 40 --count 20 --seed 1", "out/bed.packing");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    // pack's own output is in its log, not on the terminal.
    let log = std::fs::read_to_string(s.file("out/log/bed.mcap.log")).unwrap();
    assert!(log.contains("resuming at t = 0.3"), "{log}");
    assert!(!s.file("out/bed.run.mcap").exists());
}

/// `voidprof --poses` refuses beds no tube could hold and says how many pellets overlap.
#[test]
fn voidprof_refuses_impossible_poses_and_warns_of_overlaps() {
    let s = Scenario::new();
    s.run("mkpellet", &["sphere", "--diameter", "10", "--faces", "500", "-o", "s.pellet"]).success();
    s.run("mkpellet", &["cylinder", "--diameter", "10", "--height", "10", "--faces", "500", "-o", "c.pellet"])
        .success();
    let voidprof = |pellet: &str, rows: &str, d: &str| {
        std::fs::write(s.file("p.csv"), rows).unwrap();
        s.run(
            "voidprof",
            &["--poses", "p.csv", "--pellet", pellet, "--tube-diameter", d, "--window", "0,10", "-o", "x.csv"],
        )
    };
    voidprof("s.pellet", "1,100,0,5\n", "40").fails_with("pellet 1 at (100, 0, 5) mm reaches 105.000 mm from the axis");
    voidprof("s.pellet", "1,0,0,5\n2,15.2,0,5\n", "40").fails_with("pellet 2 at (15.2, 0, 5) mm");
    voidprof("s.pellet", "1,0,0,2\n", "40").fails_with("3.000 mm below the floor");
    voidprof("s.pellet", "1,0,0,5\n", "5").fails_with("narrower than the pellet (10.0000 mm");
    voidprof("c.pellet", "1,0,0,5,0.7071068,0.7071068,0,0\n", "40").success();
    voidprof("c.pellet", "1,0,0,5,0.7071068,0.7071068,0,0\n", "9").fails_with("narrower than the pellet");
    voidprof("s.pellet", "1,0,0,5\n2,10,0,5\n1,-10,0,5\n", "40").fails_with("line 3: id 1 is also on line 1");
    // Within the 1 % tolerance: accepted without a word.
    let ok = voidprof("s.pellet", "1,0,0,4.95\n2,15.05,0,5\n3,0,0,14.95\n", "40");
    ok.success();
    assert!(ok.stderr().is_empty(), "{}", ok.stderr());
    let twice = voidprof("s.pellet", "1,0,0,5\n2,0,0,5\n3,10,0,5\n4,10,0,7\n", "40");
    twice.success();
    assert!(
        twice.stderr().contains("2 pairs of pellets (4 pellets) overlap by more than 0.100 mm"),
        "{}",
        twice.stderr()
    );
}

/// Errors say what is wrong in the user's terms, once, and `-q` means quiet.
#[test]
fn messages_name_the_problem_in_the_users_terms() {
    let s = small_bed();
    std::fs::write(s.file("x.jpg"), b"hi\n").unwrap();
    s.run("mkpellet", &["sphere", "--diameter", "1e300", "-o", "x.pellet"])
        .fails_with("--diameter must be between 0.001 and 10000 mm (got 1e300 mm)");
    let plot = s.run("voidprof", &["b.packing", "--window", "0,10", "--plot", "x.jpg", "-o", "p2.csv"]);
    plot.fails_with("x.jpg: unknown image type");
    assert!(!plot.stderr().contains("x.jpg: x.jpg"), "{}", plot.stderr());
    s.run("voidprof", &["b.packing", "--window", "0,10", "--plot", "nodir/p.png", "-o", "p2.csv"])
        .fails_with("the directory nodir does not exist");
    let stl = s.run("bedexport", &["b.packing", "--stl", "nodir/b.stl"]);
    stl.fails_with("nodir/b.stl: the directory nodir does not exist; create it or give another path");
    assert!(!stl.stderr().contains(".packbed-"), "{}", stl.stderr());
    let mcap = std::fs::read(s.file("b.mcap")).unwrap();
    std::fs::write(s.file("ten.mcap"), &mcap[..10]).unwrap();
    s.run("settle-check", &["ten.mcap"]).fails_with("ten.mcap: truncated: the file ends within its MCAP header");
    std::fs::write(s.file("c.toml"), "tube-diameter = 30\ncount = 3\ncor = \"x\"\n").unwrap();
    s.run("pack", &["--case", "c.toml", "--pellet", "s.pellet", "-o", "c.mcap"])
        .fails_with("c.toml:3: invalid value `\"x\"` for cor: expected a number from 0 to 1");
    let pack = ["--pellet", "s.pellet", "--tube-diameter", "30", "--count", "2", "--quiet", "-o", "t.mcap"];
    s.run("pack", &[&pack[..], &["--max-time", "0.001"]].concat()).fails_with(
        "--max-time must be a whole number of the 0.005 s engine steps (at least 0.005 s; got 0.001 s): give 0.005",
    );
    let quiet = s.run("bedexport", &["b.packing", "--csv", "e.csv", "-q"]);
    quiet.success();
    assert!(quiet.stdout().is_empty() && quiet.stderr().is_empty(), "{}{}", quiet.stdout(), quiet.stderr());
}

/// `--record-every` finer than the engine's 5 ms step would be rounded up: refused, naming
/// the allowed values; a multiple of the step is honoured.
#[test]
fn record_every_is_honoured_or_refused() {
    let s = Scenario::new();
    s.run("mkpellet", &["sphere", "--diameter", "10", "--faces", "500", "-o", "s.pellet"]).success();
    let pack = ["--pellet", "s.pellet", "--tube-diameter", "30", "--count", "2", "--max-time", "0.1", "--quiet"];
    s.run("pack", &[&pack[..], &["--record-every", "0.001", "-o", "a.mcap"]].concat()).fails_with(
        "--record-every must be a whole number of the 0.005 s engine steps (at least 0.005 s; got 0.001 s): give 0.005",
    );
    s.run("pack", &[&pack[..], &["--record-every", "0.012", "-o", "a.mcap"]].concat()).fails_with("give 0.01 or 0.015");
    s.run("pack", &[&pack[..], &["--record-every", "0.005", "-o", "a.mcap"]].concat()).code(1);
    let t = pellet_io::read_trajectory(&std::fs::read(s.file("a.mcap")).unwrap(), "a").unwrap();
    let gaps: Vec<f64> = t.frames.windows(2).map(|w| w[1].time_s - w[0].time_s).collect();
    assert!(gaps.len() >= 15 && gaps.iter().all(|g| (g - 0.005).abs() < 1e-9), "{gaps:?}");
}

/// An STL far from the origin has lost its shape to single precision: refused. The same far
/// mesh as OBJ (double precision) imports with the shape of the near one; absurd sizes are refused.
#[test]
fn mkpellet_import_keeps_precision_or_refuses() {
    let s = Scenario::new();
    s.run("mkpellet", &["sphere", "--diameter", "10", "--obj", "near.obj", "-o", "near.pellet"]).success();
    let obj = std::fs::read_to_string(s.file("near.obj")).unwrap();
    let far: String = obj
        .lines()
        .map(|l| match l.strip_prefix("v ") {
            Some(xyz) => {
                let c: Vec<f64> = xyz.split_whitespace().map(|v| v.parse().unwrap()).collect();
                format!("v {} {} {}\n", c[0] + 1e7, c[1], c[2])
            }
            None => format!("{l}\n"),
        })
        .collect();
    std::fs::write(s.file("far.obj"), far).unwrap();
    let pellet = pellet_io::decode_pellet(&std::fs::read(s.file("near.pellet")).unwrap(), "near").unwrap().pellet;
    let mut mesh = pellet.mesh.clone();
    mesh.translate(&pellet_geom::math::Vector::new(1e4, 0.0, 0.0));
    std::fs::write(s.file("far.stl"), pellet_io::stl_bytes(&mesh, 1e3).unwrap()).unwrap();
    let mut huge = pellet.mesh.clone();
    huge.scale(1e30);
    std::fs::write(s.file("huge.stl"), pellet_io::stl_bytes(&huge, 1e3).unwrap()).unwrap();

    s.run("mkpellet", &["import", "far.stl", "-o", "f.pellet"]).fails_with("STL's single precision resolves only");
    s.run("mkpellet", &["import", "huge.stl", "-o", "h.pellet"]).fails_with("a pellet must be 0.001 to 10000 mm");
    s.run("mkpellet", &["import", "far.obj", "-o", "f.pellet"]).success();
    let info = |name: &str| -> serde_json::Value {
        serde_json::from_str(&s.run("mkpellet", &["info", name, "--json"]).stdout()).unwrap()
    };
    let (near, far) = (info("near.pellet"), info("f.pellet"));
    for key in ["sphericity", "volume_mm3", "area_mm2"] {
        let (a, b) = (near[key].as_f64().unwrap(), far[key].as_f64().unwrap());
        assert!((a / b - 1.0).abs() < 1e-6, "{key}: near {a}, far {b}");
    }
}

/// A bed of a few pellets at rest settles (its energy is a sub-micrometre oscillation whose
/// relative variation never falls within the tolerance), and settle-check agrees with pack.
#[test]
fn a_tiny_bed_at_rest_settles() {
    let s = Scenario::new();
    s.run("mkpellet", &["sphere", "--diameter", "10", "--faces", "500", "-o", "s.pellet"]).success();
    for n in ["1", "2", "3", "5"] {
        let out = format!("n{n}.mcap");
        let args = ["--pellet", "s.pellet", "--tube-diameter", "10.5", "--count", n, "--max-time", "30", "--quiet"];
        s.run("pack", &[&args[..], &["-o", &out]].concat()).success().stdout_has("settled at");
        let check = s.run("settle-check", &[&out, "--json"]);
        check.success();
        let v: serde_json::Value = serde_json::from_str(&check.stdout()).unwrap();
        assert!(v["final_max_speed_m_s"].as_f64().unwrap() < 1e-4, "{n} pellets: {v}");
    }
}

/// Ctrl-C while bedexport writes a large voxel grid removes its temporary files and leaves the
/// outputs as they were.
#[test]
fn an_interrupted_export_leaves_no_temporary_files() {
    let s = small_bed();
    let mut child = Command::new(bin("bedexport"))
        .args(["b.packing", "--voxels", "big.raw", "--voxels-per-dp", "150", "-q"])
        .current_dir(s.path())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let temporary = || {
        std::fs::read_dir(s.path()).unwrap().any(|e| e.unwrap().file_name().to_string_lossy().starts_with(".packbed-"))
    };
    let start = std::time::Instant::now();
    while !temporary() && child.try_wait().unwrap().is_none() && start.elapsed().as_secs() < 60 {
        std::thread::sleep(std::time::Duration::from_millis(1));
    }
    if child.try_wait().unwrap().is_some() {
        // Written before a temporary file was seen: nothing to interrupt on this machine.
        return;
    }
    assert!(Command::new("kill").args(["-INT", &child.id().to_string()]).status().unwrap().success());
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!temporary(), "a temporary file was left behind");
    if out.status.code() == Some(0) {
        // The signal came while the finished outputs were being renamed into place: they all are.
        let header = std::fs::read_to_string(s.file("big.raw.json")).unwrap();
        assert!(serde_json::from_str::<serde_json::Value>(&header).is_ok(), "{header}");
        assert!(s.file("big.raw").exists());
        return;
    }
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("bedexport: error: interrupted"), "{err}");
    assert!(!s.file("big.raw").exists() && !s.file("big.raw.json").exists());
}

/// The tools refuse a pellet or packing file with a changed byte, and read one of the format
/// before checksums with a note.
#[test]
fn damaged_files_fail_their_checksum_and_old_ones_read_with_a_note() {
    let s = small_bed();
    let bytes = std::fs::read(s.file("s.pellet")).unwrap();
    let pellet = pellet_io::decode_pellet(&bytes, "s").unwrap().pellet;
    let x = pellet.mesh.vertices[3].x.to_le_bytes();
    let at = bytes.windows(8).position(|w| w == x).unwrap();
    let mut flipped = bytes.clone();
    flipped[at + 2] ^= 0x01;
    std::fs::write(s.file("f.pellet"), &flipped).unwrap();
    s.run("mkpellet", &["info", "f.pellet"]).fails_with("f.pellet: the pellet file's checksum does not match");
    let packing = std::fs::read(s.file("b.packing")).unwrap();
    let mut damaged = packing.clone();
    let mid = damaged.len() / 2;
    damaged[mid] ^= 0x01;
    std::fs::write(s.file("d.packing"), &damaged).unwrap();
    let out = s.run("voidprof", &["d.packing", "--window", "0,10", "-o", "d.csv"]);
    out.code(2);
    assert!(out.stderr().contains("d.packing: the packing file"), "{}", out.stderr());
    let mut old = bytes[..bytes.len() - 4].to_vec();
    old[8..12].copy_from_slice(&1u32.to_le_bytes());
    std::fs::write(s.file("old.pellet"), &old).unwrap();
    let info = s.run("mkpellet", &["info", "old.pellet"]);
    info.success().stdout_has("sphere");
    assert!(
        info.stderr().contains("mkpellet: note: old.pellet: a pellet file of format version 1"),
        "{}",
        info.stderr()
    );
}
