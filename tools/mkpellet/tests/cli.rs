//! Process-boundary tests of `mkpellet`: exit codes, one-line errors, no partial output.

use std::path::Path;
use std::process::{Command, Output};

fn mkpellet(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mkpellet")).args(args).current_dir(dir).output().expect("run mkpellet")
}

#[track_caller]
fn assert_error(out: &Output, needle: &str) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "stderr: {err}");
    assert!(err.starts_with("mkpellet: error: "), "{err}");
    assert!(err.contains(needle), "stderr lacks {needle:?}: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "not one line: {err}");
}

fn files_in(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> =
        std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    v.sort();
    v
}

#[test]
fn bad_sizes_exit_2_with_one_line_naming_the_flag_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let cases: &[(&[&str], &str)] = &[
        (&["sphere", "--diameter", "-1"], "--diameter must be a finite number > 0 mm (got -1)"),
        (&["sphere", "--diameter", "0"], "--diameter"),
        (&["sphere", "--diameter", "nan"], "--diameter"),
        (&["sphere", "--diameter", "inf"], "--diameter"),
        (&["cylinder", "--diameter", "10", "--height", "-3"], "--height"),
        (&["ring", "--outer-diameter", "10", "--wall", "5", "--height", "10"], "--wall must be less than half"),
        (
            &["ring", "--outer-diameter", "10", "--inner-diameter", "11", "--height", "10"],
            "--inner-diameter must be smaller",
        ),
        (&["trilobe", "--lobe-diameter", "1", "--size", "5", "--height", "5"], "--size must lie between"),
        (
            &[
                "multihole",
                "--diameter",
                "10",
                "--height",
                "10",
                "--holes",
                "4",
                "--hole-diameter",
                "4",
                "--pitch-diameter",
                "5",
            ],
            "holes do not fit",
        ),
        (
            &[
                "multihole",
                "--diameter",
                "10",
                "--height",
                "10",
                "--holes",
                "4",
                "--hole-diameter",
                "2",
                "--pitch-diameter",
                "9",
            ],
            "holes do not fit",
        ),
        (&["sphere", "--diameter", "10", "--level", "9"], "--level must be 0 to 6"),
    ];
    for (args, needle) in cases {
        let mut all: Vec<&str> = args.to_vec();
        all.extend(["-o", "out.pellet", "--stl", "out.stl"]);
        assert_error(&mkpellet(dir.path(), &all), needle);
    }
    assert!(files_in(dir.path()).is_empty(), "partial output left: {:?}", files_in(dir.path()));
}

#[test]
fn usage_errors_exit_2_and_help_shows_examples() {
    let dir = tempfile::tempdir().unwrap();
    let out = mkpellet(dir.path(), &["cylinder", "--diameter", "10"]);
    assert_error(&out, "missing --height (see mkpellet cylinder --help)");
    assert_error(&mkpellet(dir.path(), &["cylindr"]), "unknown subcommand 'cylindr' (did you mean 'cylinder'?)");
    assert_error(&mkpellet(dir.path(), &[]), "give a subcommand: one of sphere, cylinder, ring");
    let help = mkpellet(dir.path(), &["--help"]);
    assert_eq!(help.status.code(), Some(0));
    let text = String::from_utf8_lossy(&help.stdout);
    assert!(text.contains("mkpellet cylinder --diameter 10 --height 10"));
    for sub in ["sphere", "cylinder", "ring", "trilobe", "quadrilobe", "multihole", "import", "info"] {
        let h = mkpellet(dir.path(), &[sub, "--help"]);
        let t = String::from_utf8_lossy(&h.stdout);
        assert!(t.contains("Example"), "{sub} --help has no example");
    }
    let ring = String::from_utf8_lossy(&mkpellet(dir.path(), &["ring", "--help"]).stdout).into_owned();
    assert!(ring.contains("(mm)"), "units in help");
}

