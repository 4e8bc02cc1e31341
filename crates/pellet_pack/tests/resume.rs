//! A run continued from a checkpoint equals the uninterrupted run: every frame and energy
//! record after the checkpoint, bit for bit, whether it continues from a checkpoint taken on
//! the way (a killed run) or from the one written at an interruption.

mod common;

use pellet_geom::{Pellet, Resolution, ShapeSpec};
use pellet_io::{EnergyRecord, Frame};
use pellet_pack::{resume_pack, run_pack, Checkpoint, Ending, PackConfig, RunSink, Stepper};

/// Records everything; asks to stop after `stop_after` energy records.
#[derive(Default)]
struct Recorder {
    frames: Vec<Frame>,
    energy: Vec<EnergyRecord>,
    checkpoints: Vec<(f64, Vec<u8>)>,
    stop_after: Option<usize>,
}

impl RunSink for Recorder {
    fn frame(&mut self, frame: &Frame) -> Result<(), String> {
        self.frames.push(frame.clone());
        Ok(())
    }
    fn energy(&mut self, record: &EnergyRecord) -> Result<(), String> {
        self.energy.push(record.clone());
        Ok(())
    }
    fn should_stop(&self) -> bool {
        self.stop_after.is_some_and(|n| self.energy.len() >= n)
    }
    fn checkpoint(&mut self, time_s: f64, bytes: &[u8]) -> Result<(), String> {
        self.checkpoints.push((time_s, bytes.to_vec()));
        Ok(())
    }
}

fn cylinder() -> Pellet {
    Pellet::build(ShapeSpec::Cylinder { diameter_mm: 10.0, height_mm: 10.0 }, Resolution::default()).unwrap()
}

fn config(max_time: f64) -> PackConfig {
    config_with(max_time, Stepper::Acceleration)
}

fn config_with(max_time: f64, stepper: Stepper) -> PackConfig {
    common::pack_config(30.0, 6, |o| {
        o.stepper = Some(stepper);
        o.max_time = Some(max_time);
        o.checkpoint_every = Some(0.1);
        o.record_every = Some(0.02);
    })
}

/// What `whole` recorded after time `t`: (frames at or after t, energy records after t).
fn after(whole: &Recorder, t: f64) -> (Vec<Frame>, Vec<EnergyRecord>) {
    (
        whole.frames.iter().filter(|f| f.time_s >= t).cloned().collect(),
        whole.energy.iter().filter(|e| e.time_s > t).cloned().collect(),
    )
}

/// The time limit of the run that is interrupted and resumed, s.
const LIMIT: f64 = 0.6;

#[test]
fn a_resumed_run_equals_the_uninterrupted_one() {
    resumed_equals_whole(Stepper::Acceleration);
}

/// The velocity-level stepper's checkpoints carry its warm impulses and pending approaches.
#[test]
fn a_resumed_run_equals_the_uninterrupted_one_velocity_stepper() {
    resumed_equals_whole(Stepper::Velocity);
}

fn resumed_equals_whole(stepper: Stepper) {
    let config = |t| config_with(t, stepper);
    let pellet = cylinder();
    let mut whole = Recorder::default();
    // The limit comes well before the bed settles (at 0.80 s; with the limit at 0.8 s
    // exactly it would settle on its last record).
    let summary = run_pack(&config(LIMIT), &pellet, &mut whole).unwrap();
    assert_eq!(summary.ending, Ending::TimeLimit);
    // Checkpoints every 0.1 s and one at the end.
    assert!(whole.checkpoints.len() >= 6, "{} checkpoints", whole.checkpoints.len());

    // Killed at 0.35 s: go on from the last checkpoint it wrote on the way (at 0.3 s).
    let mut first = Recorder { stop_after: Some(70), ..Recorder::default() };
    assert_eq!(run_pack(&config(LIMIT), &pellet, &mut first).unwrap().ending, Ending::Interrupted);
    let (t, bytes) = first.checkpoints.iter().rev().nth(1).expect("a checkpoint on the way").clone();
    assert!((t - 0.3).abs() < 1e-9, "checkpoint at {t}");
    let checkpoint = Checkpoint::decode(&bytes, "test").unwrap();
    assert_eq!(checkpoint.run.ending, None);
    assert!(checkpoint.world.bodies.len() >= 2, "pellets in the tube by then");
    let mut rest = Recorder::default();
    assert_eq!(key(&resume_pack(&config(LIMIT), &pellet, &mut rest, Some(checkpoint)).unwrap()), key(&summary));
    let (frames, energy) = after(&whole, t);
    assert_eq!(rest.frames, frames);
    assert_eq!(rest.energy, energy);

    // Interrupted: go on from the checkpoint written at the end, to the same limit.
    let (t_end, bytes) = first.checkpoints.last().unwrap().clone();
    let checkpoint = Checkpoint::decode(&bytes, "test").unwrap();
    assert_eq!(checkpoint.run.ending, Some(Ending::Interrupted));
    let mut rest = Recorder::default();
    resume_pack(&config(LIMIT), &pellet, &mut rest, Some(checkpoint)).unwrap();
    let (frames, energy) = after(&whole, t_end);
    assert_eq!(rest.frames, frames);
    assert_eq!(rest.energy, energy);
    assert_eq!(rest.checkpoints.last().map(|c| c.0), whole.checkpoints.last().map(|c| c.0));
}

