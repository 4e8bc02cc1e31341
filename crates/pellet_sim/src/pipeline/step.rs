//! One call of [`World::step`], whichever stepper takes it (`docs/engine.md`, "Time
//! stepping"): the entry point that picks the stepper and closes the step's energy account, the
//! buffers and warm starts carried from one step to the next ([`Pipeline`]), the report, and
//! what both steppers' substeps do alike (free flight, the narrow phase's view of a body).

use super::ledger::EnergyLedger;
use super::world::World;
use crate::body::Body;
use crate::dynamics::integrator::advance;
use crate::error::SimError;
use crate::geometry::contact::{Contact, ContactKey};
use crate::geometry::manifold::{Manifold, Manifolds};
use crate::geometry::narrow_phase::Pellet;
use crate::geometry::pair_cache::PairCache;
use crate::geometry::sample_cache::SampleCache;
use crate::math::{Real, Vec3};
use crate::params::Stepper;
use crate::team::Team;
use serde::{Deserialize, Serialize};

/// One contact of the last committed substep, with the forces the resting phase gave it.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactRecord {
    /// The contact geometry.
    pub contact: Contact,
    /// Normal force from the resting phase, N (0 if the contact was not resting).
    pub normal_force: Real,
    /// Friction force on body A from the resting phase, N.
    pub friction_force: Vec3,
}

/// Scratch buffers and caches reused across steps. Not part of the simulation state.
#[derive(Debug, Default, Clone)]
pub struct Pipeline {
    pub(super) broad: PairCache,
    pub(super) samples: SampleCache,
    /// Last substep's resting forces, sorted by contact key: the warm start of the next
    /// resting phase.
    pub(super) warm: Vec<WarmForce>,
    /// The velocity-level stepper's impulses of the last step, sorted by key.
    pub(super) impulses: Vec<WarmImpulse>,
    /// The velocity-level stepper's contact manifolds of the last step, by pair: they decide
    /// which contacts the next step carries instead of finding again, so a checkpoint carries
    /// them.
    pub(super) manifolds: Manifolds,
    pub(super) saved: Vec<Body>,
    /// The last committed substep's contacts and their resting forces (normal, friction),
    /// kept as the substep left them; `last_contacts` pairs them up when asked (building the
    /// records every substep moved ~0.4 MB per substep of a 690-sphere bed for nobody).
    last: Vec<Contact>,
    last_forces: (Vec<Real>, Vec<Vec3>),
    last_records: std::cell::OnceCell<Vec<ContactRecord>>,
    /// The step's threads (one: the calling thread alone); any number gives the same step bit
    /// for bit (`threads`, `team`).
    pub(super) team: Team,
}

/// A resting force of the last committed substep, kept by contact key as the next resting
/// phase's warm start. It shapes the next answer (the solvers stop at a tolerance), so a
/// checkpoint carries it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct WarmForce {
    /// The contact.
    pub key: ContactKey,
    /// Normal force, N.
    pub normal: Real,
    /// Friction force on body A (world), N.
    pub friction: Vec3,
}

/// A contact's impulses of the last committed step, kept by key: the warm start of the next
/// step's solve, as forces (impulse / h) so that a step of another length starts from the
/// same forces. A checkpoint carries them (they shape the next answer).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct WarmImpulse {
    /// The contact.
    pub key: ContactKey,
    /// Normal impulse over the step length, N.
    pub normal: Real,
    /// Friction impulse on body A over the step length, world frame, N.
    pub friction: Vec3,
    /// Angular impulse of the contact's patch on body A over the step length, world frame,
    /// N·m.
    pub torque: Vec3,
    /// The relative normal velocity (m/s, < 0) with which the contact was closing when the
    /// last step stopped it at the touching gap; 0 if it was not. The next step's restitution
    /// acts on this speed, as the impact happened at the end of that step.
    pub approach: Real,
}

impl Pipeline {
    /// Empty pipeline.
    pub fn new() -> Self {
        Self::default()
    }

    /// Collide the near pairs and walls of each step, and sweep the velocity-level stepper's
    /// impulse solve, on `threads` threads (0 or 1: the calling thread alone). The results do
    /// not depend on it: the contacts are the serial loop's and the solve's answer the same,
    /// bit for bit.
    pub fn set_threads(&mut self, threads: usize) {
        if threads.max(1) != self.team.threads() {
            self.team = Team::new(threads);
        }
    }

    /// `self` with [`Self::set_threads`].
    pub fn with_threads(mut self, threads: usize) -> Self {
        self.set_threads(threads);
        self
    }

    /// The step's threads (at least 1: set to 0 or 1, the calling thread alone).
    pub fn threads(&self) -> usize {
        self.team.threads()
    }

    /// The warm forces the next step starts from, in key order.
    pub fn warm_forces(&self) -> Vec<WarmForce> {
        self.warm.clone()
    }

    /// A pipeline that starts from `forces` (as returned by [`Self::warm_forces`]).
    pub fn with_warm_forces(forces: &[WarmForce]) -> Self {
        let mut warm = forces.to_vec();
        warm.sort_by_key(|w| w.key);
        Self { warm, ..Self::default() }
    }

    /// The velocity-level stepper's warm impulses, in key order (empty for the other stepper).
    pub fn warm_impulses(&self) -> Vec<WarmImpulse> {
        self.impulses.clone()
    }

    /// A pipeline that starts from `forces` and `impulses` (as returned by
    /// [`Self::warm_forces`] and [`Self::warm_impulses`]).
    pub fn with_warm_state(forces: &[WarmForce], impulses: &[WarmImpulse]) -> Self {
        let mut p = Self::with_warm_forces(forces);
        p.impulses = impulses.to_vec();
        p.impulses.sort_by_key(|w| w.key);
        p
    }

