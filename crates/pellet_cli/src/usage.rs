//! clap's usage errors as one line in the user's terms: what was given, for which flag, and
//! what is allowed. clap's own text spans 3-6 lines, lacks the tool's name, and echoes any
//! argument whole (a 100 kB one filled the terminal).

use std::any::TypeId;

use clap::error::{ContextKind, ContextValue, ErrorKind};
use clap::Command;

/// Most characters of a user's value echoed in a message.
pub const ECHO_LIMIT: usize = 80;

/// `text` cut to [`ECHO_LIMIT`] characters, with `…` where it was cut.
pub fn capped(text: &str) -> String {
    match text.char_indices().nth(ECHO_LIMIT) {
        Some((at, _)) => format!("{}…", &text[..at]),
        None => text.to_string(),
    }
}

/// The usage error `e` of `cmd` as one line, without the `tool: error: ` prefix; it ends
/// with where to read more, e.g. `(see pack --help)`.
pub fn usage_line(cmd: &Command, e: &clap::Error) -> String {
    let path = command_path(cmd, e);
    let see = format!("(see {} --help)", path.join(" "));
    let sub = subcommand(cmd, &path);
    let text = |kind| e.get(kind).map(plain);
    let list = |kind| e.get(kind).map(values).unwrap_or_default();
    let arg = text(ContextKind::InvalidArg).map(|a| flag_name(&a)).unwrap_or_default();
    let value = text(ContextKind::InvalidValue).map(|v| capped(&v)).unwrap_or_default();
    let body = match e.kind() {
        ErrorKind::InvalidValue if value.is_empty() => format!("{arg} needs a value"),
        ErrorKind::InvalidValue => {
            let valid = list(ContextKind::ValidValue);
            let hint = suggestion(&list(ContextKind::SuggestedValue));
            format!("invalid value '{value}' for {arg}: expected one of {}{hint}", valid.join(", "))
        }
        ErrorKind::ValueValidation => {
            let why = expected(sub, &arg, e);
            format!("invalid value '{value}' for {arg}: {why}")
        }
        ErrorKind::UnknownArgument => {
            let given = text(ContextKind::InvalidArg).map(|a| capped(&a)).unwrap_or_default();
            let what = if given.starts_with('-') { "unknown flag" } else { "unexpected argument" };
            let hint = suggestion(&list(ContextKind::SuggestedArg));
            let dash = if e.get(ContextKind::TrailingArg).is_some() {
                format!("; to give '{given}' as a value, put '--' before it")
            } else {
                String::new()
            };
            format!("{what} '{given}'{hint}{dash}")
        }
        ErrorKind::InvalidSubcommand => {
            let given = text(ContextKind::InvalidSubcommand).map(|a| capped(&a)).unwrap_or_default();
            let hint = suggestion(&list(ContextKind::SuggestedSubcommand));
            format!("unknown subcommand '{given}'{hint}: expected one of {}", subcommands(sub))
        }
        ErrorKind::ArgumentConflict => {
            let others = list(ContextKind::PriorArg).iter().map(|a| flag_name(a)).collect::<Vec<_>>();
            match others.as_slice() {
                [] => format!("{arg} cannot be used here"),
                _ => format!("{arg} cannot be used with {}: give only one of them", others.join(", ")),
            }
        }
        ErrorKind::MissingRequiredArgument => {
            let missing = list(ContextKind::InvalidArg).iter().map(|a| flag_name(a)).collect::<Vec<_>>();
            format!("missing {}", missing.join(", "))
        }
        ErrorKind::MissingSubcommand | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand if sub.has_subcommands() => {
            format!("give a subcommand: one of {}", subcommands(sub))
        }
        ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => "arguments are missing".to_string(),
        ErrorKind::TooManyValues => format!("too many values for {arg} ('{value}' is one too many)"),
        ErrorKind::TooFewValues | ErrorKind::WrongNumberOfValues => {
            let wanted = text(ContextKind::ExpectedNumValues).or_else(|| text(ContextKind::MinValues));
            format!("{arg} takes {} values", wanted.unwrap_or_default())
        }
        ErrorKind::NoEquals => format!("{arg} needs its value after '=' ({arg}=VALUE)"),
        ErrorKind::InvalidUtf8 => "an argument is not valid UTF-8".to_string(),
        _ => {
            // Kinds without context: clap's own first line, less its "error: ".
            let rendered = e.render().to_string();
            let first = rendered.lines().next().unwrap_or_default();
            capped(first.trim_start_matches("error: "))
        }
    };
    format!("{body} {see}")
}

fn plain(v: &ContextValue) -> String {
    match v {
        ContextValue::Strings(s) => s.join(", "),
        other => other.to_string(),
    }
}

fn values(v: &ContextValue) -> Vec<String> {
    match v {
        ContextValue::String(s) => vec![s.clone()],
        ContextValue::Strings(s) => s.clone(),
        ContextValue::StyledStr(s) => vec![s.to_string()],
        ContextValue::StyledStrs(s) => s.iter().map(ToString::to_string).collect(),
        _ => Vec::new(),
    }
}

fn suggestion(suggested: &[String]) -> String {
    match suggested.first() {
        Some(s) => format!(" (did you mean '{}'?)", capped(s)),
        None => String::new(),
    }
}

