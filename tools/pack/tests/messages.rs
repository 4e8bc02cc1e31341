//! `pack`'s messages: one line that names the tool, what is wrong in the user's terms and the fix.

use std::process::{Command, Output};

fn pack(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pack")).args(args).output().expect("run pack")
}

/// Exit 2 and one line, `pack: error: …`; the line.
fn usage_error(args: &[&str]) -> String {
    let out = pack(args);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.starts_with("pack: error: ") && err.trim_end().ends_with("(see pack --help)"), "{err}");
    err.trim_end().to_string()
}

#[test]
fn usage_errors_are_one_line_with_the_flag_and_what_it_takes() {
    assert_eq!(
        usage_error(&["--stepper", "Velocity"]),
        "pack: error: invalid value 'Velocity' for --stepper: expected one of acceleration, velocity \
         (did you mean 'velocity'?) (see pack --help)"
    );
    for seed in ["-1", "18446744073709551616", "x"] {
        let err = usage_error(&["--seed", seed]);
        let wanted =
            format!("invalid value '{seed}' for --seed: expected a whole number from 0 to 18446744073709551615");
        assert!(err.contains(&wanted), "{err}");
    }
    let err = usage_error(&["--resume", "--park", "p.mcap"]);
    assert!(
        err.contains("--resume cannot be used with --park") || err.contains("--park cannot be used with --resume"),
        "{err}"
    );
    assert!(usage_error(&["--nope"]).contains("unknown flag '--nope'"));
    assert!(usage_error(&["--pellet"]).contains("--pellet needs a value"));
}

#[test]
fn a_huge_argument_is_not_echoed_whole() {
    let huge = format!("--{}", "x".repeat(100_000));
    let err = usage_error(&[&huge]);
    assert!(err.len() < 200 && err.contains("xxx…'"), "{err}");
}

#[test]
fn help_and_version_still_print_to_stdout_and_exit_0() {
    for flag in ["--help", "--version"] {
        let out = pack(&[flag]);
        assert_eq!(out.status.code(), Some(0));
        assert!(out.stderr.is_empty() && !out.stdout.is_empty());
    }
    assert!(String::from_utf8_lossy(&pack(&["--help"]).stdout).contains("Usage: pack"));
}

/// A run that reaches --max-time while pellets are still entering says so, and how to go on.
#[test]
fn a_run_stopped_while_loading_says_what_that_means() {
    let dir = tempfile::tempdir().unwrap();
    let mkpellet = std::path::Path::new(env!("CARGO_BIN_EXE_pack")).with_file_name("mkpellet");
    assert!(mkpellet.exists(), "build the workspace binaries first (make test does)");
    let made = Command::new(mkpellet)
        .args(["sphere", "--diameter", "10", "--faces", "500", "-o", "s.pellet"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert_eq!(made.status.code(), Some(0));
    let args = ["--pellet", "s.pellet", "--tube-diameter", "30", "--count", "6", "--spacing", "0.05"];
    let out = Command::new(env!("CARGO_BIN_EXE_pack"))
        .args(args)
        .args(["--max-time", "0.1", "--quiet", "-o", "x.mcap"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("the run stopped while pellets were still entering") && err.contains("--resume"), "{err}");
    assert!(!err.contains("energy history"), "{err}");
}