    /// The velocity-level stepper's contact manifolds, sorted by pair (empty for the other
    /// stepper).
    pub fn manifolds(&self) -> Vec<Manifold> {
        self.manifolds.as_slice().to_vec()
    }

    /// `self` with the contact manifolds `manifolds` (as returned by [`Self::manifolds`]).
    pub fn with_manifolds(mut self, manifolds: Vec<Manifold>) -> Self {
        self.manifolds = Manifolds::from_unsorted(manifolds);
        self
    }

    /// The contacts of the last committed substep.
    pub fn last_contacts(&self) -> &[ContactRecord] {
        self.last_records.get_or_init(|| {
            let (normal, friction) = &self.last_forces;
            self.last
                .iter()
                .zip(normal.iter().zip(friction))
                .map(|(c, (&normal_force, &friction_force))| ContactRecord {
                    contact: c.clone(),
                    normal_force,
                    friction_force,
                })
                .collect()
        })
    }

    pub(super) fn set_last_contacts(&mut self, contacts: Vec<Contact>, normal: Vec<Real>, friction: Vec<Vec3>) {
        self.last = contacts;
        self.last_forces = (normal, friction);
        self.last_records.take();
    }
}

/// What one call of [`World::step`] did.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct StepReport {
    /// Contact substeps taken.
    pub substeps: u32,
    /// Free-flight segments taken.
    pub free_flights: u32,
    /// Substeps redone with a halved δt.
    pub rewinds: u32,
    /// Rotation sub-steps of the integrator (all bodies).
    pub rotation_substeps: u64,
    /// Smallest and largest substep, s.
    pub dt_min: Real,
    /// Largest substep, s.
    pub dt_max: Real,
    /// Contact points seen, summed over substeps.
    pub contacts: u64,
    /// Colliding contacts, summed over substeps.
    pub colliding: u64,
    /// Resting contacts, summed over substeps.
    pub resting: u64,
    /// Collision passes, summed.
    pub collision_passes: u64,
    /// Point impulses applied, summed.
    pub impulses: u64,
    /// Final e = 0 solves.
    pub final_solves: u32,
    /// Friction impulses dropped by the energy guard.
    pub guard_events: u32,
    /// Dynamic resting-friction forces dropped by the coupled energy guard.
    pub friction_guard_drops: u32,
    /// LCP iterations / pivots, summed.
    pub solver_iterations: u64,
    /// Worst resting-solver residual, m/s².
    pub solver_residual: Real,
    /// Worst resting-solver residual of the islands solved to the engine's tolerance (all but
    /// islands in motion; `RestingStats::residual_tight`), m/s².
    pub solver_residual_tight: Real,
    /// Resting islands whose solver did not converge.
    pub unconverged_islands: u32,
    /// Velocity-level stepper: contacts that carried load (a normal impulse), summed over
    /// steps.
    pub loaded_contacts: u64,
    /// Velocity-level stepper: of `loaded_contacts`, those warm started from a loaded contact
    /// of the same key in the step before.
    pub loaded_warm: u64,
    /// Velocity-level stepper: bodies and walls in contact (pairs with at least one contact
    /// point), summed over steps: `contacts / contact_pairs` is the points per pair.
    pub contact_pairs: u64,
    /// Largest island, rows.
    pub largest_island: usize,
    /// Largest penetration before projection, m.
    pub max_penetration: Real,
    /// Largest penetration after projection, m.
    pub max_penetration_after_projection: Real,
    /// Energies at the end and dissipation during this step.
    pub energy: EnergyLedger,
    /// Wall-clock seconds spent in (narrow phase, collision phase, resting phase, projection),
    /// rewound substeps included. For profiling only; never feeds back into the physics.
    pub wall_seconds: [Real; 4],
}

impl World {
    /// Advances the world by `dt_big` seconds (any number of internal substeps).
    pub fn step(&mut self, dt_big: Real, pipeline: &mut Pipeline) -> Result<StepReport, SimError> {
        if !(dt_big.is_finite() && dt_big >= 0.0) {
            return Err(SimError::InvalidParameter {
                name: "dt_big",
                value: dt_big,
                reason: "must be finite and >= 0",
            });
        }
        self.geometry.sync(&self.types);
        let mut report = StepReport { dt_min: Real::INFINITY, ..StepReport::default() };
        let t_end = self.time + dt_big;
        match self.params.stepper {
            Stepper::Acceleration => self.step_acceleration(t_end, pipeline, &mut report)?,
            Stepper::Velocity => self.step_velocity(t_end, pipeline, &mut report)?,
        }
        self.time = t_end;
        report.energy.kinetic_translational = self.bodies.iter().map(Body::kinetic_translational).sum();
        report.energy.kinetic_rotational = self.bodies.iter().map(Body::kinetic_rotational).sum();
        report.energy.potential = self.potential_energy();
        self.totals.accumulate(&report.energy);
        if report.dt_min == Real::INFINITY {
            report.dt_min = 0.0;
        }
        Ok(report)
    }

    pub(super) fn free_flight(&mut self, dt: Real, report: &mut StepReport) {
        let g = self.params.gravity;
        let max_rot = self.params.max_rotation_per_substep;
        for b in &mut self.bodies {
            let f = g * b.mass;
            report.rotation_substeps += advance(b, &f, &Vec3::zeros(), dt, max_rot) as u64;
        }
    }

    pub(super) fn pellet<'a>(&'a self, bodies: &'a [Body], index: usize, ty: usize) -> Pellet<'a> {
        Pellet { index, body: &bodies[index], shape: &self.types[ty].shape, geom: &self.geometry.types[ty] }
    }
}
