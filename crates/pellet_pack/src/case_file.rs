//! Reading a case file (TOML, or JSON starting with `{`) into [`PackOptions`].
//!
//! Each key and value is checked against [`keys::KEYS`] before the file is deserialized, so a
//! mistake reads in the user's terms, on one line: where it is, the key, the value given
//! (clipped) and what the key takes, with the ranges the flags have:
//! `c.toml:2: invalid value `-1` for count: expected a whole number from 1 to 1000000`.

use std::collections::BTreeMap;

use serde::de::{DeserializeSeed, Deserializer, Error as _, MapAccess, Visitor};

use crate::config::PackOptions;
use crate::keys::{self, Kind};
use crate::ConfigError;

/// Longest value or key quoted in a message (a value may be megabytes long).
const SHOWN_CHARS: usize = 40;

impl PackOptions {
    /// Parses a case file: JSON if it starts with `{`, TOML otherwise.
    pub fn from_case_file(text: &str, name: &str) -> Result<Self, ConfigError> {
        if text.trim_start().starts_with('{') {
            from_json(text, name)
        } else {
            from_toml(text, name)
        }
    }
}

/// A value as either format holds it, reduced to what the checks tell apart.
enum Given<'a> {
    Int(i128),
    Float(f64),
    Bool,
    Str(&'a str),
    /// JSON's `null`: the key is unset, as if absent.
    Null,
    /// A table, array or date.
    Other,
}

/// `Ok` if `key` takes this value, or the message saying what it takes. `shown` renders the
/// value in the file's own syntax, only when there is an error.
fn check(key: &str, given: Given, shown: impl FnOnce() -> String) -> Result<(), String> {
    let Some(kind) = keys::kind(key) else { return Err(unknown_key(key)) };
    let ok = match (kind, &given) {
        (_, Given::Null) | (Kind::Path, Given::Str(_)) | (Kind::Flag, Given::Bool) => true,
        (Kind::Whole(lo, hi), &Given::Int(i)) => i128::from(lo) <= i && i <= i128::from(hi),
        (Kind::Number(r), &Given::Int(i)) => r.holds(i as f64),
        (Kind::Number(r), &Given::Float(v)) => r.holds(v),
        (Kind::OneOf(names), Given::Str(s)) => names.contains(s),
        _ => false,
    };
    if ok {
        return Ok(());
    }
    let hint = match (kind, given) {
        (Kind::OneOf(names), Given::Str(s)) => {
            nearest(s, names, 3).map_or(String::new(), |n| format!("; did you mean `{n}`?"))
        }
        _ => String::new(),
    };
    Err(format!("invalid value `{}` for {key}: expected {}{hint}", shown(), keys::allowed(kind)))
}

fn unknown_key(key: &str) -> String {
    let names: Vec<&str> = keys::KEYS.iter().map(|(k, _)| *k).collect();
    let hint = nearest(key, &names, usize::MAX).map_or(String::new(), |k| format!("; did you mean `{k}`?"));
    format!("unknown key `{}`{hint} (keys are pack's flags without the dashes)", clip(key, SHOWN_CHARS).escape_debug())
}

/// The name nearest to `given`, if within `most` edits.
fn nearest<'a>(given: &str, names: &[&'a str], most: usize) -> Option<&'a str> {
    let given: String = given.chars().take(64).collect::<String>().to_lowercase();
    names.iter().map(|n| (edit_distance(&given, n), *n)).min().filter(|&(d, _)| d <= most).map(|(_, n)| n)
}

/// A value as the file spells it (`raw`), on one line, clipped.
fn shown(raw: &str) -> String {
    let head: String = raw.chars().take(4 * SHOWN_CHARS).collect();
    let one_line = head.split_whitespace().collect::<Vec<_>>().join(" ");
    let cut = raw.chars().nth(4 * SHOWN_CHARS).is_some() || one_line.chars().nth(SHOWN_CHARS).is_some();
    if cut {
        format!("{}…", one_line.chars().take(SHOWN_CHARS).collect::<String>())
    } else {
        one_line
    }
}

/// The line of byte `at` of `text`.
fn line_of(text: &str, at: usize) -> usize {
    text.as_bytes()[..at.min(text.len())].iter().filter(|&&b| b == b'\n').count() + 1
}

