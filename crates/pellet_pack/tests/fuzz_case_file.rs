//! `pack`'s case files (TOML and JSON) on cut, flipped and hostile input: every cut, random
//! flipped bytes, and values of the wrong type or out of range for every key. Each is read
//! and resolved to a configuration or a one-line error, never a panic.

use pellet_pack::config::{PackConfig, PackOptions};
use proptest::prelude::*;
use proptest::test_runner::Config;

/// `default` cases, or `PROPTEST_CASES` (`make fuzz` raises it).
fn config(default: u32) -> Config {
    let cases = std::env::var("PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(default);
    Config { cases, failure_persistence: None, ..Config::default() }
}

/// A case file setting every key, as a user writes one.
const CASE: &str = r#"# the paper's cylinders
pellet = "c.pellet"
output = "bed.mcap"
tube-diameter = 69.83
count = 40
seed = 7
cor = 0.9
friction = 0.1
wall-cor = 0.6
wall-friction = 0.6
density = 8030
drop-height = 30
record-every = 0.01
checkpoint-every = 1
max-time = 120
scheme = "one-column"
tilt = 45
position-jitter = 0.1
angle-jitter = 5
spacing = 0.02
settle-window = 0.15
settle-tolerance = 1e-3
max-speed = 1e-3
record-velocities = false
contact-model = "recommended"
resting-band = 5e-3
friction-clamp = "stick"
foxglove = false
stepper = "velocity"
contact-patch = 1e-3
step-travel = 0.025
max-step = 1.25e-3
substep-scale = 1
threads = 2
"#;

/// Reads and resolves a case file; every error is one readable line.
fn read(text: &str) {
    let resolved = PackOptions::from_case_file(text, "case.toml").and_then(|o| PackConfig::resolve(&o));
    if let Err(e) = resolved {
        let s = e.to_string();
        let head: String = s.chars().take(400).collect();
        assert!(!s.contains('\n'), "a multi-line error: {head:?}");
        assert!(s.chars().count() <= 300, "an error of {} characters: {head}", s.chars().count());
    }
}

#[test]
fn the_sample_case_resolves_and_every_cut_reads_or_is_refused() {
    PackConfig::resolve(&PackOptions::from_case_file(CASE, "case.toml").unwrap()).unwrap();
    for cut in 0..=CASE.len() {
        if CASE.is_char_boundary(cut) {
            read(&CASE[..cut]);
        }
    }
}

/// What a hostile case file gives a key: other types, out-of-range and non-finite numbers.
fn odd_value() -> impl Strategy<Value = String> {
    prop_oneof![
        Just("nan".to_string()),
        Just("inf".to_string()),
        Just("-inf".to_string()),
        Just("-1".to_string()),
        Just("0".to_string()),
        Just("1e308".to_string()),
        Just("-1e308".to_string()),
        Just("5e-324".to_string()),
        Just("99999999999999999999".to_string()),
        Just("4294967296".to_string()),
        Just("-9223372036854775808".to_string()),
        Just("true".to_string()),
        Just("\"\"".to_string()),
        Just(format!("\"{}\"", "x".repeat(2000))),
        Just("[1, 2]".to_string()),
        Just("{ a = 1 }".to_string()),
        Just("1979-05-27T07:32:00Z".to_string()),
        Just("\"é\\u0000\"".to_string()),
        Just(String::new()),
        any::<f64>().prop_map(|v| format!("{v:?}")),
        any::<i64>().prop_map(|v| v.to_string()),
        "[ -~]{0,10}",
    ]
}

/// The JSON form of the sample case, for the JSON reader.
fn as_json(toml_text: &str) -> Option<String> {
    let value: toml::Value = toml::from_str(toml_text).ok()?;
    serde_json::to_string(&value).ok()
}

proptest! {
    #![proptest_config(config(300))]

    #[test]
    fn odd_values_for_any_key_are_read_or_refused(picks in prop::collection::vec((any::<usize>(), odd_value()), 1..4)) {
        let mut lines: Vec<String> = CASE.lines().map(str::to_string).collect();
        let keyed: Vec<usize> = (0..lines.len()).filter(|&i| lines[i].contains(" = ")).collect();
        for (k, value) in &picks {
            let i = keyed[k % keyed.len()];
            let key = lines[i].split(" = ").next().unwrap().to_string();
            lines[i] = format!("{key} = {value}");
        }
        let text = lines.join("\n");
        read(&text);
        if let Some(json) = as_json(&text) {
            read(&json);
        }
    }

    #[test]
    fn flipped_bytes_in_a_case_file_are_read_or_refused(
        flips in prop::collection::vec((any::<usize>(), 1..=255u8), 1..=8), json in any::<bool>(),
    ) {
        let mut bytes = if json { as_json(CASE).unwrap().into_bytes() } else { CASE.as_bytes().to_vec() };
        for (at, x) in flips {
            let n = bytes.len();
            bytes[at % n] ^= x;
        }
        // pack reads case files as UTF-8 text (`read_to_string`): a byte that is not is an
        // I/O error before the parser.
        if let Ok(text) = std::str::from_utf8(&bytes) {
            read(text);
        }
    }
}