#[test]
fn open_and_inconsistent_meshes_are_rejected() {
    let dir = tempfile::tempdir().unwrap();
    // A tetrahedron missing one face: open.
    let open = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\n";
    std::fs::write(dir.path().join("open.obj"), open).unwrap();
    assert_error(&mkpellet(dir.path(), &["import", "open.obj", "-o", "x.pellet"]), "not closed");
    // A tetrahedron with one face flipped: inconsistent orientation.
    let flipped = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 3 4\n";
    std::fs::write(dir.path().join("flipped.obj"), flipped).unwrap();
    assert_error(&mkpellet(dir.path(), &["import", "flipped.obj", "-o", "x.pellet"]), "orient");
    std::fs::write(dir.path().join("junk.stl"), b"solid junk\nthis is not stl\n").unwrap();
    assert_error(&mkpellet(dir.path(), &["import", "junk.stl", "-o", "x.pellet"]), "junk.stl");
    assert_error(&mkpellet(dir.path(), &["import", "missing.stl", "-o", "x.pellet"]), "missing.stl");
    assert_error(&mkpellet(dir.path(), &["import", "mesh.ply", "-o", "x.pellet"]), "unknown mesh format");
    assert!(!dir.path().join("x.pellet").exists());
    // A closed, outward tetrahedron in metres is accepted and re-centred.
    let good = "v 0 0 0\nv 0.01 0 0\nv 0 0.01 0\nv 0 0 0.01\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n";
    std::fs::write(dir.path().join("tet.obj"), good).unwrap();
    let out = mkpellet(dir.path(), &["import", "tet.obj", "--unit", "m", "-o", "tet.pellet"]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let info = mkpellet(dir.path(), &["info", "tet.pellet", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&info.stdout).unwrap();
    assert!((v["volume_mm3"].as_f64().unwrap() - 1000.0 / 6.0).abs() < 1e-6);
    assert!(v["centroid_mm"][0].as_f64().unwrap().abs() < 1e-9);
}

#[test]
fn info_rejects_files_that_are_not_pellets() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("text.pellet"), b"hello world, not a pellet").unwrap();
    assert_error(&mkpellet(dir.path(), &["info", "text.pellet"]), "not a packbed pellet file");
    let good = mkpellet(dir.path(), &["sphere", "--diameter", "5", "-o", "s.pellet"]);
    assert_eq!(good.status.code(), Some(0));
    let bytes = std::fs::read(dir.path().join("s.pellet")).unwrap();
    std::fs::write(dir.path().join("cut.pellet"), &bytes[..bytes.len() / 2]).unwrap();
    assert_error(&mkpellet(dir.path(), &["info", "cut.pellet"]), "is truncated (its data ends early)");
    let mut future = bytes.clone();
    future[8] = 99;
    std::fs::write(dir.path().join("future.pellet"), &future).unwrap();
    assert_error(&mkpellet(dir.path(), &["info", "future.pellet"]), "format version 99");
    assert_error(&mkpellet(dir.path(), &["info", "nope.pellet"]), "nope.pellet");
}

