//! The pack run: feed pellets into the engine's tube, step it, stream
//! frames and energy records to a sink, stop when the bed is settled.
//!
//! This module does no I/O: the `pack` tool supplies a [`RunSink`] that
//! writes the MCAP trajectory and draws the progress bar.

use pellet_geom::Pellet;
use pellet_io::{EnergyRecord, Frame};
use pellet_settle::{check_settled, EnergySample, SettleCriteria, SettleReport};
use pellet_sim::{Pipeline, Vec3, World};

use serde::{Deserialize, Serialize};

use crate::checkpoint::{Checkpoint, RunState, CHECKPOINT_VERSION};
use crate::config::{Amount, PackConfig};
use crate::loading::{FeedParams, Feeder, LoadingScheme};

pub use crate::setup::{
    body_type, check_setup, engine_params, mesh_shape, narrowest_tube_radius, new_world, MAX_MESH_SAMPLES,
    SDF_GRID_NODES_PER_DIAMETER,
};

/// Length of one engine step (s): the energy channel gets a record per
/// step, so this is also its time resolution. The engine sub-steps inside.
pub const STEP_S: f64 = 0.005;

/// A pellet slower than this (m/s) for at least [`RESTING_TIME`] counts as
/// part of the bed when the bed surface is measured. The time keeps a pellet
/// just released, or at the top of a bounce, out of it.
const RESTING_SPEED: f64 = 0.05;
/// See [`RESTING_SPEED`] (s).
const RESTING_TIME: f64 = 0.05;

/// Where the run's output goes.
pub trait RunSink {
    /// A recorded pose frame.
    fn frame(&mut self, frame: &Frame) -> Result<(), String>;
    /// The energy record of one step.
    fn energy(&mut self, record: &EnergyRecord) -> Result<(), String>;
    /// Progress, after each step.
    fn progress(&mut self, _progress: &Progress) {}
    /// Whether the user asked to stop (Ctrl-C).
    fn should_stop(&self) -> bool {
        false
    }
    /// A checkpoint taken at simulated time `time_s` (s): bytes of a [`Checkpoint`].
    fn checkpoint(&mut self, _time_s: f64, _bytes: &[u8]) -> Result<(), String> {
        Ok(())
    }
}

/// Progress of a run.
#[derive(Clone, Copy, Debug)]
pub struct Progress {
    /// Simulated time (s).
    pub time_s: f64,
    /// Pellets in the tube.
    pub pellets: u32,
    /// Pellets to load (`None` when filling to a height).
    pub target: Option<u32>,
    /// Kinetic energy (J).
    pub kinetic_j: f64,
    /// Height of the bed surface (m).
    pub bed_top_m: f64,
}

/// How a run ended.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Ending {
    /// The settle test passed.
    Settled,
    /// The time limit was reached first.
    TimeLimit,
    /// The sink asked to stop.
    Interrupted,
}

/// What a run did.
#[derive(Clone, Debug)]
pub struct RunSummary {
    /// How it ended.
    pub ending: Ending,
    /// Final simulated time (s).
    pub time_s: f64,
    /// Pellets loaded.
    pub pellets: u32,
    /// The settle test's verdict at the end.
    pub settle: SettleReport,
    /// Largest penetration seen (m): the deepest a step's motion took a contact before
    /// position projection.
    pub max_penetration_m: f64,
    /// The deepest penetration left after the last step (m), the bed's as written.
    pub end_penetration_m: f64,
    /// Engine substeps taken.
    pub substeps: u64,
    /// The contact solve over the last `SOLVER_WINDOW_S` simulated (of the part of the run
    /// this call made).
    pub solver: SolverStats,
}

/// How the contact solve fared over a stretch of a run (velocity-level stepper; zeros for the
/// force-level one, which counts none of these).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SolverStats {
    /// Engine steps.
    pub steps: u64,
    /// Steps whose solve ended unconverged.
    pub unconverged: u64,
    /// Contact points, summed over steps.
    pub contacts: u64,
    /// Pairs (pellet–pellet or pellet–wall) with contact points, summed over steps.
    pub pairs: u64,
    /// Contacts that carried load, summed over steps.
    pub loaded: u64,
    /// Of those, the ones warm started from the step before.
    pub loaded_warm: u64,
}