/// `--seed <SEED>` → `--seed`; `<PROFILE>...` → `PROFILE`.
fn flag_name(arg: &str) -> String {
    let arg = arg.trim();
    if arg.starts_with('-') {
        let end = arg.find([' ', '=']).unwrap_or(arg.len());
        capped(&arg[..end])
    } else {
        capped(arg.trim_end_matches("...").trim_matches(['<', '>', '[', ']']))
    }
}

/// The command line up to the subcommand that failed (`mkpellet cylinder`), read from the
/// usage clap attached; the tool's name alone without one.
fn command_path(cmd: &Command, e: &clap::Error) -> Vec<String> {
    let mut path = vec![cmd.get_name().to_string()];
    let Some(usage) = e.get(ContextKind::Usage).map(ToString::to_string) else {
        return path;
    };
    let words = usage.trim().trim_start_matches("Usage:").split_whitespace().skip(1);
    let mut at = cmd;
    for word in words {
        match at.find_subcommand(word) {
            Some(next) => {
                path.push(word.to_string());
                at = next;
            }
            None => break,
        }
    }
    path
}

fn subcommand<'a>(cmd: &'a Command, path: &[String]) -> &'a Command {
    path.iter().skip(1).fold(cmd, |at, name| at.find_subcommand(name).unwrap_or(at))
}

fn subcommands(cmd: &Command) -> String {
    let names = cmd.get_subcommands().map(|s| s.get_name()).filter(|n| *n != "help");
    names.collect::<Vec<_>>().join(", ")
}

/// What the flag takes: for whole numbers their range, for numbers "a number", otherwise the
/// reason the value parser gave.
fn expected(cmd: &Command, arg: &str, e: &clap::Error) -> String {
    let reason = std::error::Error::source(e).map(ToString::to_string).unwrap_or_default();
    let found = cmd.get_arguments().find(|a| {
        a.get_long().is_some_and(|l| format!("--{l}") == arg)
            || a.get_short().is_some_and(|s| format!("-{s}") == arg)
            || a.get_id().as_str().eq_ignore_ascii_case(arg)
    });
    let Some(found) = found else {
        return capped(&reason);
    };
    let id = found.get_value_parser().type_id();
    macro_rules! whole {
        ($($t:ty),*) => {
            $(if id == TypeId::of::<$t>() {
                return format!("expected a whole number from {} to {}", <$t>::MIN, <$t>::MAX);
            })*
        };
    }
    whole!(u8, u16, u32, u64, usize, i8, i16, i32, i64, isize);
    let unparsed = std::error::Error::source(e).is_some_and(|s| s.is::<std::num::ParseFloatError>());
    if unparsed && (id == TypeId::of::<f64>() || id == TypeId::of::<f32>()) {
        return "expected a number".to_string();
    }
    capped(&reason)
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Debug, Parser)]
    #[command(name = "t", allow_negative_numbers = true)]
    struct Args {
        #[arg(long)]
        seed: Option<u64>,
        #[arg(long)]
        count: Option<u32>,
        #[arg(long)]
        ratio: Option<f64>,
        #[arg(long, value_enum)]
        mode: Option<Mode>,
        #[arg(long, conflicts_with = "b")]
        a: bool,
        #[arg(long)]
        b: bool,
    }

    #[derive(Clone, Copy, Debug, clap::ValueEnum)]
    enum Mode {
        Fast,
        Slow,
    }

    fn line(args: &[&str]) -> String {
        let e = Args::try_parse_from(std::iter::once("t").chain(args.iter().copied())).unwrap_err();
        usage_line(&<Args as clap::CommandFactory>::command(), &e)
    }

    #[test]
    fn each_kind_reads_as_one_line_with_the_flag_and_what_it_takes() {
        assert_eq!(
            line(&["--mode", "Fast"]),
            "invalid value 'Fast' for --mode: expected one of fast, slow (did you mean 'fast'?) (see t --help)"
        );
        assert_eq!(
            line(&["--seed", "x"]),
            "invalid value 'x' for --seed: expected a whole number from 0 to 18446744073709551615 (see t --help)"
        );
        assert_eq!(
            line(&["--count", "-5"]),
            "invalid value '-5' for --count: expected a whole number from 0 to 4294967295 (see t --help)"
        );
        assert_eq!(line(&["--ratio", "x"]), "invalid value 'x' for --ratio: expected a number (see t --help)");
        assert_eq!(line(&["--a", "--b"]), "--a cannot be used with --b: give only one of them (see t --help)");
        assert_eq!(line(&["--seed"]), "--seed needs a value (see t --help)");
        assert_eq!(line(&["--sed", "1"]), "unknown flag '--sed' (did you mean '--seed'?) (see t --help)");
    }

    #[test]
    fn echoed_values_are_capped() {
        let long = format!("--{}", "x".repeat(100_000));
        let l = line(&[&long]);
        assert!(l.len() < 200 && l.contains("xxx…'"), "{l}");
        assert_eq!(capped("short"), "short");
        assert_eq!(capped(&"é".repeat(81)), format!("{}…", "é".repeat(80)));
    }
}