fn from_toml(text: &str, name: &str) -> Result<PackOptions, ConfigError> {
    use toml::{Spanned, Value};
    let syntax = |e: toml::de::Error| {
        // The position as name:line, where an editor jumps to it.
        let at = e.span().map_or(String::new(), |s| format!(":{}", line_of(text, s.start)));
        ConfigError(format!("{name}{at}: bad TOML case file: {}", plain(e.message())))
    };
    let table: BTreeMap<Spanned<String>, Spanned<Value>> = toml::from_str(text).map_err(syntax)?;
    let mut entries: Vec<_> = table.iter().collect();
    entries.sort_by_key(|(k, _)| k.span().start);
    for (key, value) in entries {
        let given = match value.get_ref() {
            Value::String(s) => Given::Str(s),
            Value::Integer(i) => Given::Int((*i).into()),
            Value::Float(v) => Given::Float(*v),
            Value::Boolean(_) => Given::Bool,
            Value::Datetime(_) | Value::Array(_) | Value::Table(_) => Given::Other,
        };
        // A table's span is its header or dotted key: it is shown inline instead.
        let raw = || match value.get_ref() {
            Value::Table(t) => shown(&Value::Table(t.clone()).to_string()),
            _ => shown(&text[value.span()]),
        };
        check(key.get_ref(), given, raw)
            .map_err(|m| ConfigError(format!("{name}:{}: {m}", line_of(text, key.span().start))))?;
    }
    // What the checks let through deserializes; their fallback is the parser's own message.
    toml::from_str(text).map_err(syntax)
}

/// Checks a JSON case file's keys and values in order, keeping the first mistake with its line
/// (serde_json would place an error at the end of the object).
struct JsonChecks<'a> {
    text: &'a str,
    failure: &'a std::cell::RefCell<Option<(usize, String)>>,
}

impl<'de> DeserializeSeed<'de> for JsonChecks<'de> {
    type Value = ();
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<(), D::Error> {
        d.deserialize_map(self)
    }
}

impl<'de> Visitor<'de> for JsonChecks<'de> {
    type Value = ();
    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("an object of pack's settings")
    }
    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<(), A::Error> {
        use serde_json::{value::RawValue, Value};
        while let Some(key) = map.next_key::<String>()? {
            // Borrowed from the text, so its place there gives the line.
            let raw: &RawValue = map.next_value()?;
            let line = line_of(self.text, (raw.get().as_ptr() as usize).saturating_sub(self.text.as_ptr() as usize));
            let fail = |message: String| {
                *self.failure.borrow_mut() = Some((line, message));
                A::Error::custom("checked")
            };
            if keys::kind(&key).is_none() {
                return Err(fail(unknown_key(&key)));
            }
            let value: Value = serde_json::from_str(raw.get()).map_err(A::Error::custom)?;
            let given = match &value {
                Value::String(s) => Given::Str(s),
                Value::Number(n) => match (n.as_i64(), n.as_u64()) {
                    (Some(i), _) => Given::Int(i.into()),
                    (None, Some(u)) => Given::Int(u.into()),
                    (None, None) => Given::Float(n.as_f64().unwrap_or(f64::NAN)),
                },
                Value::Bool(_) => Given::Bool,
                Value::Null => Given::Null,
                Value::Array(_) | Value::Object(_) => Given::Other,
            };
            check(&key, given, || shown(raw.get())).map_err(fail)?;
        }
        Ok(())
    }
}

fn from_json(text: &str, name: &str) -> Result<PackOptions, ConfigError> {
    let syntax = |e: serde_json::Error| {
        let message = e.to_string();
        let message = message.strip_suffix(&format!(" at line {} column {}", e.line(), e.column())).unwrap_or(&message);
        let at = if e.line() > 0 { format!(":{}", e.line()) } else { String::new() };
        ConfigError(format!("{name}{at}: bad JSON case file: {}", plain(message)))
    };
    let failure = std::cell::RefCell::new(None);
    let checked = JsonChecks { text, failure: &failure }.deserialize(&mut serde_json::Deserializer::from_str(text));
    if let Some((line, message)) = failure.into_inner() {
        return Err(ConfigError(format!("{name}:{line}: {message}")));
    }
    checked.map_err(syntax)?;
    // What the checks let through deserializes; their fallback is the parser's own message.
    serde_json::from_str(text).map_err(syntax)
}