impl SolverStats {
    fn add(&mut self, o: &SolverStats) {
        self.steps += o.steps;
        self.unconverged += o.unconverged;
        self.contacts += o.contacts;
        self.pairs += o.pairs;
        self.loaded += o.loaded;
        self.loaded_warm += o.loaded_warm;
    }

    /// Contact points per pair in contact.
    pub fn contacts_per_pair(&self) -> f64 {
        self.contacts as f64 / self.pairs.max(1) as f64
    }

    /// Fraction of the loaded contacts that were warm started.
    pub fn warm_start_rate(&self) -> f64 {
        self.loaded_warm as f64 / self.loaded.max(1) as f64
    }

    /// Fraction of the steps whose solve converged.
    pub fn converged_rate(&self) -> f64 {
        1.0 - self.unconverged as f64 / self.steps.max(1) as f64
    }
}

/// The stretch of simulated time at the end of a run that [`RunSummary::solver`] covers, s:
/// the bed at rest, where every loaded contact should be warm started.
pub const SOLVER_WINDOW_S: f64 = 0.1;

/// A run that cannot start or failed.
#[derive(Debug, thiserror::Error)]
pub enum PackError {
    /// The pellet or the configuration does not fit the engine.
    #[error("{0}")]
    Setup(String),
    /// The engine failed.
    #[error("engine error at t = {time_s:.4} s: {message}")]
    Engine {
        /// Simulated time.
        time_s: f64,
        /// What went wrong.
        message: String,
    },
    /// The sink failed (e.g. the disk is full).
    #[error("{0}")]
    Sink(String),
}

/// Runs a pack from the start.
pub fn run_pack(config: &PackConfig, pellet: &Pellet, sink: &mut impl RunSink) -> Result<RunSummary, PackError> {
    resume_pack(config, pellet, sink, None)
}

