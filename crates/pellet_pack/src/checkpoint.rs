//! Checkpoints of a pack run: everything that, with the run's configuration and pellet,
//! continues it bit for bit — the bodies with their momenta, the resting phase's warm forces,
//! the loader's place in its random stream, and the driver's own state (next entry, next
//! frame, the recent energy history the settle test reads).
//!
//! `pack` writes one into the trajectory every `--checkpoint-every` simulated seconds and at
//! the end; `pack --resume` reads the last one back. A bed of hundreds of cylinders takes hours,
//! and a run killed by a machine going down, a wall-clock limit or a closed terminal is then
//! not lost: the resumed trajectory equals the uninterrupted one frame for frame.

use serde::{Deserialize, Serialize};

use pellet_settle::EnergySample;
use pellet_sim::{Manifold, WarmForce, WarmImpulse, WorldState};

use crate::config::PackConfig;
use crate::driver::{Ending, PackError};
use crate::loading::FeederState;

/// Version of the checkpoint layout. A reader accepts its own, version 3 (without the
/// velocity-level stepper's contact manifolds), version 2 (whose warm impulses also lack the
/// torques of the contacts' patches) and version 1 (written before the velocity-level stepper,
/// whose impulses and integrator ledger it lacks).
pub const CHECKPOINT_VERSION: u32 = 4;

/// The driver's state between two steps, apart from the world and the loader.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunState {
    /// Pellets are still being fed.
    pub feeding: bool,
    /// Earliest time of the next pellet's entry (s).
    pub next_entry: f64,
    /// Time of the next recorded frame (s).
    pub next_frame: f64,
    /// Time of the next checkpoint (s).
    pub next_checkpoint: f64,
    /// Largest penetration so far (m).
    pub max_penetration: f64,
    /// Engine substeps so far.
    pub substeps: u64,
    /// The energy history the settle test still reads (the last two windows).
    pub history: Vec<EnergySample>,
    /// Since when each pellet has been slow (s), for the bed surface.
    pub slow_since: Vec<Option<f64>>,
    /// How the run ended, for the checkpoint written at its end.
    pub ending: Option<Ending>,
}

/// One checkpoint.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Checkpoint {
    /// [`CHECKPOINT_VERSION`] of the writer.
    pub version: u32,
    /// Bodies, clock and dissipation totals.
    pub world: WorldState,
    /// The resting phase's warm forces.
    pub warm: Vec<WarmForce>,
    /// The loader.
    pub feeder: FeederState,
    /// The driver.
    pub run: RunState,
    /// The velocity-level stepper's warm impulses (empty for the other stepper).
    pub impulses: Vec<WarmImpulse>,
    /// The velocity-level stepper's contact manifolds (empty for the other stepper).
    pub manifolds: Vec<Manifold>,
}

impl Checkpoint {
    /// Simulated time of the checkpoint (s).
    pub fn time_s(&self) -> f64 {
        self.world.time
    }

    /// The bytes stored in the trajectory.
    pub fn encode(&self) -> Result<Vec<u8>, PackError> {
        pellet_io::encode_message(self).map_err(|e| PackError::Sink(e.to_string()))
    }

    /// Reads a checkpoint stored in `path`.
    pub fn decode(bytes: &[u8], path: &str) -> Result<Self, PackError> {
        let setup = |m: String| PackError::Setup(m);
        // The version leads the layout, so an older layout is named, not misread.
        let version: u32 = pellet_io::decode_message(bytes.get(..4).unwrap_or_default(), path, "checkpoint")
            .map_err(|e| setup(e.to_string()))?;
        match version {
            CHECKPOINT_VERSION => pellet_io::decode_message(bytes, path, "checkpoint").map_err(|e| setup(e.to_string())),
            3 => pellet_io::decode_message::<v3::Checkpoint>(bytes, path, "checkpoint")
                .map(v3::Checkpoint::upgrade)
                .map_err(|e| setup(e.to_string())),
            2 => pellet_io::decode_message::<v2::Checkpoint>(bytes, path, "checkpoint")
                .map(v2::Checkpoint::upgrade)
                .map_err(|e| setup(e.to_string())),
            1 => pellet_io::decode_message::<v1::Checkpoint>(bytes, path, "checkpoint")
                .map(v1::Checkpoint::upgrade)
                .map_err(|e| setup(e.to_string())),
            _ => Err(setup(format!(
                "{path}: checkpoint version {version}, this pack reads versions 1 to {CHECKPOINT_VERSION}; run without --resume"
            ))),
        }
    }
}

