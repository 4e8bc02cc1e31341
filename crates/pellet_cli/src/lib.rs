//! The contract every packbed tool follows, implemented once.
//!
//! | exit code | meaning |
//! |---|---|
//! | 0 | success, or the check passed |
//! | 1 | the check answered "no" (e.g. `settle-check`: not settled) |
//! | 2 | any error, including usage errors |
//!
//! Errors are printed once, here, as `tool: error: message` on one line
//! (causes joined with `: `). A closed stdout (broken pipe) ends the tool
//! quietly with exit 0. Results go to stdout; diagnostics and progress to stderr.
#![deny(missing_docs)]

use std::process::ExitCode;

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

/// Parses the arguments, runs the tool and turns the result into an exit code.
pub fn main<A: Parser>(tool: &str, run: impl FnOnce(A) -> anyhow::Result<Outcome>) -> ExitCode {
    let args = match A::try_parse() {
        Ok(a) => a,
        Err(e) => {
            // --help and --version are successes; usage errors exit 2.
            let _ = e.print();
            return if e.use_stderr() { ExitCode::from(EXIT_ERROR) } else { ExitCode::SUCCESS };
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

/// The error and its causes on one line.
pub fn one_line(e: &anyhow::Error) -> String {
    format!("{e:#}").replace('\n', " ")
}

fn is_broken_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.downcast_ref::<std::io::Error>().is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
            || c.to_string().contains("Broken pipe")
    })
}

/// Checks a length flag in mm: finite and > 0. The error names the flag.
pub fn positive_mm(flag: &str, value: f64) -> anyhow::Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        anyhow::bail!("{flag} must be a finite number > 0 mm (got {value})")
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
