//! `pack --threads N`: the same bed bit for bit for every N, a run resumed with another N, and
//! the flag's mistakes.

use std::path::Path;
use std::process::{Command, Output};

fn run(dir: &Path, exe: &Path, args: &[&str]) -> Output {
    Command::new(exe).args(args).current_dir(dir).output().expect("run tool")
}

fn pack(dir: &Path, args: &[&str]) -> Output {
    run(dir, Path::new(env!("CARGO_BIN_EXE_pack")), args)
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// A temporary directory with `c.pellet` (10 × 10 mm cylinder) and `s.pellet` (10 mm sphere).
fn setup() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let mk = Path::new(env!("CARGO_BIN_EXE_pack")).with_file_name("mkpellet");
    assert!(mk.exists(), "build the workspace binaries first (make test does)");
    for args in [
        &["cylinder", "--diameter", "10", "--height", "10", "-o", "c.pellet"][..],
        &["sphere", "--diameter", "10", "--faces", "500", "-o", "s.pellet"],
    ] {
        let out = run(dir.path(), &mk, args);
        assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    }
    dir
}

fn read(dir: &Path, name: &str) -> pellet_io::Trajectory {
    let bytes = std::fs::read(dir.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
    pellet_io::read_trajectory(&bytes, name).unwrap()
}

/// Every frame's poses (and velocities) and every energy record, bit for bit.
fn assert_same_run(a: &pellet_io::Trajectory, b: &pellet_io::Trajectory, what: &str) {
    assert!(!a.frames.is_empty(), "{what}: no frames");
    assert_eq!(a.frames.len(), b.frames.len(), "{what}");
    for (fa, fb) in a.frames.iter().zip(&b.frames) {
        let bits = |f: &pellet_io::Frame| {
            let p = f.positions.iter().flatten().map(|x| x.to_bits());
            let q = f.orientations.iter().flatten().map(|x| x.to_bits());
            let v = f.velocities.iter().flatten().flatten().map(|x| x.to_bits());
            p.chain(q).chain(v).collect::<Vec<u64>>()
        };
        assert_eq!(bits(fa), bits(fb), "{what}: frame at t = {}", fa.time_s);
    }
    assert_eq!(a.frames, b.frames, "{what}");
    assert_eq!(a.energy, b.energy, "{what}");
}

/// A batch of `count` pellets of `pellet` in a 40 mm tube until `max_time`, on `threads`.
fn bed(pellet: &str, count: &str, max_time: &str, threads: &str, output: &str) -> Vec<String> {
    [
        "--pellet",
        pellet,
        "--tube-diameter",
        "40",
        "--count",
        count,
        "--scheme",
        "batch",
        "--seed",
        "3",
        "--max-time",
        max_time,
        "--record-velocities",
        "--checkpoint-every",
        "0.1",
        "--quiet",
        "--threads",
        threads,
        "-o",
        output,
    ]
    .map(String::from)
    .to_vec()
}

fn pack_owned(dir: &Path, args: &[String]) -> Output {
    pack(dir, &args.iter().map(String::as_str).collect::<Vec<_>>())
}

#[test]
fn every_thread_count_packs_the_same_bed_bit_for_bit() {
    let dir = setup();
    let d = dir.path();
    let beds: [(&str, &str, &str, &[&str]); 3] = [
        ("c.pellet", "20", "0.4", &[]),
        // Enough contacts for the impulse solve to sweep on several threads.
        ("s.pellet", "150", "0.4", &[]),
        ("c.pellet", "20", "0.3", &["--stepper", "acceleration"]),
    ];
    for (pellet, count, max_time, extra) in beds {
        let runs: Vec<pellet_io::Trajectory> = ["1", "2", "3"]
            .iter()
            .map(|threads| {
                let output = format!("{threads}.mcap");
                let mut args = bed(pellet, count, max_time, threads, &output);
                args.extend(extra.iter().map(|s| s.to_string()));
                let out = pack_owned(d, &args);
                assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
                let t = read(d, &output);
                assert!(t.run["config"].contains(&format!(r#""threads":{threads}"#)), "{}", t.run["config"]);
                t
            })
            .collect();
        let what = format!("{count} × {pellet} {extra:?}");
        // The bed moved: pellets fell and met (not a cloud in free fall).
        let (first, last) = (&runs[0].frames[0], runs[0].frames.last().unwrap());
        assert!(first.positions.iter().zip(&last.positions).any(|(a, b)| (a[2] - b[2]).abs() > 0.01), "{what}");
        assert_same_run(&runs[0], &runs[1], &format!("{what}, 1 and 2 threads"));
        assert_same_run(&runs[0], &runs[2], &format!("{what}, 1 and 3 threads"));
    }
}

/// A run made on 2 threads, stopped at its time limit, goes on on 1 to the frames of the
/// uninterrupted run (a bed of spheres large enough for a solve on both threads); the metadata
/// records each leg's threads.
#[test]
fn a_run_made_on_two_threads_resumes_on_one_exactly() {
    let dir = setup();
    let d = dir.path();
    assert_eq!(pack_owned(d, &bed("s.pellet", "150", "0.4", "2", "whole.mcap")).status.code(), Some(1));
    let whole = read(d, "whole.mcap");
    assert_eq!(pack_owned(d, &bed("s.pellet", "150", "0.25", "2", "a.mcap")).status.code(), Some(1));
    let mut again = bed("s.pellet", "150", "0.4", "1", "a.mcap");
    again.push("--resume".into());
    let out = pack_owned(d, &again);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let a = read(d, "a.mcap");
    assert!(a.run["config"].contains(r#""threads":1"#), "{}", a.run["config"]);
    assert_same_run(&a, &whole, "resumed on 1 thread");
}

#[test]
fn a_bad_thread_count_is_a_one_line_error() {
    let dir = setup();
    let d = dir.path();
    for (value, needle) in [
        ("0", "--threads must be in [1, 1024] (got 0)"),
        ("two", "invalid value 'two' for --threads"),
        ("-2", "invalid value '-2' for --threads"),
        ("1025", "--threads must be in [1, 1024] (got 1025)"),
    ] {
        let out = pack(
            d,
            &["--pellet", "s.pellet", "--tube-diameter", "30", "--count", "3", "--threads", value, "-o", "x.mcap"],
        );
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{value}: {err}");
        assert!(err.contains(needle), "{value}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    }
    std::fs::write(d.join("case.toml"), "threads = 0\n").unwrap();
    let out = pack(
        d,
        &["--case", "case.toml", "--pellet", "s.pellet", "--tube-diameter", "30", "--count", "3", "-o", "x.mcap"],
    );
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("case.toml:1: invalid value `0` for threads: expected a whole number from 1 to 1024"),
        "{err}"
    );
    assert!(!d.join("x.mcap").exists());
}
