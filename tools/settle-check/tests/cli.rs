//! `settle-check` at the process boundary, on trajectories written in the test.

use std::path::Path;
use std::process::{Command, Output};

use pellet_geom::{Pellet, Resolution, ShapeSpec, Tube};
use pellet_io::{EnergyRecord, Frame, Provenance, TrajectoryHeader, TrajectoryWriter};

fn settle_check(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_settle-check")).args(args).current_dir(dir).output().expect("run settle-check")
}

/// A sphere dropped at t = 0 whose kinetic energy decays to rest by `rest_at`
/// (or never, if `None`), frames every 0.05 s, energy every 1 ms, for 1 s.
fn write_trajectory(path: &Path, rest_at: Option<f64>) {
    let pellet = Pellet::build(ShapeSpec::Sphere { diameter_mm: 10.0 }, Resolution { level: 0, faces: None }).unwrap();
    let pellet_bytes = pellet_io::encode_pellet(&pellet_io::PelletFile {
        length_unit: "m".into(),
        provenance: Provenance { tool: "test".into(), version: "0".into(), args: vec![] },
        pellet,
    })
    .unwrap();
    let provenance = Provenance { tool: "test".into(), version: "0".into(), args: vec![] };
    let tube = Tube { diameter: 0.04, lid_height: None };
    let files = [pellet_bytes];
    let header = TrajectoryHeader {
        provenance: &provenance,
        config_json: r#"{"density_kg_m3": 8030.0}"#,
        seed: 1,
        build: "git 0123456789ab",
        pellet_files: &files,
        tube: &tube,
    };
    let mut w = TrajectoryWriter::create(path, &header).unwrap();
    for k in 0..=1000 {
        let t = k as f64 * 1e-3;
        let moving = rest_at.is_none_or(|r| t < r);
        let ke = if moving { 1e-3 * (2.0 - t) } else { 0.0 };
        let z = 0.005 + if moving { 0.01 * (1.0 - t) } else { 0.0 };
        w.write_energy(&EnergyRecord {
            time_s: t,
            pellets: 1,
            kinetic_translational_j: ke,
            max_speed_m_s: if moving { 0.1 } else { 0.0 },
            ..Default::default()
        })
        .unwrap();
        if k % 100 == 99 {
            // As pack does: close the chunk so a killed run keeps it.
            w.flush().unwrap();
        }
        if k % 50 == 0 {
            w.write_frame(&Frame {
                time_s: t,
                type_index: vec![0],
                positions: vec![[0.001, -0.002, z]],
                orientations: vec![[1.0, 0.0, 0.0, 0.0]],
                velocities: None,
            })
            .unwrap();
        }
    }
    w.finish().unwrap();
}