/// Runs mkpellet with its stdout closed, as `mkpellet … >&-` does; `Stdio::null()` would be
/// an open stdout.
fn mkpellet_stdout_closed(dir: &Path, args: &[&str]) -> Output {
    Command::new("sh")
        .args(["-c", r#""$0" "$@" >&-"#, env!("CARGO_BIN_EXE_mkpellet")])
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run mkpellet through sh")
}

#[test]
fn two_outputs_naming_one_file_are_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    assert_eq!(
        mkpellet(dir.path(), &["sphere", "--diameter", "10", "-o", "in.pellet", "--stl", "in.stl"]).status.code(),
        Some(0)
    );
    std::fs::create_dir(dir.path().join("sub")).unwrap();
    std::os::unix::fs::symlink("in.stl", dir.path().join("link.stl")).unwrap();
    let before = files_in(dir.path());
    let sphere = ["sphere", "--diameter", "10"];
    let cases: &[(&[&str], &[&str], &str)] = &[
        (
            &sphere,
            &["-o", "s.pellet", "--stl", "s.pellet"],
            "-o and --stl both name s.pellet; give each output its own file",
        ),
        (&sphere, &["-o", "s.pellet", "--obj", "./s.pellet"], "-o s.pellet and --obj ./s.pellet are the same file"),
        (&sphere, &["-o", "s.pellet", "--stl", "sub/../x", "--obj", "x"], "--stl sub/../x and --obj x"),
        (&sphere, &["--stl", "-"], "-o and --stl both name - (stdout)"),
        (&["import", "in.stl", "-o", "x"], &["--obj", "x"], "-o and --obj both name x"),
        (&["info", "in.pellet"], &["--stl", "x", "--obj", "x"], "--stl and --obj both name x"),
        (&["info", "in.pellet"], &["--stl", "in.stl", "--obj", "link.stl"], "--stl in.stl and --obj link.stl"),
    ];
    for (command, flags, needle) in cases {
        let args: Vec<&str> = command.iter().chain(flags.iter()).copied().collect();
        let out = mkpellet(dir.path(), &args);
        assert_error(&out, needle);
        assert!(out.stdout.is_empty(), "{args:?}: something was written to stdout");
        assert_eq!(files_in(dir.path()), before, "{args:?}");
    }
}

#[test]
fn a_closed_stdout_is_an_error_not_a_silent_success() {
    let dir = tempfile::tempdir().unwrap();
    let out = mkpellet_stdout_closed(dir.path(), &["sphere", "--diameter", "10", "--stl", "s.stl"]);
    assert_error(&out, "cannot write to standard output: it is closed");
    assert!(files_in(dir.path()).is_empty(), "the --stl file was written without the pellet file");
    assert_eq!(
        mkpellet_stdout_closed(dir.path(), &["sphere", "--diameter", "10", "-o", "s.pellet"]).status.code(),
        Some(0)
    );
    assert_error(&mkpellet_stdout_closed(dir.path(), &["info", "s.pellet"]), "standard output: it is closed");
    assert_error(&mkpellet_stdout_closed(dir.path(), &["--help"]), "standard output: it is closed");
}

/// Damaged inputs of both readers `mkpellet` has (meshes for `import`, pellet files for
/// `info`): exit 2, one line, nothing written, the input left as it was.
#[test]
fn damaged_meshes_and_pellets_are_one_line_errors_and_left_unchanged() {
    let dir = tempfile::tempdir().unwrap();
    let mut lying = vec![0u8; 84 + 50];
    lying[80..84].copy_from_slice(&1000u32.to_le_bytes());
    let good = mkpellet(dir.path(), &["sphere", "--diameter", "5", "-o", "s.pellet"]);
    assert_eq!(good.status.code(), Some(0));
    let mut flipped = std::fs::read(dir.path().join("s.pellet")).unwrap();
    let mid = flipped.len() / 2;
    flipped[mid] ^= 0x40;
    let cases: &[(&str, &[u8], &str)] = &[
        ("lying.stl", &lying, "its header counts 1000 triangles"),
        ("empty.stl", b"", "a binary STL is truncated: 0 bytes"),
        ("short.stl", b"solid t\nfacet normal 0 0 1\nouter loop\nvertex 1 2\n", "line 4: `vertex` must be followed"),
        ("nan.obj", b"v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n", "not a finite number"),
        ("past.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", "unreadable OBJ"),
        ("flipped.pellet", &flipped, "checksum does not match"),
    ];
    for (name, bytes, needle) in cases {
        std::fs::write(dir.path().join(name), bytes).unwrap();
        let args: &[&str] =
            if name.ends_with(".pellet") { &["info", name] } else { &["import", name, "-o", "x.pellet"] };
        assert_error(&mkpellet(dir.path(), args), needle);
        assert_eq!(&std::fs::read(dir.path().join(name)).unwrap(), bytes, "{name} was changed");
        assert!(!dir.path().join("x.pellet").exists(), "{name}: an output was written");
    }
}

/// An output that cannot be written is said in plain words about the user's path: no OS error
/// number, no temporary file's name.
#[test]
fn an_output_that_is_a_directory_is_said_so_plainly() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("d")).unwrap();
    let out = mkpellet(dir.path(), &["sphere", "--diameter", "10", "-o", "d"]);
    assert_error(&out, "mkpellet: error: d: is a directory, not a file; give a file name");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("os error") && !err.contains(".packbed-"), "{err}");
    assert!(files_in(&dir.path().join("d")).is_empty(), "a temporary file was left");
}