/// The layout of version 3, read into the current one: no contact manifolds; the next step
/// finds every contact afresh.
mod v3 {
    use super::*;

    #[derive(Deserialize)]
    pub(super) struct Checkpoint {
        pub(super) version: u32,
        pub(super) world: WorldState,
        pub(super) warm: Vec<WarmForce>,
        pub(super) feeder: FeederState,
        pub(super) run: RunState,
        pub(super) impulses: Vec<WarmImpulse>,
    }

    impl Checkpoint {
        pub(super) fn upgrade(self) -> super::Checkpoint {
            debug_assert_eq!(self.version, 3);
            super::Checkpoint {
                version: CHECKPOINT_VERSION,
                world: self.world,
                warm: self.warm,
                feeder: self.feeder,
                run: self.run,
                impulses: self.impulses,
                manifolds: Vec::new(),
            }
        }
    }
}

/// The layout of version 2, read as version 3 and then into the current one: its warm
/// impulses carry no patch torques, and start from none.
mod v2 {
    use super::*;
    use pellet_sim::ContactKey;

    #[derive(Deserialize)]
    struct Impulse {
        key: ContactKey,
        normal: f64,
        friction: pellet_sim::Vec3,
        approach: f64,
    }

    #[derive(Deserialize)]
    pub(super) struct Checkpoint {
        version: u32,
        world: WorldState,
        warm: Vec<WarmForce>,
        feeder: FeederState,
        run: RunState,
        impulses: Vec<Impulse>,
    }

    impl Checkpoint {
        pub(super) fn upgrade(self) -> super::Checkpoint {
            debug_assert_eq!(self.version, 2);
            let impulses = self
                .impulses
                .into_iter()
                .map(|w| WarmImpulse {
                    key: w.key,
                    normal: w.normal,
                    friction: w.friction,
                    torque: pellet_sim::Vec3::zeros(),
                    approach: w.approach,
                })
                .collect();
            super::v3::Checkpoint {
                version: 3,
                world: self.world,
                warm: self.warm,
                feeder: self.feeder,
                run: self.run,
                impulses,
            }
            .upgrade()
        }
    }
}

/// The layout of version 1, read into the current one.
mod v1 {
    use super::*;
    use pellet_sim::{Body, EnergyLedger};

    #[derive(Deserialize)]
    struct Ledger {
        kinetic_translational: f64,
        kinetic_rotational: f64,
        potential: f64,
        removed_by_collisions: f64,
        removed_by_friction: f64,
        removed_by_projection: f64,
        resting_normal_work: f64,
        resting_work_bound: f64,
    }

    #[derive(Deserialize)]
    struct World {
        bodies: Vec<Body>,
        time: f64,
        totals: Ledger,
    }

    #[derive(Deserialize)]
    pub(super) struct Checkpoint {
        version: u32,
        world: World,
        warm: Vec<WarmForce>,
        feeder: FeederState,
        run: RunState,
    }

    impl Checkpoint {
        pub(super) fn upgrade(self) -> super::Checkpoint {
            let t = self.world.totals;
            let totals = EnergyLedger {
                kinetic_translational: t.kinetic_translational,
                kinetic_rotational: t.kinetic_rotational,
                potential: t.potential,
                removed_by_collisions: t.removed_by_collisions,
                removed_by_friction: t.removed_by_friction,
                removed_by_projection: t.removed_by_projection,
                resting_normal_work: t.resting_normal_work,
                resting_work_bound: t.resting_work_bound,
                removed_by_integrator: 0.0,
            };
            debug_assert_eq!(self.version, 1);
            super::Checkpoint {
                version: CHECKPOINT_VERSION,
                world: WorldState { bodies: self.world.bodies, time: self.world.time, totals },
                warm: self.warm,
                feeder: self.feeder,
                run: self.run,
                impulses: Vec::new(),
                manifolds: Vec::new(),
            }
        }
    }
}

/// Settings that may differ between a run and its continuation: where the pellet file is
/// (its bytes are compared instead), when to stop, how often to checkpoint, the viewer, and
/// the threads (any number gives the same frames).
const MAY_CHANGE: [&str; 5] = ["pellet", "max_time_s", "checkpoint_every_s", "foxglove", "threads"];

