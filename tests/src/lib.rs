//! The harness for end-to-end tests: a scratch directory and the real
//! packbed binaries, run as a user would run them.
//!
//! Binaries are looked up next to the test executable's directory
//! (`target/<profile>/`), which `cargo build --workspace --bins` fills;
//! `make test` builds them first.
#![deny(missing_docs)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

/// A scratch directory in which tools are run.
pub struct Scenario {
    dir: tempfile::TempDir,
}

/// The result of one tool run, with chainable assertions.
pub struct Run {
    /// What was run, for failure messages.
    pub command: String,
    /// The process output.
    pub output: Output,
}

/// Path of a workspace binary built for the same profile as the tests.
pub fn bin(name: &str) -> PathBuf {
    let exe = std::env::current_exe().expect("test executable path");
    // target/<profile>/deps/<test> → target/<profile>/<name>
    let dir = exe.parent().and_then(Path::parent).expect("target/<profile> directory");
    let path = dir.join(name);
    assert!(
        path.exists(),
        "{} is missing: run `cargo build --workspace --bins` (or `make test`) first",
        path.display()
    );
    path
}

impl Scenario {
    /// A fresh, empty scratch directory.
    pub fn new() -> Self {
        Scenario { dir: tempfile::tempdir().expect("temporary directory") }
    }

    /// The scratch directory.
    pub fn path(&self) -> &Path {
        self.dir.path()
    }

    /// A path inside the scratch directory.
    pub fn file(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }

    /// Runs a packbed tool in the scratch directory with the given arguments.
    pub fn run(&self, tool: &str, args: &[&str]) -> Run {
        self.run_with_stdin(tool, args, None)
    }

    /// Runs a tool with its stdout sent to `stdout` (e.g. `/dev/full`) instead of captured.
    pub fn run_with_stdout(&self, tool: &str, args: &[&str], stdout: Stdio) -> Run {
        let output = Command::new(bin(tool))
            .args(args)
            .current_dir(self.path())
            .stdin(Stdio::null())
            .stdout(stdout)
            .stderr(Stdio::piped())
            .output()
            .expect("run tool");
        Run { command: format!("{tool} {}", args.join(" ")), output }
    }

    /// Runs a tool feeding `stdin` to it.
    pub fn run_with_stdin(&self, tool: &str, args: &[&str], stdin: Option<&[u8]>) -> Run {
        use std::io::Write;
        let mut cmd = Command::new(bin(tool));
        cmd.args(args).current_dir(self.path()).stdout(Stdio::piped()).stderr(Stdio::piped());
        cmd.stdin(if stdin.is_some() { Stdio::piped() } else { Stdio::null() });
        let mut child = cmd.spawn().expect("spawn tool");
        if let Some(data) = stdin {
            child.stdin.take().expect("stdin").write_all(data).expect("write stdin");
        }
        let output = child.wait_with_output().expect("wait for tool");
        Run { command: format!("{tool} {}", args.join(" ")), output }
    }
}

impl Default for Scenario {
    fn default() -> Self {
        Self::new()
    }
}

impl Run {
    /// Stdout as text.
    pub fn stdout(&self) -> String {
        String::from_utf8_lossy(&self.output.stdout).into_owned()
    }

    /// Stderr as text.
    pub fn stderr(&self) -> String {
        String::from_utf8_lossy(&self.output.stderr).into_owned()
    }

    /// Asserts the exit code.
    #[track_caller]
    pub fn code(&self, expected: i32) -> &Self {
        assert_eq!(
            self.output.status.code(),
            Some(expected),
            "`{}` exited {:?}, expected {expected}\n--- stdout\n{}\n--- stderr\n{}",
            self.command,
            self.output.status.code(),
            self.stdout(),
            self.stderr()
        );
        self
    }

    /// Asserts success (exit 0).
    #[track_caller]
    pub fn success(&self) -> &Self {
        self.code(0)
    }

    /// Asserts a single-line error on stderr containing `needle`, and exit 2.
    #[track_caller]
    pub fn fails_with(&self, needle: &str) -> &Self {
        self.code(2);
        let err = self.stderr();
        assert!(err.contains(needle), "`{}`: stderr lacks {needle:?}:\n{err}", self.command);
        assert_eq!(err.trim_end().lines().count(), 1, "`{}`: error is not one line:\n{err}", self.command);
        assert!(!err.contains("panicked"), "`{}` panicked:\n{err}", self.command);
        self
    }

    /// Asserts stdout contains `needle`.
    #[track_caller]
    pub fn stdout_has(&self, needle: &str) -> &Self {
        assert!(self.stdout().contains(needle), "`{}`: stdout lacks {needle:?}:\n{}", self.command, self.stdout());
        self
    }
}