#[test]
fn a_settled_run_gives_exit_0_and_the_settled_frame() {
    let dir = tempfile::tempdir().unwrap();
    write_trajectory(&dir.path().join("bed.mcap"), Some(0.4));
    let out = settle_check(dir.path(), &["bed.mcap", "-o", "bed.packing", "--csv", "poses.csv"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{text}{}", String::from_utf8_lossy(&out.stderr));
    // At rest from 0.4 s; the 0.15 s window is quiet from 0.55 s.
    assert!(text.contains("settled at 0.5500 s"), "{text}");
    let packing = pellet_io::decode_packing(&std::fs::read(dir.path().join("bed.packing")).unwrap(), "p").unwrap();
    assert_eq!(packing.bed.pellets.len(), 1);
    assert!((packing.time_s - 0.55).abs() < 1e-9);
    assert_eq!(packing.bed.pellets[0].position, [0.001, -0.002, 0.005]);
    assert!(packing.verdict.unwrap().settled);
    let csv = std::fs::read_to_string(dir.path().join("poses.csv")).unwrap();
    assert_eq!(csv.lines().next(), Some("id,x,y,z,qw,qx,qy,qz"));
    assert_eq!(csv.lines().nth(1), Some("0,1,-2,5,1,0,0,0"));
}

#[test]
fn an_unsettled_run_exits_1_and_says_why() {
    let dir = tempfile::tempdir().unwrap();
    write_trajectory(&dir.path().join("bed.mcap"), None);
    let out = settle_check(dir.path(), &["bed.mcap", "--json"]);
    assert_eq!(out.status.code(), Some(1));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["settled"], false);
    // The build of the `pack` that wrote the trajectory is passed on.
    assert_eq!(v["build"], "git 0123456789ab");
    // And its stepper: a configuration that does not name one was the force-level stepper's.
    assert_eq!(v["stepper"], "acceleration");
    // Energy still falls linearly, by 0.15/1.15 of its value per window.
    assert!(v["reason"].as_str().unwrap().contains("kinetic energy still changes"), "{v}");
}

#[test]
fn at_and_all_frames_pick_frames_by_time() {
    let dir = tempfile::tempdir().unwrap();
    write_trajectory(&dir.path().join("bed.mcap"), Some(0.4));
    let out = settle_check(dir.path(), &["bed.mcap", "--at", "0.26", "-o", "t.packing"]);
    assert_eq!(out.status.code(), Some(0));
    let p = pellet_io::decode_packing(&std::fs::read(dir.path().join("t.packing")).unwrap(), "t").unwrap();
    assert!((p.time_s - 0.25).abs() < 1e-9);
    let out = settle_check(dir.path(), &["bed.mcap", "--all-frames", "--csv", "all.csv"]);
    assert_eq!(out.status.code(), Some(0));
    let csv = std::fs::read_to_string(dir.path().join("all.csv")).unwrap();
    assert_eq!(csv.lines().next(), Some("time,id,x,y,z,qw,qx,qy,qz"));
    assert_eq!(csv.lines().count(), 1 + 21);
}

#[test]
fn a_truncated_trajectory_is_read_up_to_its_last_chunk() {
    let dir = tempfile::tempdir().unwrap();
    write_trajectory(&dir.path().join("bed.mcap"), Some(0.4));
    let bytes = std::fs::read(dir.path().join("bed.mcap")).unwrap();
    std::fs::write(dir.path().join("cut.mcap"), &bytes[..bytes.len() * 2 / 3]).unwrap();
    let out = settle_check(dir.path(), &["cut.mcap"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(matches!(out.status.code(), Some(0) | Some(1)), "{err}");
    assert!(err.contains("is truncated"), "{err}");
    let v = settle_check(dir.path(), &["cut.mcap", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&v.stdout).unwrap();
    // Some but not all of the 1 s run survived.
    let t = v["final_time_s"].as_f64().unwrap();
    assert!(t > 0.2 && t < 1.0, "final time {t}");
}

/// Byte offsets of the chunk records (opcode 0x06) of an MCAP file, walking its records.
fn chunk_offsets(bytes: &[u8]) -> Vec<usize> {
    let (mut at, mut out) = (8, Vec::new());
    while at + 9 <= bytes.len() {
        let len = u64::from_le_bytes(bytes[at + 1..at + 9].try_into().unwrap()) as usize;
        if bytes[at] == 0x06 {
            out.push(at);
        }
        at += 9 + len;
    }
    out
}

#[test]
fn a_chunk_with_a_corrupt_size_is_read_up_to_that_chunk_not_aborted_on() {
    // Read through mcap's ChunkFlattener, which bounds no record length, this chunk made
    // settle-check abort asking the allocator for 5e17 bytes (pellet_io's `mcap_records`).
    let dir = tempfile::tempdir().unwrap();
    write_trajectory(&dir.path().join("bed.mcap"), Some(0.4));
    let mut bytes = std::fs::read(dir.path().join("bed.mcap")).unwrap();
    let chunks = chunk_offsets(&bytes);
    assert!(chunks.len() >= 2, "the 1 s run has several chunks: {chunks:?}");
    let size_field = chunks[chunks.len() - 1] + 9 + 16;
    bytes[size_field..size_field + 8].copy_from_slice(&506_381_209_866_536_720u64.to_le_bytes());
    std::fs::write(dir.path().join("bad.mcap"), &bytes).unwrap();
    let out = settle_check(dir.path(), &["bad.mcap", "--json"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(matches!(out.status.code(), Some(0) | Some(1)), "{err}");
    // The file is whole: its last chunk is damaged, not cut.
    assert!(err.contains("bad.mcap: the file is damaged after t = "), "{err}");
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!((&v["truncated"], &v["damaged"]), (&false.into(), &true.into()), "{v}");
}

#[test]
fn damage_anywhere_in_a_trajectory_is_an_error_or_a_truncation_never_a_crash() {
    // Zeroed or inverted runs of bytes at 48 places each: the reader once aborted on some of them
    // (a record length it reserved before decompressing).
    let dir = tempfile::tempdir().unwrap();
    write_trajectory(&dir.path().join("bed.mcap"), Some(0.4));
    let bytes = std::fs::read(dir.path().join("bed.mcap")).unwrap();
    let places = 48;
    for k in 0..places {
        let at = 8 + k * (bytes.len() - 8) / places;
        for (name, invert) in [("zeroed", false), ("inverted", true)] {
            let mut b = bytes.clone();
            let end = (at + 256).min(b.len());
            b[at..end].iter_mut().for_each(|x| *x = if invert { !*x } else { 0 });
            std::fs::write(dir.path().join("d.mcap"), &b).unwrap();
            let out = settle_check(dir.path(), &["d.mcap", "--json"]);
            let err = String::from_utf8_lossy(&out.stderr);
            assert!(
                matches!(out.status.code(), Some(0..=2)) && !err.contains("panicked"),
                "bytes {at}..{end} {name}: {:?}\n{err}",
                out.status
            );
            // An error is one line; a warning (damaged, truncated) one line each.
            if out.status.code() == Some(2) {
                assert_eq!(err.trim_end().lines().count(), 1, "bytes {at}..{end} {name}: {err}");
            }
            assert!(err.lines().all(|l| l.starts_with("settle-check: ")), "bytes {at}..{end} {name}: {err}");
            assert!(std::fs::read(dir.path().join("d.mcap")).unwrap() == b, "bytes {at}..{end} {name}: input changed");
        }
    }
}

#[test]
fn bad_input_is_a_one_line_error_with_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("junk.mcap"), b"definitely not an mcap file").unwrap();
    for (args, needle) in [
        (vec!["junk.mcap"], "not an MCAP file"),
        (vec!["missing.mcap"], "missing.mcap"),
        (vec!["junk.mcap", "--settle-window", "-1"], "not an MCAP"),
    ] {
        let out = settle_check(dir.path(), &args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(err.contains(needle), "{err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    }
    write_trajectory(&dir.path().join("bed.mcap"), Some(0.4));
    let out = settle_check(dir.path(), &["bed.mcap", "--settle-window", "-1", "-o", "x.packing"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--settle-window must be"));
    assert!(!dir.path().join("x.packing").exists());
    // Every number has its range; a time far past the frames picked the first frame.
    for (args, needle) in [
        (&["--settle-tolerance", "5"][..], "--settle-tolerance must be in (0, 1] (got 5)"),
        (&["--settle-window", "1e300"][..], "--settle-window must be in (0, 1000] s (got 1e300)"),
        (&["--at", "1e300"][..], "--at must be a time in s within the recorded frames"),
        (&["--at", "-3"][..], "(got -3)"),
    ] {
        let out = settle_check(dir.path(), &[&["bed.mcap", "-o", "x.packing"][..], args].concat());
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(err.contains(needle) && err.trim_end().lines().count() == 1, "{err}");
        assert!(!dir.path().join("x.packing").exists());
    }
    // Usage errors (clap's) are one line too, with the flag and what it takes.
    let out = settle_check(dir.path(), &["bed.mcap", "--settle-window", "soon"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert_eq!(
        err.trim_end(),
        "settle-check: error: invalid value 'soon' for --settle-window: expected a number (see settle-check --help)"
    );
}

/// Runs settle-check with its stdout closed, as `settle-check … >&-` does; `Stdio::null()`
/// would be an open stdout.
fn settle_check_stdout_closed(dir: &Path, args: &[&str]) -> Output {
    Command::new("sh")
        .args(["-c", r#""$0" "$@" >&-"#, env!("CARGO_BIN_EXE_settle-check")])
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run settle-check through sh")
}

#[track_caller]
fn assert_one_line_error(out: &Output, needles: &[&str]) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.starts_with("settle-check: error: "), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    for needle in needles {
        assert!(err.contains(needle), "stderr lacks {needle:?}: {err}");
    }
}

#[test]
fn two_outputs_naming_one_file_are_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    write_trajectory(&dir.path().join("bed.mcap"), Some(0.4));
    std::fs::create_dir(dir.path().join("sub")).unwrap();
    std::os::unix::fs::symlink("x", dir.path().join("link")).unwrap();
    for (o, csv) in [("x", "x"), ("x", "./x"), ("sub/../x", "x"), ("x", "link"), ("-", "-")] {
        let out = settle_check(dir.path(), &["bed.mcap", "-o", o, "--csv", csv]);
        assert_one_line_error(&out, &["-o", "--csv", "give each output its own file"]);
        assert!(out.stdout.is_empty(), "{o} {csv}: something was written to stdout");
        assert!(!dir.path().join("x").exists(), "{o} {csv}: x was written");
    }
    let out = settle_check(dir.path(), &["bed.mcap", "-o", "x", "--csv", "x"]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("-o and --csv both name x; give each output its own file"));
}

#[test]
fn a_closed_stdout_is_an_error_not_a_silent_success() {
    let dir = tempfile::tempdir().unwrap();
    write_trajectory(&dir.path().join("bed.mcap"), Some(0.4));
    for args in [&["bed.mcap", "--csv", "-"][..], &["bed.mcap"]] {
        let out = settle_check_stdout_closed(dir.path(), args);
        assert_one_line_error(&out, &["cannot write to standard output: it is closed"]);
    }
    // Discarding stdout is not closing it.
    let status = Command::new(env!("CARGO_BIN_EXE_settle-check"))
        .args(["bed.mcap", "--csv", "-"])
        .current_dir(dir.path())
        .stdout(std::process::Stdio::null())
        .status()
        .unwrap();
    assert_eq!(status.code(), Some(0));
}