/// The settings in which `config` differs from the run recorded with `recorded_json` (the
/// trajectory's `config` metadata), as the flags a user types: "--count 20 → 21"; empty if it
/// may continue it.
pub fn resume_conflicts(recorded_json: &str, config: &PackConfig) -> Vec<String> {
    let Ok(serde_json::Value::Object(mut old)) = serde_json::from_str::<serde_json::Value>(recorded_json) else {
        return vec!["config: the recorded configuration is unreadable".into()];
    };
    // A setting recorded before it existed reads as the value that run had (the field's
    // default), not as a change.
    if let Ok(serde_json::Value::Object(filled)) =
        serde_json::from_str::<PackConfig>(recorded_json).map(|c| serde_json::to_value(c).unwrap_or_default())
    {
        old = filled;
    }
    let Ok(serde_json::Value::Object(new)) = serde_json::to_value(config) else {
        return vec!["config: cannot encode the configuration".into()];
    };
    let mut out = Vec::new();
    for (key, value) in &new {
        if MAY_CHANGE.contains(&key.as_str()) {
            continue;
        }
        match old.get(key) {
            Some(v) if v == value => {}
            Some(v) => {
                let ((was_flag, was), (flag, now)) = (as_flag(key, v), as_flag(key, value));
                if was_flag == flag {
                    out.push(format!("{flag} {was} → {now}"));
                } else {
                    out.push(format!("{was_flag} {was} → {flag} {now}"));
                }
            }
            None => {
                let (flag, now) = as_flag(key, value);
                out.push(format!("{flag}: not recorded → {now}"));
            }
        }
    }
    for key in old.keys() {
        if !new.contains_key(key) && !MAY_CHANGE.contains(&key.as_str()) {
            out.push(format!("{}: recorded but unknown to this pack", as_flag(key, &serde_json::Value::Null).0));
        }
    }
    out
}

/// A recorded setting (SI, named as in [`PackConfig`]) as the flag and value a user gives:
/// `tube_diameter_m` 0.03 → `--tube-diameter` 30 (mm), `amount` {"Count":20} → `--count` 20.
fn as_flag(key: &str, value: &serde_json::Value) -> (String, String) {
    use serde_json::Value;
    if let Value::Object(amount) = value {
        if let Some((variant, inner)) = amount.iter().next() {
            return match variant.as_str() {
                "Count" => ("--count".into(), shown(inner, 1.0)),
                "FillHeight" => ("--fill-height".into(), shown(inner, 1e3)),
                other => (format!("--{}", kebab(other)), shown(inner, 1.0)),
            };
        }
    }
    // The SI suffixes of PackConfig, longest first, and the factor back to the flag's unit.
    let units = [("_kg_m3", 1.0), ("_m_s", 1.0), ("_rad", 180.0 / std::f64::consts::PI), ("_dp", 1.0), ("_s", 1.0)];
    let (name, factor) = units
        .iter()
        .find_map(|(suffix, f)| key.strip_suffix(suffix).map(|n| (n, *f)))
        .or_else(|| key.strip_suffix("_m").map(|n| (n, 1e3)))
        .unwrap_or((key, 1.0));
    (format!("--{}", kebab(name)), shown(value, factor))
}

fn shown(value: &serde_json::Value, factor: f64) -> String {
    use serde_json::Value;
    match value {
        Value::Number(n) if factor != 1.0 || n.is_f64() => {
            // Rounded to 12 digits: 0.12 m × 1000 reads 120, not 120.00000000000001.
            let v = n.as_f64().unwrap_or(f64::NAN) * factor;
            let digits = 11 - v.abs().log10().floor().clamp(-20.0, 20.0) as i32;
            let scale = 10f64.powi(digits.max(0));
            format!("{}", (v * scale).round() / scale)
        }
        Value::Number(n) => n.to_string(),
        Value::String(s) => kebab(s),
        Value::Bool(true) => "on".into(),
        Value::Bool(false) => "off".into(),
        Value::Null => "(none)".into(),
        other => other.to_string(),
    }
}