/// A bed at rest carries its contacts from step to step, so a checkpoint's contact manifolds
/// decide the steps after it: resumed with them the run is the uninterrupted one, without them
/// it is not.
#[test]
fn a_resumed_run_carries_the_contact_manifolds() {
    let config = common::pack_config(30.0, 8, |o| {
        o.scheme = Some(pellet_pack::LoadingScheme::Batch);
        o.stepper = Some(Stepper::Velocity);
        o.max_time = Some(2.0);
        o.checkpoint_every = Some(0.1);
        o.record_every = Some(0.02);
    });
    let pellet = cylinder();
    let mut whole = Recorder::default();
    let summary = run_pack(&config, &pellet, &mut whole).unwrap();
    assert_eq!(summary.ending, Ending::Settled);
    // The last checkpoint on the way, when the bed is at rest or nearly.
    let (t, bytes) = whole.checkpoints.iter().rev().nth(1).expect("a checkpoint on the way").clone();
    let checkpoint = Checkpoint::decode(&bytes, "test").unwrap();
    assert!(!checkpoint.manifolds.is_empty());
    let (frames, energy) = after(&whole, t);
    assert!(frames.len() >= 2, "frames after the checkpoint at {t} s");
    let mut rest = Recorder::default();
    resume_pack(&config, &pellet, &mut rest, Some(checkpoint.clone())).unwrap();
    assert_eq!(rest.frames, frames);
    assert_eq!(rest.energy, energy);
    let mut forgetful = Recorder::default();
    resume_pack(&config, &pellet, &mut forgetful, Some(Checkpoint { manifolds: Vec::new(), ..checkpoint })).unwrap();
    assert_ne!(forgetful.frames, frames, "the manifolds made no difference: the test shows nothing");
}

fn key(s: &pellet_pack::RunSummary) -> (Ending, f64, u32, f64, u64) {
    (s.ending.clone(), s.time_s, s.pellets, s.max_penetration_m, s.substeps)
}

/// A checkpoint of another layout version is refused with a message that says what to do.
#[test]
fn another_checkpoint_version_is_refused() {
    let mut whole = Recorder::default();
    run_pack(&config(0.15), &cylinder(), &mut whole).unwrap();
    let mut bytes = whole.checkpoints.last().unwrap().1.clone();
    bytes[0] = bytes[0].wrapping_add(1);
    let e = Checkpoint::decode(&bytes, "x.mcap").unwrap_err().to_string();
    assert!(e.contains("checkpoint version") && e.contains("without --resume"), "{e}");
}

/// An older checkpoint layout: the current fields up to the warm impulses, in their own form.
#[derive(serde::Serialize)]
struct OldLayout<'a, I> {
    version: u32,
    world: &'a pellet_sim::WorldState,
    warm: &'a [pellet_sim::WarmForce],
    feeder: &'a pellet_pack::FeederState,
    run: &'a pellet_pack::RunState,
    impulses: I,
}

impl<'a, I: serde::Serialize> OldLayout<'a, I> {
    fn of(version: u32, now: &'a Checkpoint, impulses: I) -> Self {
        Self { version, world: &now.world, warm: &now.warm, feeder: &now.feeder, run: &now.run, impulses }
    }

    fn read(&self) -> Checkpoint {
        Checkpoint::decode(&pellet_io::encode_message(self).unwrap(), "x.mcap").unwrap()
    }
}

/// The last checkpoint of a 6-cylinder bed poured for 0.6 s with the velocity-level stepper.
fn velocity_checkpoint() -> Checkpoint {
    let mut whole = Recorder::default();
    run_pack(&config_with(0.6, Stepper::Velocity), &cylinder(), &mut whole).unwrap();
    Checkpoint::decode(&whole.checkpoints.last().unwrap().1, "x.mcap").unwrap()
}

/// A checkpoint of layout 2, whose warm impulses had no patch torques, is read with every
/// torque zero and everything else as written.
#[test]
fn a_layout_2_checkpoint_is_read_with_no_torques() {
    #[derive(serde::Serialize)]
    struct Impulse {
        key: pellet_sim::ContactKey,
        normal: f64,
        friction: pellet_sim::Vec3,
        approach: f64,
    }
    let now = velocity_checkpoint();
    assert!(now.impulses.iter().any(|w| w.torque != pellet_sim::Vec3::zeros()), "no patch torque to drop");
    let impulses: Vec<Impulse> = now
        .impulses
        .iter()
        .map(|w| Impulse { key: w.key, normal: w.normal, friction: w.friction, approach: w.approach })
        .collect();
    let read = OldLayout::of(2, &now, impulses).read();
    let mut want = now.clone();
    for w in &mut want.impulses {
        w.torque = pellet_sim::Vec3::zeros();
    }
    want.manifolds.clear();
    assert_eq!(read, want);
}

/// A checkpoint of layout 3, written before contact manifolds were kept, is read with none
/// and everything else as written; a run resumed from it finds every contact afresh and goes
/// on.
#[test]
fn a_layout_3_checkpoint_is_read_without_manifolds() {
    let now = velocity_checkpoint();
    assert!(!now.manifolds.is_empty(), "a cylinder bed in contact keeps manifolds");
    let read = OldLayout::of(3, &now, &now.impulses).read();
    let mut want = now.clone();
    want.manifolds.clear();
    assert_eq!(read, want);
    let mut rest = Recorder::default();
    let s = resume_pack(&config_with(0.8, Stepper::Velocity), &cylinder(), &mut rest, Some(read)).unwrap();
    // The checkpoint is at 0.6 s; the run goes on, to its limit or until it settles.
    assert!(rest.frames.last().is_some_and(|f| f.time_s > 0.61), "the run did not go on from its checkpoint");
    assert!(s.ending == Ending::Settled || s.time_s > 0.79, "{:?} at {} s", s.ending, s.time_s);
}
