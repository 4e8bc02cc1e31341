//! The contract every packbed tool follows, implemented once.
//!
//! | exit code | meaning |
//! |---|---|
//! | 0 | success, or the check passed |
//! | 1 | the check answered "no" (e.g. `settle-check`: not settled) |
//! | 2 | any error, including usage errors |
//!
//! Errors are printed once, here, as `tool: error: message` on one line
//! (causes joined with `: `). A reader of stdout that went away (broken pipe)
//! ends the tool quietly with exit 0; any other failure to write stdout (a full
//! disk, or a stdout closed when the tool started: `tool >&-`) is an error.
//! Results go to stdout ([`print_stdout`]); diagnostics and progress to stderr.
//! Two outputs naming the same file, or an output naming an input, are refused
//! before any work ([`refuse_clashing_outputs`]).
#![deny(missing_docs)]

use std::io::Write;
use std::process::ExitCode;

mod same_file;
mod usage;

pub use same_file::{refuse_clashing_outputs, refuse_overwriting_inputs};
pub use usage::{capped, usage_line, ECHO_LIMIT};

use clap::Parser;

/// What a tool's `run` reports on success.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// Done, or the check passed: exit 0.
    Success,
    /// The check answered "no": exit 1.
    CheckFailed,
}

/// Exit code for errors.
pub const EXIT_ERROR: u8 = 2;

/// The source this binary was built from: `git <commit>` (`-dirty` when files under `crates/`,
/// `tools/` or the workspace manifests differed from it), or `unknown (…)` outside a git
/// checkout. Set by the build script.
pub const BUILD: &str = env!("PACKBED_BUILD");

/// `--version`'s text: the package version and [`BUILD`].
pub const LONG_VERSION: &str = concat!(env!("CARGO_PKG_VERSION"), " (", env!("PACKBED_BUILD"), ")");

/// Parses the arguments, runs the tool and turns the result into an exit code.
pub fn main<A: Parser>(tool: &str, run: impl FnOnce(A) -> anyhow::Result<Outcome>) -> ExitCode {
    let args = match A::try_parse() {
        Ok(a) => a,
        Err(e) => {
            // --help and --version are successes, unless their text could not be written;
            // usage errors exit 2, on one line as every other error.
            if e.use_stderr() {
                eprintln!("{tool}: error: {}", usage_line(&A::command(), &e));
                return ExitCode::from(EXIT_ERROR);
            }
            if let Err(closed) = pellet_io::require_stdout() {
                eprintln!("{tool}: error: {closed}");
                return ExitCode::from(EXIT_ERROR);
            }
            let printed = e.print().and_then(|()| std::io::stdout().flush());
            return match printed {
                Err(io) if io.kind() != std::io::ErrorKind::BrokenPipe => {
                    eprintln!("{tool}: error: {}", one_line(&stdout_error(io)));
                    ExitCode::from(EXIT_ERROR)
                }
                _ => ExitCode::SUCCESS,
            };
        }
    };
    match run(args) {
        Ok(Outcome::Success) => ExitCode::SUCCESS,
        Ok(Outcome::CheckFailed) => ExitCode::from(1),
        Err(e) if is_broken_pipe(&e) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("{tool}: error: {}", one_line(&e));
            ExitCode::from(EXIT_ERROR)
        }
    }
}

/// The error and its causes on one line, `outer: cause: cause`. A cause whose text the message
/// before it already ends with is left out: errors that show their source in their own message
/// (`path: reason`, with the reason also as the source) printed it twice.
pub fn one_line(e: &anyhow::Error) -> String {
    let mut line = String::new();
    // Where the last message starts: a cause that begins with it (a context that is just the
    // path, over an error that starts with the path) replaces it.
    let mut last = 0;
    for cause in e.chain() {
        let text = match cause.downcast_ref::<std::io::Error>() {
            Some(io) => pellet_io::plain_reason(io),
            None => cause.to_string(),
        };
        let text = text.replace('\n', " ");
        if line.ends_with(&text) {
            continue;
        }
        if !line.is_empty() && text.starts_with(&line[last..]) {
            line.truncate(last);
        } else if !line.is_empty() {
            line.push_str(": ");
        }
        last = line.len();
        line.push_str(&text);
    }
    line
}

/// Writes a tool's text result to stdout and flushes it. Unlike `print!`, which panics, a
/// failed write is returned as an error for [`main`] to report (a broken pipe ends quietly),
/// and so is a stdout that was closed at start, where the text would vanish.
pub fn print_stdout(text: &str) -> anyhow::Result<()> {
    pellet_io::require_stdout()?;
    let mut out = std::io::stdout().lock();
    out.write_all(text.as_bytes()).and_then(|()| out.flush()).map_err(stdout_error)
}

fn stdout_error(e: std::io::Error) -> anyhow::Error {
    anyhow::Error::new(e).context("cannot write the result to stdout (redirect it to a file with space, or pipe it on)")
}

fn is_broken_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.downcast_ref::<std::io::Error>().is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
            || c.to_string().contains("Broken pipe")
    })
}