/// `tube_diameter` → `tube-diameter`, `OneColumn` → `one-column`.
fn kebab(name: &str) -> String {
    let mut out = String::new();
    for (i, c) in name.chars().enumerate() {
        if c.is_ascii_uppercase() && i > 0 {
            out.push('-');
        }
        out.push(if c == '_' { '-' } else { c.to_ascii_lowercase() });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::{PackOptions, Stepper};

    fn config(stepper: Option<Stepper>) -> PackConfig {
        let o = PackOptions {
            pellet: Some("s.pellet".into()),
            tube_diameter: Some(40.0),
            count: Some(10),
            stepper,
            ..Default::default()
        };
        PackConfig::resolve(&o).unwrap()
    }

    /// A run recorded before the stepper could be chosen was the force-level stepper's: it
    /// resumes with that one, and is refused with the other, naming the setting.
    #[test]
    fn a_run_resumes_only_with_its_own_stepper() {
        let mut old = serde_json::to_value(config(None)).unwrap();
        old.as_object_mut().unwrap().remove("stepper");
        let old = old.to_string();
        assert!(resume_conflicts(&old, &config(Some(Stepper::Acceleration))).is_empty());
        let refused = resume_conflicts(&old, &config(Some(Stepper::Velocity)));
        assert_eq!(refused.len(), 1, "{refused:?}");
        assert_eq!(refused, ["--stepper acceleration → velocity"]);
        let velocity = serde_json::to_string(&config(Some(Stepper::Velocity))).unwrap();
        assert!(resume_conflicts(&velocity, &config(Some(Stepper::Velocity))).is_empty());
        assert_eq!(resume_conflicts(&velocity, &config(Some(Stepper::Acceleration))).len(), 1);
    }

    /// A run recorded before the velocity stepper's step was a setting had the step of that
    /// time (0.025 d, 1.25 ms): it resumes with those, and any other is a change.
    #[test]
    fn a_run_recorded_before_the_step_settings_had_the_old_step() {
        let mut velocity = config(Some(Stepper::Velocity));
        velocity.step_travel_dp = 0.025;
        velocity.max_step_s = 1.25e-3;
        let mut old = serde_json::to_value(&velocity).unwrap();
        for key in ["step_travel_dp", "max_step_s"] {
            old.as_object_mut().unwrap().remove(key);
        }
        let old = old.to_string();
        assert!(resume_conflicts(&old, &velocity).is_empty());
        let mut halved = velocity.clone();
        halved.max_step_s = 6.25e-4;
        assert_eq!(resume_conflicts(&old, &halved), ["--max-step 0.00125 → 0.000625"]);
    }

    /// A run recorded before the substep scale was a setting ran the substep rule unscaled: it
    /// resumes with scale 1, and a halved substep is a change.
    #[test]
    fn a_run_recorded_before_the_substep_scale_had_the_whole_substep() {
        let force = config(Some(Stepper::Acceleration));
        let mut old = serde_json::to_value(&force).unwrap();
        old.as_object_mut().unwrap().remove("substep_scale");
        let old = old.to_string();
        assert!(resume_conflicts(&old, &force).is_empty());
        let halved = PackConfig { substep_scale: 0.5, ..force };
        assert_eq!(resume_conflicts(&old, &halved), ["--substep-scale 1 → 0.5"]);
    }

    /// The threads may change on resume (any number gives the same frames), also from a run
    /// recorded before they were a setting.
    #[test]
    fn a_run_resumes_on_any_number_of_threads() {
        let mut two = config(None);
        two.threads = 2;
        let recorded = serde_json::to_string(&two).unwrap();
        let mut old = serde_json::to_value(&two).unwrap();
        old.as_object_mut().unwrap().remove("threads");
        for threads in [1, 2, 7] {
            let now = PackConfig { threads, ..two.clone() };
            assert!(resume_conflicts(&recorded, &now).is_empty(), "{threads}");
            assert!(resume_conflicts(&old.to_string(), &now).is_empty(), "{threads}");
        }
    }

    /// The settings are named as the flags are typed, in the flags' units.
    #[test]
    fn differing_settings_read_as_flags_in_their_units() {
        let run = |o: PackOptions| PackConfig::resolve(&o).unwrap();
        let base = || PackOptions {
            pellet: Some("s.pellet".into()),
            tube_diameter: Some(30.0),
            count: Some(20),
            ..Default::default()
        };
        let old = serde_json::to_string(&run(base())).unwrap();
        let changed = run(PackOptions {
            count: Some(21),
            tube_diameter: Some(40.0),
            tilt: Some(30.0),
            record_velocities: Some(true),
            ..base()
        });
        let mut got = resume_conflicts(&old, &changed);
        got.sort();
        let want = ["--count 20 → 21", "--record-velocities off → on", "--tilt 45 → 30", "--tube-diameter 30 → 40"];
        assert_eq!(got, want);
        let filled = run(PackOptions { count: None, fill_height: Some(120.0), ..base() });
        assert_eq!(resume_conflicts(&old, &filled), ["--count 20 → --fill-height 120"]);
    }
}
