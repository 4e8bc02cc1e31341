//! What each of `pack`'s settings takes: one table for the case-file reader (which names the
//! key, the value and what is allowed) and for [`PackConfig::resolve`](crate::PackConfig::resolve)
//! (which checks the merged flags and file against the same ranges).

use crate::config::{MAX_COUNT, MAX_LENGTH_MM, MAX_THREADS};

/// The numbers a setting takes: `lo` to `hi` (`lo` itself excluded when `lo_open`), in `unit`
/// as the flag messages print it (" mm", "°", or "" for a pure number).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Range {
    pub lo: f64,
    pub hi: f64,
    pub lo_open: bool,
    pub unit: &'static str,
}

impl Range {
    /// Whether `v` is a finite number in the range.
    pub fn holds(&self, v: f64) -> bool {
        v.is_finite() && (if self.lo_open { v > self.lo } else { v >= self.lo }) && v <= self.hi
    }
}

/// The kind of value a setting takes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Kind {
    /// A file path.
    Path,
    /// An integer from `.0` to `.1`.
    Whole(u64, u64),
    /// A number in a range.
    Number(Range),
    /// `true` or `false`.
    Flag,
    /// One of these names.
    OneOf(&'static [&'static str]),
}

const fn closed(lo: f64, hi: f64, unit: &'static str) -> Kind {
    Kind::Number(Range { lo, hi, lo_open: false, unit })
}

const fn above(lo: f64, hi: f64, unit: &'static str) -> Kind {
    Kind::Number(Range { lo, hi, lo_open: true, unit })
}

/// Every setting, spelled as its flag without the dashes (the case-file key).
pub(crate) const KEYS: &[(&str, Kind)] = &[
    ("pellet", Kind::Path),
    ("output", Kind::Path),
    ("tube-diameter", above(0.0, MAX_LENGTH_MM, " mm")),
    ("count", Kind::Whole(1, MAX_COUNT as u64)),
    ("fill-height", above(0.0, MAX_LENGTH_MM, " mm")),
    ("seed", Kind::Whole(0, u64::MAX)),
    ("cor", closed(0.0, 1.0, "")),
    ("friction", closed(0.0, 10.0, "")),
    ("wall-cor", closed(0.0, 1.0, "")),
    ("wall-friction", closed(0.0, 10.0, "")),
    ("density", above(0.0, 1e6, " kg/m³")),
    ("drop-height", above(0.0, 1e4, " mm")),
    ("release-height", above(0.0, MAX_LENGTH_MM, " mm")),
    // Also whole engine steps, which resolve checks.
    ("record-every", above(0.0, 1e3, " s")),
    ("checkpoint-every", closed(0.0, 1e6, " s")),
    ("max-time", above(0.0, 1e6, " s")),
    ("scheme", Kind::OneOf(&["one-column", "two-columns", "four-columns", "sock", "dense", "batch"])),
    ("tilt", closed(0.0, 90.0, "°")),
    ("position-jitter", closed(0.0, 10.0, " dp")),
    ("angle-jitter", closed(0.0, 180.0, "°")),
    ("spacing", closed(0.0, 1e3, " s")),
    ("settle-window", above(0.0, 1e3, " s")),
    ("settle-tolerance", above(0.0, 1.0, "")),
    ("max-speed", above(0.0, 1e3, " m/s")),
    ("record-velocities", Kind::Flag),
    ("contact-model", Kind::OneOf(&["paper", "recommended"])),
    // Below ~1e-4 m/s the substep cap εp / 2g would be a few µs; above 0.1 m/s a pellet
    // bouncing at a walking pace would count as resting.
    ("resting-band", closed(1e-4, 0.1, " m/s")),
    ("friction-clamp", Kind::OneOf(&["stick", "zero"])),
    ("foxglove", Kind::Flag),
    ("stepper", Kind::OneOf(&["acceleration", "velocity"])),
    // Up to a tenth of the pellet: a wider patch is not a contact point's any more.
    ("contact-patch", closed(0.0, 0.1, " dp")),
    // A step is a fraction of an engine step of 5 ms; a pair travelling more than a tenth of a
    // pellet in one step would pass contacts that the step's near set cannot hold.
    ("step-travel", above(0.0, 0.1, " dp")),
    ("max-step", above(0.0, 0.005, " s")),
    ("substep-scale", above(0.0, 1.0, "")),
    ("threads", Kind::Whole(1, MAX_THREADS as u64)),
];

/// What `key` takes; `None` for a key `pack` does not have.
pub(crate) fn kind(key: &str) -> Option<Kind> {
    KEYS.iter().find(|(k, _)| *k == key).map(|&(_, kind)| kind)
}

/// The range of a numeric setting. Panics for a key that is not one: a mistake in this table.
pub(crate) fn range(key: &str) -> Range {
    match kind(key) {
        Some(Kind::Number(r)) => r,
        other => panic!("`{key}` is not a numeric setting ({other:?})"),
    }
}

