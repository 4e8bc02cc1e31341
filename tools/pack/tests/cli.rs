//! `pack` at the process boundary: a few spheres, short runs.

use std::path::Path;
use std::process::{Command, Output};

fn tool(name: &str) -> std::path::PathBuf {
    // mkpellet and settle-check are built beside pack by `cargo build --workspace --bins`.
    let pack = Path::new(env!("CARGO_BIN_EXE_pack"));
    pack.with_file_name(name)
}

fn run(dir: &Path, exe: &Path, args: &[&str]) -> Output {
    Command::new(exe).args(args).current_dir(dir).output().expect("run tool")
}

fn pack(dir: &Path, args: &[&str]) -> Output {
    run(dir, Path::new(env!("CARGO_BIN_EXE_pack")), args)
}

fn setup() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let mk = tool("mkpellet");
    assert!(mk.exists(), "build the workspace binaries first (make test does)");
    let out = run(dir.path(), &mk, &["sphere", "--diameter", "10", "--faces", "500", "-o", "s.pellet"]);
    assert_eq!(out.status.code(), Some(0));
    dir
}

const SHORT: &[&str] = &[
    "--pellet",
    "s.pellet",
    "--tube-diameter",
    "30",
    "--count",
    "4",
    "--max-time",
    "0.4",
    "--quiet",
    "--spacing",
    "0.05",
];