/// Creates the output directory `dir` given by `flag`, and its parents. A file in its way is
/// said so: the OS's own "File exists" reads as if the directory were there.
pub fn create_output_dir(flag: &str, dir: &std::path::Path) -> anyhow::Result<()> {
    use std::io::ErrorKind as K;
    match std::fs::create_dir_all(dir) {
        Ok(()) => Ok(()),
        Err(e) if matches!(e.kind(), K::AlreadyExists | K::NotADirectory) => anyhow::bail!(
            "{flag} {}: a file is in the way of this directory; remove it or give another {flag}",
            dir.display()
        ),
        Err(e) => Err(anyhow::Error::new(e).context(format!("{flag} {}: cannot create the directory", dir.display()))),
    }
}

/// A number as messages show it (scientific when huge or tiny, not three hundred digits).
pub use pellet_geom::math::shown;

/// Checks a length flag in mm: finite and > 0. The error names the flag.
pub fn positive_mm(flag: &str, value: f64) -> anyhow::Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        anyhow::bail!("{flag} must be a finite number > 0 mm (got {})", shown(value))
    }
}

/// Checks a length flag in mm against its range (lo, hi] (lo = 0 is allowed where `lo_closed`).
/// `why` says where the bounds come from (say "(dp / 50 to dp / 2 for these pellets)"), so the
/// error gives the range in the user's numbers.
pub fn mm_in_range(flag: &str, value: f64, lo: f64, hi: f64, lo_closed: bool, why: &str) -> anyhow::Result<f64> {
    let above = if lo_closed { value >= lo } else { value > lo };
    if value.is_finite() && above && value <= hi {
        Ok(value)
    } else {
        let open = if lo_closed { "[" } else { "(" };
        // The bounds to a micrometre (dp / 50 is 0.19634954… mm for some pellets).
        let bound = |x: f64| shown(if x.abs() >= 1e-3 { (x * 1e3).round() / 1e3 } else { x });
        anyhow::bail!("{flag} must be in {open}{}, {}] mm{why} (got {})", bound(lo), bound(hi), shown(value))
    }
}

/// Parses `--window z0,z1` (mm) into metres; z1 > z0. Shared by the tools that
/// cut the bed to an axial window.
pub fn parse_window(text: &str) -> anyhow::Result<(f64, f64)> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let [a, b] = parts.as_slice() else {
        anyhow::bail!("--window must be z0,z1 in mm, e.g. --window 0,100 (got {text:?})");
    };
    let parse = |s: &str| s.parse::<f64>().ok().filter(|v| v.is_finite());
    match (parse(a), parse(b)) {
        (Some(z0), Some(z1)) if z1 > z0 => Ok((z0 * 1e-3, z1 * 1e-3)),
        (Some(_), Some(_)) => anyhow::bail!("--window z0,z1 needs z1 > z0 (got {text:?})"),
        _ => anyhow::bail!("--window must be two finite numbers z0,z1 in mm (got {text:?})"),
    }
}

#[cfg(test)]
mod tests {
    use super::one_line;

    /// An error that shows its source in its own message, as `path: reason` does.
    #[derive(Debug)]
    struct WithPath(std::io::Error);

    impl std::fmt::Display for WithPath {
        fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            write!(f, "bed.pellet: {}", self.0)
        }
    }

    impl std::error::Error for WithPath {
        fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
            Some(&self.0)
        }
    }

    #[test]
    fn a_cause_already_in_the_message_is_not_repeated() {
        let io = std::io::Error::new(std::io::ErrorKind::NotFound, "No such file or directory");
        let e = anyhow::Error::new(WithPath(io)).context("reading the pellet");
        assert_eq!(one_line(&e), "reading the pellet: bed.pellet: No such file or directory");
    }

    #[test]
    fn a_context_that_the_cause_starts_with_is_not_repeated() {
        let e = anyhow::anyhow!("x.jpg: unknown image type").context("x.jpg").context("plotting");
        assert_eq!(one_line(&e), "plotting: x.jpg: unknown image type");
    }

    #[test]
    fn a_file_in_the_way_of_an_output_directory_is_named() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("out");
        std::fs::write(&file, b"").unwrap();
        for target in [file.clone(), file.join("sub")] {
            let e = super::create_output_dir("-o", &target).unwrap_err().to_string();
            assert!(e.ends_with("a file is in the way of this directory; remove it or give another -o"), "{e}");
        }
        super::create_output_dir("-o", &dir.path().join("a/b")).unwrap();
        assert!(dir.path().join("a/b").is_dir());
    }

    #[test]
    fn os_errors_are_in_plain_words() {
        let e = anyhow::Error::new(std::io::Error::from_raw_os_error(21)).context("bed.stl");
        assert_eq!(one_line(&e), "bed.stl: is a directory, not a file; give a file name");
    }

    #[test]
    fn causes_are_joined_on_one_line() {
        let e = anyhow::anyhow!("line one\nline two").context("outer");
        assert_eq!(one_line(&e), "outer: line one line two");
    }
}