/// What a setting takes, in words: "a whole number from 1 to 1000000", "a number in mm above 0",
/// "one of paper, recommended".
pub(crate) fn allowed(kind: Kind) -> String {
    match kind {
        Kind::Path => "a file path in quotes".into(),
        Kind::Whole(lo, hi) => format!("a whole number from {lo} to {hi}"),
        Kind::Number(r) => {
            let unit = match r.unit.trim() {
                "" => String::new(),
                "°" => " in degrees".into(),
                "dp" => " in pellet diameters".into(),
                u => format!(" in {u}"),
            };
            let bounds = match (r.lo_open, r.hi.is_finite()) {
                (false, _) => format!("from {} to {}", r.lo, r.hi),
                (true, false) => format!("above {}", r.lo),
                (true, true) => format!("above {} and at most {}", r.lo, r.hi),
            };
            format!("a number{unit} {bounds}")
        }
        Kind::Flag => "true or false".into(),
        Kind::OneOf(names) => format!("one of {}", names.join(", ")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::{ClampRule, ContactModel, PackOptions};
    use crate::loading::LoadingScheme;
    use crate::Stepper;

    /// Every field of PackOptions is in the table and every key of the table is a field:
    /// a field is listed here by name, so a new one fails to compile until it is added.
    #[test]
    fn the_table_lists_every_setting_once() {
        let all = PackOptions {
            pellet: Some("p".into()),
            output: Some("o".into()),
            tube_diameter: Some(1.0),
            count: Some(1),
            fill_height: Some(1.0),
            seed: Some(1),
            cor: Some(1.0),
            friction: Some(1.0),
            wall_cor: Some(1.0),
            wall_friction: Some(1.0),
            density: Some(1.0),
            drop_height: Some(1.0),
            release_height: Some(1.0),
            record_every: Some(1.0),
            checkpoint_every: Some(1.0),
            max_time: Some(1.0),
            scheme: Some(LoadingScheme::Sock),
            tilt: Some(1.0),
            position_jitter: Some(1.0),
            angle_jitter: Some(1.0),
            spacing: Some(1.0),
            settle_window: Some(1.0),
            settle_tolerance: Some(1.0),
            max_speed: Some(1.0),
            record_velocities: Some(true),
            contact_model: Some(ContactModel::Paper),
            resting_band: Some(1.0),
            friction_clamp: Some(ClampRule::Zero),
            foxglove: Some(true),
            stepper: Some(Stepper::Velocity),
            contact_patch: Some(1.0),
            step_travel: Some(1.0),
            max_step: Some(1.0),
            substep_scale: Some(1.0),
            threads: Some(1),
        };
        let fields = match serde_json::to_value(all).unwrap() {
            serde_json::Value::Object(m) => m.keys().cloned().collect::<Vec<_>>(),
            v => panic!("{v}"),
        };
        let mut keys: Vec<String> = KEYS.iter().map(|(k, _)| k.to_string()).collect();
        keys.sort();
        assert_eq!(fields, keys);
    }

    /// The names listed are exactly the names each enum reads.
    #[test]
    fn the_names_listed_are_the_names_read() {
        fn names<T: serde::Serialize>(all: &[T]) -> Vec<String> {
            all.iter().map(|v| serde_json::to_value(v).unwrap().as_str().unwrap().to_string()).collect()
        }
        // Exhaustive matches: a new variant fails to compile until it is listed.
        let scheme = |s: LoadingScheme| match s {
            LoadingScheme::OneColumn
            | LoadingScheme::TwoColumns
            | LoadingScheme::FourColumns
            | LoadingScheme::Sock
            | LoadingScheme::Dense
            | LoadingScheme::Batch => s,
        };
        let model = |m: ContactModel| match m {
            ContactModel::Paper | ContactModel::Recommended => m,
        };
        let clamp = |c: ClampRule| match c {
            ClampRule::Stick | ClampRule::Zero => c,
        };
        let stepper = |s: Stepper| match s {
            Stepper::Acceleration | Stepper::Velocity => s,
        };
        use LoadingScheme::*;
        for (key, wanted) in [
            ("scheme", names(&[OneColumn, TwoColumns, FourColumns, Sock, Dense, Batch].map(scheme))),
            ("contact-model", names(&[ContactModel::Paper, ContactModel::Recommended].map(model))),
            ("friction-clamp", names(&[ClampRule::Stick, ClampRule::Zero].map(clamp))),
            ("stepper", names(&[Stepper::Acceleration, Stepper::Velocity].map(stepper))),
        ] {
            let Some(Kind::OneOf(listed)) = kind(key) else { panic!("{key}") };
            assert_eq!(listed, wanted, "{key}");
        }
    }

    #[test]
    fn what_is_allowed_reads_as_words() {
        assert_eq!(allowed(kind("count").unwrap()), "a whole number from 1 to 1000000");
        assert_eq!(allowed(kind("tube-diameter").unwrap()), "a number in mm above 0 and at most 10000");
        assert_eq!(allowed(kind("cor").unwrap()), "a number from 0 to 1");
        assert_eq!(allowed(kind("density").unwrap()), "a number in kg/m³ above 0 and at most 1000000");
        assert_eq!(allowed(kind("tilt").unwrap()), "a number in degrees from 0 to 90");
        assert_eq!(allowed(kind("foxglove").unwrap()), "true or false");
        assert_eq!(allowed(kind("stepper").unwrap()), "one of acceleration, velocity");
    }
}