/// Runs a pack from the start, or continues one from a [`Checkpoint`] of a run with the same
/// configuration (see [`crate::checkpoint::resume_conflicts`]) and pellet: then the sink gets
/// what the uninterrupted run would have written after the checkpoint, bit for bit.
pub fn resume_pack(
    config: &PackConfig,
    pellet: &Pellet,
    sink: &mut impl RunSink,
    from: Option<Checkpoint>,
) -> Result<RunSummary, PackError> {
    let (mut world, type_id) = new_world(config, pellet)?;
    let tube_radius = 0.5 * config.tube_diameter_m;
    let dp = pellet.properties.equivalent_diameter;
    let r_b = pellet.bounding_radius;
    let mut feeder = Feeder::new(
        FeedParams {
            scheme: config.scheme,
            tilt: config.tilt_rad,
            position_jitter: config.position_jitter_dp * dp,
            angle_jitter: config.angle_jitter_rad,
            drop_height: config.drop_height_m.max(1.05 * r_b),
            release_height: config.release_height_m,
            tube_radius,
            bounding_radius: r_b,
        },
        config.seed,
    );
    let target = match config.amount {
        Amount::Count(n) => Some(n),
        Amount::FillHeight(_) => None,
    };
    let mass = config.density_kg_m3 * pellet.properties.volume;
    let spheres = pellet.is_sphere();
    let mut pipeline = Pipeline::new().with_threads(config.threads as usize);
    let mut run = RunState {
        feeding: true,
        next_entry: 0.0,
        next_frame: 0.0,
        next_checkpoint: config.checkpoint_every_s,
        max_penetration: 0.0,
        substeps: 0,
        history: Vec::new(),
        slow_since: Vec::new(),
        ending: None,
    };
    match from {
        Some(c) => {
            let time_s = c.time_s();
            world.restore(c.world).map_err(|e| PackError::Engine { time_s, message: e.to_string() })?;
            pipeline = Pipeline::with_warm_state(&c.warm, &c.impulses)
                .with_manifolds(c.manifolds)
                .with_threads(config.threads as usize);
            feeder.set_state(c.feeder);
            run = RunState { ending: None, ..c.run };
        }
        None => {
            // The batch scheme places every pellet at t = 0 (config.rs requires a count for it).
            if let (LoadingScheme::Batch, Amount::Count(n)) = (config.scheme, config.amount) {
                for spawn in feeder.batch(n) {
                    world
                        .add_body(type_id, spawn.position, spawn.orientation, Vec3::zeros(), Vec3::zeros())
                        .map_err(|e| PackError::Engine { time_s: 0.0, message: e.to_string() })?;
                }
                run.feeding = false;
            }
        }
    }
    let mut settle = check_settled(&[], &criteria(config, 0, mass, dp, spheres));
    let checkpoint = |world: &World, pipeline: &Pipeline, feeder: &Feeder, run: &RunState| Checkpoint {
        version: CHECKPOINT_VERSION,
        world: world.state(),
        warm: pipeline.warm_forces(),
        feeder: feeder.state(),
        run: run.clone(),
        impulses: pipeline.warm_impulses(),
        manifolds: pipeline.manifolds(),
    };
    let mut recent: std::collections::VecDeque<(f64, SolverStats)> = Default::default();
    let mut end_penetration: f64;
    let ending = loop {
        let t = world.time();
        if config.checkpoint_every_s > 0.0 && t + 1e-12 >= run.next_checkpoint {
            while run.next_checkpoint <= t + 1e-12 {
                run.next_checkpoint += config.checkpoint_every_s;
            }
            let c = checkpoint(&world, &pipeline, &feeder, &run);
            sink.checkpoint(t, &c.encode()?).map_err(PackError::Sink)?;
        }
        let top = bed_top(&world, &run.slow_since);
        // Feed: one pellet at a time, once the entry point is clear.
        if run.feeding {
            let full = match config.amount {
                Amount::Count(n) => world.bodies().len() as u32 >= n,
                Amount::FillHeight(h) => top >= h,
            };
            if full {
                run.feeding = false;
            } else if t >= run.next_entry {
                let spawn = feeder.next(top);
                if entry_is_clear(&world, &spawn.position, r_b) {
                    world
                        .add_body(type_id, spawn.position, spawn.orientation, Vec3::zeros(), Vec3::zeros())
                        .map_err(|e| PackError::Engine { time_s: t, message: e.to_string() })?;
                    run.next_entry = t + config.spacing_s;
                }
            }
        }
        if t + 1e-12 >= run.next_frame {
            sink.frame(&frame(&world, config.record_velocities)).map_err(PackError::Sink)?;
            run.next_frame += config.record_every_s;
        }
        let report = world
            .step(STEP_S, &mut pipeline)
            .map_err(|e| PackError::Engine { time_s: world.time(), message: e.to_string() })?;
        recent.push_back((
            world.time(),
            SolverStats {
                steps: report.substeps as u64,
                unconverged: report.unconverged_islands as u64,
                contacts: report.contacts,
                pairs: report.contact_pairs,
                loaded: report.loaded_contacts,
                loaded_warm: report.loaded_warm,
            },
        ));
        while recent.front().is_some_and(|(t, _)| *t < world.time() - SOLVER_WINDOW_S + 1e-9) {
            recent.pop_front();
        }
        run.max_penetration = run.max_penetration.max(report.max_penetration);
        end_penetration = report.max_penetration_after_projection;
        run.substeps += report.substeps as u64;
        let ledger = world.energy();
        let max_speed = world.bodies().iter().map(|b| b.velocity().norm()).fold(0.0, f64::max);
        run.slow_since.resize(world.bodies().len(), None);
        for (since, body) in run.slow_since.iter_mut().zip(world.bodies()) {
            *since = if body.velocity().norm() < RESTING_SPEED { since.or(Some(world.time())) } else { None };
        }
        let record = EnergyRecord {
            time_s: world.time(),
            pellets: world.bodies().len() as u32,
            kinetic_translational_j: ledger.kinetic_translational,
            kinetic_rotational_j: ledger.kinetic_rotational,
            potential_j: ledger.potential,
            dissipated_collisions_j: ledger.removed_by_collisions,
            dissipated_friction_j: ledger.removed_by_friction,
            projection_j: ledger.removed_by_projection,
            colliding_contacts: report.colliding.min(u32::MAX as u64) as u32,
            resting_contacts: report.resting.min(u32::MAX as u64) as u32,
            substeps: report.substeps,
            solver_residual: report.solver_residual,
            solver_iterations: report.solver_iterations.min(u32::MAX as u64) as u32,
            max_penetration_m: report.max_penetration_after_projection,
            max_speed_m_s: max_speed,
        };
        sink.energy(&record).map_err(PackError::Sink)?;
        run.history.push(EnergySample {
            time_s: record.time_s,
            kinetic_j: record.kinetic_j(),
            kinetic_translational_j: record.kinetic_translational_j,
            max_speed_m_s: max_speed,
            pellets: record.pellets,
        });
        // Only the recent past matters to the test: keep its cost and the checkpoints flat.
        let from = run.history.partition_point(|s| s.time_s < record.time_s - 2.0 * config.settle_window_s);
        run.history.drain(..from);
        sink.progress(&Progress {
            time_s: record.time_s,
            pellets: record.pellets,
            target,
            kinetic_j: record.kinetic_j(),
            bed_top_m: top,
        });
        if !run.feeding {
            settle = check_settled(&run.history, &criteria(config, record.pellets, mass, dp, spheres));
            if settle.settled {
                break Ending::Settled;
            }
        }
        if world.time() >= config.max_time_s {
            break Ending::TimeLimit;
        }
        if sink.should_stop() {
            break Ending::Interrupted;
        }
    };
    // The state at the end, to go on from (a longer --max-time, an interrupted run).
    run.ending = Some(ending.clone());
    let c = checkpoint(&world, &pipeline, &feeder, &run);
    sink.checkpoint(world.time(), &c.encode()?).map_err(PackError::Sink)?;
    sink.frame(&frame(&world, config.record_velocities)).map_err(PackError::Sink)?;
    Ok(RunSummary {
        ending,
        time_s: world.time(),
        pellets: world.bodies().len() as u32,
        settle,
        max_penetration_m: run.max_penetration,
        end_penetration_m: end_penetration,
        substeps: run.substeps,
        solver: recent.iter().fold(SolverStats::default(), |mut a, (_, s)| {
            a.add(s);
            a
        }),
    })
}

