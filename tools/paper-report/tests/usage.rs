//! `paper-report`'s usage errors: one line that names the tool, the flag and what it takes.

use std::process::Command;

#[test]
fn usage_errors_are_one_line_with_the_flag_and_what_it_takes() {
    let run = |args: &[&str]| Command::new(env!("CARGO_BIN_EXE_paper-report")).args(args).output().expect("run");
    let out = run(&["--table", "t.csv", "--runs", "r", "-o", "o", "--repeats", "-2"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.starts_with("paper-report: error: ") && err.contains("(see paper-report --help)"), "{err}");
    let help = run(&["--help"]);
    assert_eq!(help.status.code(), Some(0));
    assert!(String::from_utf8_lossy(&help.stdout).contains("Usage: paper-report"));
}
