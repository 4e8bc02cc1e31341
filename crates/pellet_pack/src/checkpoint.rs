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
use pellet_sim::{WarmForce, WarmImpulse, WorldState};

use crate::config::PackConfig;
use crate::driver::{Ending, PackError};
use crate::loading::FeederState;

/// Version of the checkpoint layout. A reader accepts its own and version 1 (written before
/// the velocity-level stepper, whose impulses and integrator ledger it lacks).
pub const CHECKPOINT_VERSION: u32 = 2;

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
            1 => pellet_io::decode_message::<v1::Checkpoint>(bytes, path, "checkpoint")
                .map(v1::Checkpoint::upgrade)
                .map_err(|e| setup(e.to_string())),
            _ => Err(setup(format!(
                "{path}: checkpoint version {version}, this pack reads versions 1 and {CHECKPOINT_VERSION}; run without --resume"
            ))),
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
            }
        }
    }
}

/// Settings that may differ between a run and its continuation: where the pellet file is
/// (its bytes are compared instead), when to stop, how often to checkpoint, the viewer.
const MAY_CHANGE: [&str; 4] = ["pellet", "max_time_s", "checkpoint_every_s", "foxglove"];

/// The settings in which `config` differs from the run recorded with `recorded_json` (the
/// trajectory's `config` metadata), as "name: recorded → now"; empty if it may continue it.
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
            Some(v) => out.push(format!("{key}: {v} → {value}")),
            None => out.push(format!("{key}: (not recorded) → {value}")),
        }
    }
    for key in old.keys() {
        if !new.contains_key(key) && !MAY_CHANGE.contains(&key.as_str()) {
            out.push(format!("{key}: recorded but unknown to this pack"));
        }
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
        assert!(refused[0].starts_with("stepper:") && refused[0].contains("velocity"), "{refused:?}");
        let velocity = serde_json::to_string(&config(Some(Stepper::Velocity))).unwrap();
        assert!(resume_conflicts(&velocity, &config(Some(Stepper::Velocity))).is_empty());
        assert_eq!(resume_conflicts(&velocity, &config(Some(Stepper::Acceleration))).len(), 1);
    }
}