fn criteria(config: &PackConfig, pellets: u32, mass: f64, dp: f64, spheres: bool) -> SettleCriteria {
    let mut c = SettleCriteria::recommended(pellets, mass, dp);
    c.window_s = config.settle_window_s;
    c.relative_tolerance = config.settle_tolerance;
    c.max_speed_m_s = config.max_speed_m_s;
    c.spheres = spheres;
    c
}

/// The bed surface: the highest top of a pellet that has been slow for a
/// while, or the floor.
fn bed_top(world: &World, slow_since: &[Option<f64>]) -> f64 {
    let settled_before = world.time() - RESTING_TIME;
    world
        .bodies()
        .iter()
        .zip(slow_since)
        .filter(|(_, since)| since.is_some_and(|t| t <= settled_before))
        .map(|(b, _)| b.position.z + b.bounding_radius)
        .fold(0.0, f64::max)
}

/// No pellet's bounding sphere comes within the new pellet's.
fn entry_is_clear(world: &World, at: &Vec3, r_b: f64) -> bool {
    world.bodies().iter().all(|b| (b.position - at).norm() > b.bounding_radius + r_b)
}

fn frame(world: &World, velocities: bool) -> Frame {
    let bodies = world.bodies();
    Frame {
        time_s: world.time(),
        type_index: bodies.iter().map(|b| b.type_id.0).collect(),
        positions: bodies.iter().map(|b| [b.position.x, b.position.y, b.position.z]).collect(),
        orientations: bodies
            .iter()
            .map(|b| {
                let q = b.orientation.quaternion();
                [q.w, q.i, q.j, q.k]
            })
            .collect(),
        velocities: velocities.then(|| {
            bodies
                .iter()
                .map(|b| {
                    let (v, w) = (b.velocity(), b.angular_velocity());
                    [v.x, v.y, v.z, w.x, w.y, w.z]
                })
                .collect()
        }),
    }
}