/// A parser's message in a user's terms, on one line: what the file holds is quoted to at
/// most 40 characters (a value may be a megabyte long). For what the checks do not catch.
fn plain(message: &str) -> String {
    // Quoted spans ("…" or `…`) clipped, everything else kept.
    let mut out = String::new();
    let mut rest = message;
    while let Some(open) = rest.find(['"', '`']) {
        let quote = rest[open..].chars().next().expect("found");
        out.push_str(&rest[..=open]);
        rest = &rest[open + 1..];
        let close = rest.find(quote).unwrap_or(rest.len());
        out.push_str(&clip(&rest[..close], SHOWN_CHARS));
        rest = &rest[close..];
        if let Some(q) = rest.strip_prefix(quote) {
            out.push(quote);
            rest = q;
        }
    }
    out.push_str(rest);
    clip(&out.replace(['\n', '\r'], " "), 200)
}

/// At most `n` characters of `s`, an ellipsis marking a cut.
fn clip(s: &str, n: usize) -> String {
    match s.char_indices().nth(n) {
        Some((at, _)) => format!("{}…", &s[..at]),
        None => s.to_string(),
    }
}

/// Levenshtein distance, for suggesting the key or name a typo meant.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let next = (diagonal + usize::from(ca != cb)).min(row[j] + 1).min(row[j + 1] + 1);
            diagonal = row[j + 1];
            row[j + 1] = next;
        }
    }
    row[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(text: &str, name: &str) -> String {
        let e = PackOptions::from_case_file(text, name).unwrap_err().to_string();
        assert!(!e.contains('\n') && e.chars().count() <= 200, "{} characters: {e:?}", e.chars().count());
        e
    }

    /// The error for `key = value` on the second line of a TOML file and of a JSON file: the
    /// same message after the location.
    fn both(key: &str, toml_value: &str, json_value: &str) -> String {
        let t = err(&format!("output = \"b.mcap\"\n{key} = {toml_value}\n"), "c.toml");
        let j = err(&format!("{{\"output\": \"b.mcap\",\n  \"{key}\": {json_value}\n}}"), "c.json");
        let (t, j) = (t.strip_prefix("c.toml:2: ").expect(&t), j.strip_prefix("c.json:2: ").expect(&j));
        assert_eq!(t, j);
        t.to_string()
    }

    #[test]
    fn a_wrong_number_names_the_key_and_the_range() {
        assert_eq!(
            both("count", "-1", "-1"),
            "invalid value `-1` for count: expected a whole number from 1 to 1000000"
        );
        assert_eq!(
            both("count", "4294967296", "4294967296"),
            "invalid value `4294967296` for count: expected a whole number from 1 to 1000000"
        );
        assert_eq!(
            both("count", "2.5", "2.5"),
            "invalid value `2.5` for count: expected a whole number from 1 to 1000000"
        );
        assert_eq!(both("cor", "1.5", "1.5"), "invalid value `1.5` for cor: expected a number from 0 to 1");
        assert_eq!(
            both("tube-diameter", "-3", "-3"),
            "invalid value `-3` for tube-diameter: expected a number in mm above 0 and at most 10000"
        );
        assert_eq!(
            both("density", "2e6", "2e6"),
            "invalid value `2e6` for density: expected a number in kg/m³ above 0 and at most 1000000"
        );
        let e = err("tilt = nan\n", "c.toml");
        assert_eq!(e, "c.toml:1: invalid value `nan` for tilt: expected a number in degrees from 0 to 90");
    }

    #[test]
    fn a_wrong_type_names_the_key_and_what_it_takes() {
        let t = err("count = { a = 1 }\n", "c.toml");
        assert_eq!(t, "c.toml:1: invalid value `{ a = 1 }` for count: expected a whole number from 1 to 1000000");
        let j = err(r#"{"count": {"a": 1}}"#, "c.json");
        assert_eq!(j, r#"c.json:1: invalid value `{"a": 1}` for count: expected a whole number from 1 to 1000000"#);
        assert_eq!(
            both("scheme", "3", "3"),
            "invalid value `3` for scheme: expected one of one-column, two-columns, four-columns, sock, dense, batch"
        );
        assert_eq!(
            both("stepper", "\"Velocity\"", "\"Velocity\""),
            "invalid value `\"Velocity\"` for stepper: expected one of acceleration, velocity; did you mean `velocity`?"
        );
        assert_eq!(both("foxglove", "1", "1"), "invalid value `1` for foxglove: expected true or false");
        assert_eq!(
            both("pellet", "[1, 2]", "[1, 2]"),
            "invalid value `[1, 2]` for pellet: expected a file path in quotes"
        );
        assert_eq!(
            both("seed", "\"7\"", "\"7\""),
            "invalid value `\"7\"` for seed: expected a whole number from 0 to 18446744073709551615"
        );
    }

    /// The case file is flat: a table where a value belongs is named by its key, at its header.
    #[test]
    fn a_nested_table_is_refused_at_its_key() {
        let e = err("pellet = \"c.pellet\"\n\n[count]\nn = \"x\"\n", "c.toml");
        assert_eq!(e, "c.toml:3: invalid value `{ n = \"x\" }` for count: expected a whole number from 1 to 1000000");
        let e = err("{\"pellet\": \"c.pellet\",\n\"count\": {\"n\": \"x\"}}", "c.json");
        assert_eq!(e, "c.json:2: invalid value `{\"n\": \"x\"}` for count: expected a whole number from 1 to 1000000");
        let e = err("[loading]\nscheme = 3\n", "c.toml");
        assert!(e.starts_with("c.toml:1: unknown key `loading`"), "{e}");
    }

    #[test]
    fn a_huge_value_is_clipped() {
        let huge = "x".repeat(20 << 20);
        let clipped = format!("\"{}…", "x".repeat(39));
        for key in ["count", "scheme", "cor"] {
            let t = err(&format!("{key} = \"{huge}\"\n"), "c.toml");
            let j = err(&format!("{{\"{key}\": \"{huge}\"}}"), "c.json");
            for e in [t, j] {
                assert!(e.contains(&format!("invalid value `{clipped}` for {key}: expected ")), "{e}");
            }
        }
        let e = err(&format!("{huge} = 1\n"), "c.toml");
        assert!(e.starts_with(&format!("c.toml:1: unknown key `{}…`", "x".repeat(40))), "{e}");
        let e = err("\"a\\nb\" = 1\n", "c.toml");
        assert!(e.starts_with("c.toml:1: unknown key `a\\nb`"), "{e}");
        let e = err("scheme = \"a\\nb\"\n", "c.toml");
        assert!(e.contains("invalid value `\"a\\nb\"` for scheme"), "{e}");
    }

    #[test]
    fn unknown_keys_and_syntax_errors_say_where() {
        let e = err("count = 3\ntube-diametr = 3\n", "c.toml");
        assert_eq!(
            e,
            "c.toml:2: unknown key `tube-diametr`; did you mean `tube-diameter`? (keys are pack's flags without the dashes)"
        );
        let e = err("{\"count\": 3,\n\"tube-diametr\": 3}", "c.json");
        assert!(e.starts_with("c.json:2: unknown key `tube-diametr`; did you mean `tube-diameter`?"), "{e}");
        assert!(err("count = \n", "c.toml").starts_with("c.toml:1: bad TOML case file: "));
        assert!(err("{\"count\": 3,\n\n", "c.json").starts_with("c.json:3: bad JSON case file: "));
        let e = err("{\"count\": 3, \"count\": 4}", "c.json");
        assert_eq!(e, "c.json:1: bad JSON case file: duplicate field `count`");
    }

    #[test]
    fn good_values_read_in_both_formats() {
        let toml = "count = 5\ntilt = 0\nrecord-velocities = true\nstepper = \"velocity\"\nseed = 0\n";
        let json =
            r#"{"count": 5, "tilt": 0, "record-velocities": true, "stepper": "velocity", "seed": 0, "cor": null}"#;
        let a = PackOptions::from_case_file(toml, "c.toml").unwrap();
        assert_eq!(a, PackOptions::from_case_file(json, "c.json").unwrap());
        assert_eq!((a.count, a.tilt, a.seed, a.cor), (Some(5), Some(0.0), Some(0), None));
    }
}