#[test]
fn a_short_run_writes_a_readable_deterministic_trajectory() {
    let dir = setup();
    let mut a: Vec<&str> = SHORT.to_vec();
    a.extend(["--seed", "7", "-o", "a.mcap"]);
    let out = pack(dir.path(), &a);
    // 0.4 s is too short to settle: exit 1 (not settled), but the trajectory is complete.
    assert_eq!(out.status.code(), Some(1), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(String::from_utf8_lossy(&out.stderr).contains("did not settle within --max-time"));
    let bytes = std::fs::read(dir.path().join("a.mcap")).unwrap();
    let t = pellet_io::read_trajectory(&bytes, "a.mcap").unwrap();
    assert!(t.truncated.is_none());
    assert_eq!(t.pellet_files.len(), 1);
    assert!((t.tube.unwrap().diameter - 0.030).abs() < 1e-15);
    assert_eq!(t.run["seed"], "7");
    assert!(t.energy.len() >= 80, "{} energy records", t.energy.len());
    assert_eq!(t.energy.last().unwrap().pellets, 4);
    let last = t.frames.last().unwrap();
    assert_eq!(last.positions.len(), 4);
    for p in &last.positions {
        // Inside the tube (radius 15 mm, sphere radius 5 mm) and above the floor.
        assert!(p[0].hypot(p[1]) <= 0.010 + 1e-4 && p[2] >= 0.005 - 1e-4, "{p:?}");
    }
    // Same seed: the same bytes. Another seed: another bed.
    let mut b: Vec<&str> = SHORT.to_vec();
    b.extend(["--seed", "7", "-o", "b.mcap"]);
    pack(dir.path(), &b);
    let again = std::fs::read(dir.path().join("b.mcap")).unwrap();
    let tb = pellet_io::read_trajectory(&again, "b.mcap").unwrap();
    assert_eq!(tb.frames, t.frames);
    assert_eq!(tb.energy, t.energy);
    let mut c: Vec<&str> = SHORT.to_vec();
    c.extend(["--seed", "8", "-o", "c.mcap"]);
    pack(dir.path(), &c);
    let tc = pellet_io::read_trajectory(&std::fs::read(dir.path().join("c.mcap")).unwrap(), "c.mcap").unwrap();
    assert_ne!(tc.frames.last().unwrap().positions, last.positions);
    // settle-check reads it (not settled yet: exit 1).
    let sc = run(dir.path(), &tool("settle-check"), &["a.mcap", "-o", "a.packing"]);
    assert_eq!(sc.status.code(), Some(1), "{}", String::from_utf8_lossy(&sc.stderr));
    assert!(dir.path().join("a.packing").exists());
}

#[test]
fn bad_input_is_a_one_line_error_and_never_clobbers_the_output() {
    let dir = setup();
    std::fs::write(dir.path().join("keep.mcap"), b"precious").unwrap();
    let cases: &[(&[&str], &str)] = &[
        (&["--tube-diameter", "9"], "too narrow for this pellet"),
        (&["--cor", "1.5"], "--cor must be in [0, 1]"),
        (&["--wall-cor", "-0.2"], "--wall-cor"),
        (&["--density", "-5"], "--density"),
        (&["--tube-diameter", "nan"], "--tube-diameter"),
    ];
    for (extra, needle) in cases {
        let mut args = vec!["--pellet", "s.pellet", "--tube-diameter", "30", "--count", "3", "-o", "keep.mcap"];
        // Each flag once: replace the base value or add the flag.
        for pair in extra.chunks(2) {
            if let Some(i) = args.iter().position(|a| *a == pair[0]) {
                args[i + 1] = pair[1];
            } else {
                args.extend_from_slice(pair);
            }
        }
        let out = pack(dir.path(), &args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert_eq!(std::fs::read(dir.path().join("keep.mcap")).unwrap(), b"precious");
    }
    let out =
        pack(dir.path(), &["--pellet", "missing.pellet", "--tube-diameter", "30", "--count", "3", "-o", "x.mcap"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("missing.pellet"));
    std::fs::write(dir.path().join("case.toml"), "tube-diameter = 30\ncount = 3\ncorr = 0.5\n").unwrap();
    let out = pack(dir.path(), &["--case", "case.toml", "--pellet", "s.pellet", "-o", "x.mcap"]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("corr"));
    assert!(!dir.path().join("x.mcap").exists());
}

#[test]
fn foxglove_channels_place_every_pellet_of_every_frame() {
    let dir = setup();
    let mut a: Vec<&str> = SHORT.to_vec();
    a.extend(["--seed", "2", "--foxglove", "-o", "v.mcap"]);
    let out = pack(dir.path(), &a);
    assert_eq!(out.status.code(), Some(1), "{}", String::from_utf8_lossy(&out.stderr));
    let bytes = std::fs::read(dir.path().join("v.mcap")).unwrap();
    // The packbed reader still sees its own channels.
    let t = pellet_io::read_trajectory(&bytes, "v.mcap").unwrap();
    // Read the viewer channels with the mcap crate alone, as a viewer would.
    let mut entities: Vec<String> = Vec::new();
    let mut transforms = Vec::new();
    for message in mcap::MessageStream::new(&bytes).unwrap() {
        let m = message.unwrap();
        let schema = m.channel.schema.as_ref().unwrap();
        let json: serde_json::Value = match m.channel.topic.as_str() {
            "/foxglove/scene" | "/foxglove/transforms" => {
                assert_eq!(m.channel.message_encoding, "json");
                assert_eq!(schema.encoding, "jsonschema");
                serde_json::from_slice(&m.data).unwrap()
            }
            _ => continue,
        };
        if m.channel.topic == "/foxglove/scene" {
            assert_eq!(schema.name, "foxglove.SceneUpdate");
            for e in json["entities"].as_array().unwrap() {
                // Entities are announced no later than their first transform.
                assert!(transforms.len() <= t.frames.len());
                entities.push(e["id"].as_str().unwrap().to_string());
            }
        } else {
            assert_eq!(schema.name, "foxglove.FrameTransforms");
            let list = json["transforms"].as_array().unwrap().clone();
            for tf in &list {
                let child = tf["child_frame_id"].as_str().unwrap();
                assert!(entities.iter().any(|e| e == child), "{child} placed before it was drawn");
            }
            transforms.push((m.log_time, list));
        }
    }
    assert_eq!(entities[0], "tube");
    assert_eq!(entities.len(), 1 + 4, "tube and 4 pellets: {entities:?}");
    assert_eq!(transforms.len(), t.frames.len(), "one transform message per pose frame");
    for ((log_time, list), frame) in transforms.iter().zip(&t.frames) {
        assert_eq!(*log_time, (frame.time_s * 1e9).round() as u64);
        assert_eq!(list.len(), frame.positions.len());
        for (tf, (p, q)) in list.iter().zip(frame.positions.iter().zip(&frame.orientations)) {
            assert_eq!(tf["translation"]["z"].as_f64().unwrap(), p[2]);
            assert_eq!(tf["rotation"]["w"].as_f64().unwrap(), q[0]);
            assert_eq!(tf["rotation"]["x"].as_f64().unwrap(), q[1]);
        }
    }
}

#[test]
fn the_batch_scheme_releases_every_pellet_at_once_and_settles() {
    let dir = setup();
    let args = ["--pellet", "s.pellet", "--tube-diameter", "30", "--count", "12", "--scheme", "batch", "--quiet"];
    let mut a = args.to_vec();
    a.extend(["-o", "batch.mcap"]);
    let out = pack(dir.path(), &a);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let t = pellet_io::read_trajectory(&std::fs::read(dir.path().join("batch.mcap")).unwrap(), "batch.mcap").unwrap();
    assert_eq!(t.frames[0].positions.len(), 12, "all pellets are there at t = 0");
    assert_eq!(t.frames[0].time_s, 0.0);
    for p in &t.frames.last().unwrap().positions {
        assert!(p[0].hypot(p[1]) <= 0.010 + 1e-4 && p[2] >= 0.005 - 1e-4, "{p:?}");
    }
    // A batch needs a count: with a fill height it is a one-line error.
    let mut f: Vec<&str> = args.iter().copied().filter(|s| *s != "--count" && *s != "12").collect();
    f.extend(["--fill-height", "40", "-o", "f.mcap"]);
    let out = pack(dir.path(), &f);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("batch") && err.contains("--count"), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(!dir.path().join("f.mcap").exists());
}

/// An output that cannot be written is refused before the run, not after simulating the whole
/// bed: an empty name, a directory, a missing directory. Nothing is left behind.
#[test]
fn an_unwritable_output_is_refused_before_the_run() {
    let dir = setup();
    std::fs::create_dir(dir.path().join("beds")).unwrap();
    for (output, needle) in [("", "-o is empty"), ("beds", "is a directory"), ("nowhere/bed.mcap", "does not exist")] {
        let args = ["--pellet", "s.pellet", "--tube-diameter", "30", "--count", "200", "-o", output];
        let started = std::time::Instant::now();
        let out = pack(dir.path(), &args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "-o {output:?}: {err}");
        assert!(err.contains(needle), "-o {output:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(started.elapsed().as_secs_f64() < 5.0, "-o {output:?} ran the bed first");
    }
    let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(left.len(), 2, "only the pellet and the directory: {left:?}");
    assert_eq!(std::fs::read_dir(dir.path().join("beds")).unwrap().count(), 0);
}

/// The velocity-level stepper's summary says how its contact solve fared at the end of the run:
/// a small bed at rest has every loaded contact warm started and every solve converged.
#[test]
fn the_velocity_stepper_reports_its_contact_solve() {
    let dir = setup();
    let args = [
        "--pellet",
        "s.pellet",
        "--tube-diameter",
        "30",
        "--count",
        "12",
        "--scheme",
        "batch",
        "--stepper",
        "velocity",
        "-o",
        "v.mcap",
    ];
    let out = pack(dir.path(), &args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    let line = err.lines().find(|l| l.contains("contact solve over the last 0.1 s")).expect("the solve's line");
    let figure = |after: &str| -> f64 {
        let tail = &line[line.find(after).unwrap_or_else(|| panic!("{after} in {line}")) + after.len()..];
        tail.split_whitespace().next().unwrap().parse().unwrap()
    };
    // Spheres: one point a pair.
    assert_eq!(figure("0.1 s: "), 1.0, "{line}");
    assert_eq!(figure("a pair, "), 100.0, "{line}");
    assert_eq!(figure("warm started, "), 100.0, "{line}");
}

/// A case file's relative paths name files beside it, whatever the working directory.
#[test]
fn case_file_paths_are_relative_to_the_case_file() {
    let dir = setup();
    std::fs::create_dir(dir.path().join("cases")).unwrap();
    std::fs::write(
        dir.path().join("cases/c.toml"),
        "pellet = \"../s.pellet\"\ntube-diameter = 30\ncount = 3\nmax-time = 0.05\noutput = \"c.mcap\"\n",
    )
    .unwrap();
    let out = pack(dir.path(), &["--case", "cases/c.toml", "--quiet"]);
    // Too short to settle (exit 1), but read the pellet beside the case and wrote beside it.
    assert_eq!(out.status.code(), Some(1), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(dir.path().join("cases/c.mcap").exists());
    // A flag stays relative to the working directory.
    let out = pack(dir.path(), &["--case", "cases/c.toml", "--quiet", "-o", "top.mcap"]);
    assert_eq!(out.status.code(), Some(1), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(dir.path().join("top.mcap").exists());
}

/// `--release-height` reaches the feeder: every pellet of a shallow bed first appears at that
/// height (100 mm) instead of 30 mm above the bed, and the batch scheme, which pours nothing,
/// refuses it.
#[test]
fn pellets_poured_from_a_release_height_enter_there() {
    let dir = setup();
    let mut a: Vec<&str> = SHORT.to_vec();
    a.extend(["--release-height", "100", "--record-every", "0.005", "-o", "r.mcap"]);
    let out = pack(dir.path(), &a);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let t = read(dir.path(), "r.mcap");
    let mut first = Vec::new();
    for f in &t.frames {
        while first.len() < f.positions.len() {
            first.push(f.positions[first.len()][2]);
        }
    }
    assert_eq!(first.len(), 4, "{first:?}");
    // A frame is recorded every engine step, right after a pellet enters: at the release height.
    assert!(first.iter().all(|z| (z - 0.1).abs() < 1e-12), "{first:?}");
    let mut b: Vec<&str> = SHORT.to_vec();
    b.extend(["--scheme", "batch", "--release-height", "100", "-o", "b.mcap"]);
    let batch = pack(dir.path(), &b);
    assert_eq!(batch.status.code(), Some(2));
    let msg = stderr(&batch);
    assert!(msg.contains("--release-height") && msg.lines().count() == 1, "{msg}");
    assert!(!dir.path().join("b.mcap").exists());
}

fn read(dir: &Path, name: &str) -> pellet_io::Trajectory {
    let bytes = std::fs::read(dir.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
    pellet_io::read_trajectory(&bytes, name).unwrap()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// Six spheres fed one by one into a 30 mm tube until `max_time`, with checkpoints every 0.1 s;
/// a settle window longer than the run, so that it always ends at its time limit.
fn resumable(max_time: &str, output: &str) -> Vec<String> {
    let mut a: Vec<String> = SHORT.iter().map(|s| s.to_string()).collect();
    let at = a.iter().position(|s| s == "--max-time").unwrap();
    a[at + 1] = max_time.into();
    let count = a.iter().position(|s| s == "--count").unwrap();
    a[count + 1] = "6".into();
    a.extend(["--checkpoint-every", "0.1", "--settle-window", "5", "-o", output].map(String::from));
    a
}

fn pack_owned(dir: &Path, args: &[String]) -> Output {
    pack(dir, &args.iter().map(String::as_str).collect::<Vec<_>>())
}

/// A run that reached its --max-time goes on with a larger one; a killed run (a `.part` cut
/// in the middle of a chunk) goes on from its last checkpoint. Both give the uninterrupted
/// run's trajectory: every frame and energy record equal.
#[test]
fn resume_continues_a_stopped_or_killed_run_exactly() {
    let dir = setup();
    let d = dir.path();
    assert_eq!(pack_owned(d, &resumable("0.9", "whole.mcap")).status.code(), Some(1));
    let whole = read(d, "whole.mcap");
    assert!(whole.checkpoint.is_some());

    // The run of `output` continued to 0.9 s: it ends at the time limit again.
    let resume_to_the_end = |output: &str| {
        let mut again = resumable("0.9", output);
        again.push("--resume".into());
        let out = pack_owned(d, &again);
        assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
        read(d, output)
    };

    // Past the time limit.
    assert_eq!(pack_owned(d, &resumable("0.45", "a.mcap")).status.code(), Some(1));
    let a = resume_to_the_end("a.mcap");
    assert_eq!(a.frames, whole.frames);
    assert_eq!(a.energy, whole.energy);
    assert!(a.run["args"].contains("--resume"));
    // Both legs were run by this build: it is named once.
    let build = &whole.run["build"];
    assert!(build.starts_with("git ") || build.starts_with("unknown"), "{build}");
    assert_eq!(&a.run["build"], build);

    // Killed: the complete file cut at 60 % of its bytes, under the name a killed run leaves.
    let bytes = std::fs::read(d.join("whole.mcap")).unwrap();
    std::fs::write(d.join("k.mcap.part"), &bytes[..bytes.len() * 6 / 10]).unwrap();
    let cut = read(d, "k.mcap.part");
    assert!(cut.truncated.is_some() && cut.checkpoint.is_some());
    let k = resume_to_the_end("k.mcap");
    assert_eq!(k.frames, whole.frames);
    assert_eq!(k.energy, whole.energy);
    assert!(!d.join("k.mcap.part").exists() && !d.join("k.mcap.resume").exists());
}

/// A run made with settings whose default has since changed (here the stepper, given as the
/// force-level one) resumes with them when the same command leaves them out, to the
/// uninterrupted run's frames; asking for another stepper is refused, naming it.
#[test]
fn a_run_resumes_with_the_stepper_it_was_made_with() {
    let dir = setup();
    let d = dir.path();
    let with_stepper = |max_time: &str, output: &str, stepper: Option<&str>| {
        let mut a = resumable(max_time, output);
        if let Some(s) = stepper {
            a.extend(["--stepper", s].map(String::from));
        }
        a
    };
    let whole = with_stepper("0.9", "whole.mcap", Some("acceleration"));
    assert_eq!(pack_owned(d, &whole).status.code(), Some(1));
    let whole = read(d, "whole.mcap");
    assert!(whole.run["config"].contains(r#""stepper":"acceleration""#), "{}", whole.run["config"]);

    assert_eq!(pack_owned(d, &with_stepper("0.45", "a.mcap", Some("acceleration"))).status.code(), Some(1));
    let mut other = with_stepper("0.9", "a.mcap", Some("velocity"));
    other.push("--resume".into());
    let err = stderr(&pack_owned(d, &other));
    assert!(err.contains("cannot resume") && err.contains("--stepper acceleration → velocity"), "{err}");

    let mut again = with_stepper("0.9", "a.mcap", None);
    again.push("--resume".into());
    let out = pack_owned(d, &again);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let a = read(d, "a.mcap");
    assert!(a.run["config"].contains(r#""stepper":"acceleration""#), "{}", a.run["config"]);
    assert_eq!(a.frames, whole.frames);
    assert_eq!(a.energy, whole.energy);
}

/// --park writes a small copy of a partial run (one frame, the energy records, the
/// checkpoint) and leaves the run alone; that copy, put under the output's name in another
/// directory, resumes to the uninterrupted run's frames after the checkpoint and its energy
/// records, bit for bit.
#[test]
fn a_parked_run_resumes_elsewhere_exactly() {
    let dir = setup();
    let d = dir.path();
    assert_eq!(pack_owned(d, &resumable("0.9", "whole.mcap")).status.code(), Some(1));
    let whole = read(d, "whole.mcap");
    assert_eq!(pack_owned(d, &resumable("0.45", "p.mcap")).status.code(), Some(1));
    let before = std::fs::read(d.join("p.mcap")).unwrap();

    let mut park = resumable("0.45", "p.mcap");
    park.extend(["--park", "parked.mcap"].map(String::from));
    let out = pack_owned(d, &park);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(String::from_utf8_lossy(&out.stdout).contains("parked the run of p.mcap at its checkpoint t = 0.450 s"));
    assert_eq!(std::fs::read(d.join("p.mcap")).unwrap(), before, "the parked run was changed");
    let parked = read(d, "parked.mcap");
    let source = read(d, "p.mcap");
    assert_eq!(parked.run, source.run);
    assert_eq!(parked.pellet_files, source.pellet_files);
    assert_eq!(parked.checkpoint, source.checkpoint);
    // The run ended at its checkpoint: every energy record is kept.
    assert!(parked.energy == source.energy, "{} of {} energy records", parked.energy.len(), source.energy.len());
    assert_eq!(parked.frames.len(), 1);
    assert!(std::fs::metadata(d.join("parked.mcap")).unwrap().len() < before.len() as u64);

    // Elsewhere: the parked copy under the output's name, the pellet beside it.
    let other = d.join("other");
    std::fs::create_dir(&other).unwrap();
    std::fs::copy(d.join("s.pellet"), other.join("s.pellet")).unwrap();
    std::fs::copy(d.join("parked.mcap"), other.join("p.mcap")).unwrap();
    let mut again = resumable("0.9", "p.mcap");
    again.push("--resume".into());
    let out = pack_owned(&other, &again);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let resumed = read(&other, "p.mcap");
    // The parked frame, then every frame of the uninterrupted run after it.
    let kept = parked.frames[0].time_s;
    let after = |f: &[pellet_io::Frame]| f.iter().filter(|f| f.time_s >= kept).cloned().collect::<Vec<_>>();
    assert!(resumed.frames == after(&whole.frames), "the resumed frames differ from the uninterrupted run's");
    assert!(resumed.frames.len() > 10 && resumed.frames.len() < whole.frames.len());
    assert!(resumed.energy == whole.energy, "the resumed energy records differ from the uninterrupted run's");

    // Nothing to park: a clear one-line error.
    let mut none = resumable("0.45", "none.mcap");
    none.extend(["--park", "x.mcap"].map(String::from));
    let out = pack_owned(d, &none);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("no partial run with a checkpoint to park"), "{}", stderr(&out));
    assert!(!d.join("x.mcap").exists());
}

/// --resume refuses another run's file and a settled run, and starts over when there is
/// nothing to resume.
#[test]
fn resume_refuses_what_it_cannot_continue() {
    let dir = setup();
    let d = dir.path();
    assert_eq!(pack_owned(d, &resumable("0.3", "r.mcap")).status.code(), Some(1));
    let mut other = resumable("0.6", "r.mcap");
    other.extend(["--cor", "0.5", "--resume"].map(String::from));
    let out = pack_owned(d, &other);
    assert_eq!(out.status.code(), Some(2));
    let err = stderr(&out);
    assert!(err.contains("cannot resume") && err.contains("--cor 0.9 → 0.5"), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    // The file is untouched.
    assert!(read(d, "r.mcap").checkpoint.is_some());

    let mut same = resumable("0.3", "r.mcap");
    same.push("--resume".into());
    let err = stderr(&pack_owned(d, &same));
    assert!(err.contains("give a larger --max-time"), "{err}");

    let one = ["--pellet", "s.pellet", "--tube-diameter", "30", "--count", "1", "--quiet", "-o", "one.mcap"];
    assert_eq!(pack(d, &one).status.code(), Some(0));
    let out = pack(d, &[&one[..], &["--resume"]].concat());
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("settled at t = ") && stderr(&out).contains("nothing to resume"), "{}", stderr(&out));

    let mut fresh = resumable("0.3", "new.mcap");
    fresh.push("--resume".into());
    fresh.retain(|a| a != "--quiet");
    let out = pack_owned(d, &fresh);
    assert!(stderr(&out).contains("starting at t = 0"), "{}", stderr(&out));
    assert_eq!(read(d, "new.mcap").frames, read(d, "r.mcap").frames);
}

/// Two packs never write the same output: while one holds `<output>.lock` the other stops
/// before touching anything, and says who holds it. A stale lock file (a killed run's) is no
/// obstacle, and a finished run removes its lock file.
#[test]
fn a_second_pack_on_the_same_output_is_refused() {
    let dir = setup();
    let d = dir.path();
    std::fs::write(d.join("o.mcap.part"), b"another run's partial trajectory").unwrap();
    let held = std::fs::OpenOptions::new().create(true).truncate(true).write(true).open(d.join("o.mcap.lock")).unwrap();
    held.try_lock().unwrap();
    std::fs::write(d.join("o.mcap.lock"), b"4242").unwrap();
    let args = resumable("0.2", "o.mcap");
    let out = pack_owned(d, &[args.clone(), vec!["--resume".into()]].concat());
    assert_eq!(out.status.code(), Some(2));
    let err = stderr(&out);
    assert!(err.contains("another pack (pid 4242) is writing o.mcap") && err.contains("give another -o"), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert_eq!(std::fs::read(d.join("o.mcap.part")).unwrap(), b"another run's partial trajectory");
    assert!(!d.join("o.mcap").exists());

    // Released (as by a killed run): the stale file is locked again, and removed at the end.
    drop(held);
    std::fs::remove_file(d.join("o.mcap.part")).unwrap();
    assert_eq!(pack_owned(d, &args).status.code(), Some(1), "ends at its --max-time");
    assert!(read(d, "o.mcap").checkpoint.is_some());
    assert!(!d.join("o.mcap.lock").exists() && !d.join("o.mcap.part").exists());
}

#[test]
fn the_output_and_park_naming_one_file_are_refused_before_any_work() {
    let dir = setup();
    for park in ["x.mcap", "./x.mcap", "x.mcap.part"] {
        let out = pack(
            dir.path(),
            &["--pellet", "s.pellet", "--tube-diameter", "30", "--count", "3", "-o", "x.mcap", "--park", park],
        );
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{park}: {err}");
        assert!(err.starts_with("pack: error: -o ") && err.contains("give each output its own file"), "{err}");
        assert!(err.contains("--park"), "{err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(!dir.path().join("x.mcap").exists());
    }
}

#[test]
fn a_closed_stdout_is_refused_before_the_run() {
    let dir = setup();
    // `>&-` closes stdout; `Stdio::null()` would be an open one.
    let out = Command::new("sh")
        .args(["-c", r#""$0" "$@" >&-"#, env!("CARGO_BIN_EXE_pack")])
        .args(SHORT)
        .args(["-o", "x.mcap"])
        .current_dir(dir.path())
        .output()
        .expect("run pack through sh");
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert_eq!(err.trim_end(), "pack: error: cannot write to standard output: it is closed; redirect it to a file (or to /dev/null to discard the output)");
    assert!(!dir.path().join("x.mcap").exists());
}

/// Offsets of the top-level chunk records of an MCAP file (after its 8-byte magic).
fn chunk_offsets(bytes: &[u8]) -> Vec<usize> {
    let (mut at, mut out) = (8, Vec::new());
    while at + 9 <= bytes.len() {
        let len = u64::from_le_bytes(bytes[at + 1..at + 9].try_into().unwrap());
        // A chunk being written has the placeholder length u64::MAX.
        let Some(len) = usize::try_from(len).ok().filter(|&l| l <= bytes.len() - at - 9) else { break };
        if bytes[at] == 0x06 {
            out.push(at);
        }
        at += 9 + len;
    }
    out
}

/// A killed run's `.part` with one bad byte in its first chunk: --resume skips that chunk, says
/// so, and goes on from the last checkpoint that reads; the result is the uninterrupted run
/// without the damaged chunk's records. A `.part` none of whose checkpoints reads, or that is
/// no trajectory at all, is refused in one line and left as it was; an empty one (killed as it
/// began) is started over.
#[test]
fn resume_goes_past_a_damaged_chunk_and_keeps_what_it_cannot_read() {
    let dir = setup();
    let d = dir.path();
    assert_eq!(pack_owned(d, &resumable("0.9", "whole.mcap")).status.code(), Some(1));
    let whole = read(d, "whole.mcap");
    let bytes = std::fs::read(d.join("whole.mcap")).unwrap();
    let chunks = chunk_offsets(&bytes);
    assert!(chunks.len() > 5, "{chunks:?}");
    let resume = |output: &str| {
        let mut again = resumable("0.9", output);
        again.push("--resume".into());
        again.retain(|a| a != "--quiet");
        pack_owned(d, &again)
    };

    // Killed at 60 % of its bytes, one byte of the first chunk's compressed data changed.
    let mut part = bytes[..bytes.len() * 6 / 10].to_vec();
    part[chunks[0] + 80] ^= 0x5a;
    std::fs::write(d.join("k.mcap.part"), &part).unwrap();
    let out = resume("k.mcap");
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("pack: warning: k.mcap.part: ") && err.contains("do not read"), "{err}");
    assert!(err.contains("resuming at t = ") && !err.contains("starting at t = 0"), "{err}");
    let k = read(d, "k.mcap");
    let (frame, energy) = (k.frames[0].time_s, k.energy[0].time_s);
    assert!(frame > 0.0 && frame < 0.11 && energy > 0.0 && energy < 0.11, "first frame {frame} s, energy {energy} s");
    let after = |t: f64| whole.frames.iter().filter(|f| f.time_s >= t).cloned().collect::<Vec<_>>();
    assert!(k.frames == after(frame), "the resumed frames differ from the uninterrupted run's");
    let after = |t: f64| whole.energy.iter().filter(|e| e.time_s >= t).cloned().collect::<Vec<_>>();
    assert!(k.energy == after(energy), "the resumed energy records differ from the uninterrupted run's");
    assert!(!d.join("k.mcap.part").exists() && !d.join("k.mcap.resume").exists());

    // The damaged chunk (its zstd frame's magic changed) held the only complete checkpoint.
    let mut part = bytes[..chunks[1] + 100].to_vec();
    part[chunks[0] + 9 + 44] ^= 0x5a;
    let not_mcap = b"not a trajectory at all".to_vec();
    for (name, kept) in [("n.mcap.part", part), ("x.mcap.part", not_mcap)] {
        std::fs::write(d.join(name), &kept).unwrap();
        let output = name.trim_end_matches(".part");
        let out = resume(output);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(err.starts_with(&format!("pack: error: cannot resume: {name}: ")), "{err}");
        assert!(err.contains("remove or rename it, or give another -o"), "{err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert_eq!(std::fs::read(d.join(name)).unwrap(), kept, "{name} was changed");
        assert!(!d.join(output).exists() && !d.join(format!("{output}.resume")).exists());
    }

    // Killed as it began, before its first bytes left the buffer: nothing to keep.
    std::fs::write(d.join("e.mcap.part"), b"").unwrap();
    let out = resume("e.mcap");
    assert!(stderr(&out).contains("starting at t = 0"), "{}", stderr(&out));
    assert!(read(d, "e.mcap").frames == whole.frames);
}

/// Twenty spheres fed one by one, checkpoints every 0.1 s: long enough to be stopped mid-run.
fn interruptible(max_time: &str, output: &str) -> Vec<String> {
    let mut a = resumable(max_time, output);
    let count = a.iter().position(|s| s == "--count").unwrap();
    a[count + 1] = "20".into();
    a
}

/// SIGTERM closes the run under its final name and says how to go on; the same pack without
/// --resume refuses to start over it and keeps it; with --resume it goes on to the
/// uninterrupted run's trajectory, every frame and energy record equal.
#[test]
fn an_interrupted_run_is_kept_and_resumed_exactly() {
    let dir = setup();
    let d = dir.path();
    let child = Command::new(env!("CARGO_BIN_EXE_pack"))
        .args(interruptible("60", "i.mcap"))
        .current_dir(d)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("run pack");
    // Stopped once its first checkpoint's chunk is on disk: the run is under way, its signal
    // handler set.
    let start = std::time::Instant::now();
    while std::fs::read(d.join("i.mcap.part")).map_or(true, |b| chunk_offsets(&b).is_empty()) {
        assert!(start.elapsed().as_secs() < 60, "pack wrote no chunk");
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    assert!(Command::new("kill").args(["-TERM", &child.id().to_string()]).status().unwrap().success());
    let out = child.wait_with_output().unwrap();
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("interrupted at t = ") && err.contains("the same command with --resume continues it"),
        "{err}"
    );
    let stopped = read(d, "i.mcap");
    let t = stopped.energy.last().unwrap().time_s;
    let kept = std::fs::read(d.join("i.mcap")).unwrap();

    let out = pack_owned(d, &interruptible("60", "i.mcap"));
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.starts_with(&format!("pack: error: i.mcap holds a run interrupted at t = {t:.3} s; add --resume")),
        "{err}"
    );
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(std::fs::read(d.join("i.mcap")).unwrap() == kept, "the interrupted run was changed");

    let limit = format!("{:.3}", t + 0.2);
    let mut again = interruptible(&limit, "i.mcap");
    again.push("--resume".into());
    let out = pack_owned(d, &again);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert_eq!(pack_owned(d, &interruptible(&limit, "s.mcap")).status.code(), Some(1));
    let (resumed, straight) = (read(d, "i.mcap"), read(d, "s.mcap"));
    assert!(resumed.frames == straight.frames, "the resumed frames differ from the uninterrupted run's");
    assert!(resumed.energy == straight.energy, "the resumed energy records differ from the uninterrupted run's");
    assert!(resumed.frames.last().unwrap().time_s > t);
}

/// A mistake in a case file is one line: the file and line, the key, the value given (clipped)
/// and what the key takes, alike for TOML and JSON; the run does not start.
#[test]
fn case_file_mistakes_name_the_key_the_value_and_what_it_takes() {
    let dir = tempfile::tempdir().unwrap();
    let huge = "y".repeat(20 << 20);
    let cases: &[(&str, &str, &str)] = &[
        ("count", "-1", "expected a whole number from 1 to 1000000"),
        ("count", "{}", "expected a whole number from 1 to 1000000"),
        ("scheme", "3", "expected one of one-column, two-columns, four-columns, sock, dense, batch"),
        ("max-time", "0", "expected a number in s above 0 and at most 1000000"),
        ("angle-jitter", "181", "expected a number in degrees from 0 to 180"),
        ("stepper", &format!("\"{huge}\""), "expected one of acceleration, velocity"),
    ];
    for (key, value, wanted) in cases {
        let shown: String = value.chars().take(40).collect();
        let shown = if value.chars().count() > 40 { format!("{shown}…") } else { shown };
        for (file, text) in [
            ("c.toml", format!("pellet = \"s.pellet\"\n{key} = {value}\n")),
            ("c.json", format!("{{\"pellet\": \"s.pellet\",\n \"{key}\": {value}}}")),
        ] {
            std::fs::write(dir.path().join(file), text).unwrap();
            let out = pack(dir.path(), &["--case", file, "--tube-diameter", "30", "-o", "x.mcap"]);
            let err = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(2), "{err}");
            let line = format!("pack: error: {file}:2: invalid value `{shown}` for {key}: {wanted}\n");
            assert_eq!(err, line);
        }
    }
    // A table under a key, its header's line.
    std::fs::write(dir.path().join("t.toml"), "pellet = \"s.pellet\"\n[count]\nn = 3\n").unwrap();
    let out = pack(dir.path(), &["--case", "t.toml", "-o", "x.mcap"]);
    assert_eq!(
        String::from_utf8_lossy(&out.stderr),
        "pack: error: t.toml:2: invalid value `{ n = 3 }` for count: expected a whole number from 1 to 1000000\n"
    );
    assert!(!dir.path().join("x.mcap").exists());
}
