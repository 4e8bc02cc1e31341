//! The force-level stepper's time-stepping skeleton (`docs/engine.md`, "Time stepping"): swept
//! broad phase, free flight when nothing is near, otherwise substeps of δt = min(0.2λ/v_max, cap,
//! time to the next proximity entry) with collision phase, resting phase, midpoint integration,
//! position projection and rewind-and-halve on excess penetration.

use super::ledger::EnergyLedger;
use super::proximity::Proximity;
use super::velocity_step::WarmImpulse;
use super::world::World;
use crate::body::Body;
use crate::container::Container;
use crate::dynamics::collide::collision_phase;
use crate::dynamics::integrator::advance;
use crate::dynamics::resting::resting_phase;
use crate::dynamics::rows::relative_velocity_from;
use crate::dynamics::stabilize::{project_positions, GapBounds, ProjectionStats};
use crate::error::SimError;
use crate::geometry::contact::{Contact, ContactKey, Counterpart};
use crate::geometry::contact_sampled::gap_jump;
use crate::geometry::narrow_phase::{collide_feature, collide_pair_cached, collide_wall, Pellet};
use crate::geometry::pair_cache::PairCache;
use crate::geometry::sample_cache::SampleCache;
use crate::geometry::samples::GeometryCache;
use crate::geometry::sdf::lipschitz;
use crate::math::{Real, Vec3};
use crate::params::Stepper;
use crate::shape::{BodyType, ShapeDesc};
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
    pub(crate) broad: PairCache,
    pub(crate) samples: SampleCache,
    /// Last substep's resting forces, sorted by contact key: the warm start of the next
    /// resting phase.
    warm: Vec<WarmForce>,
    /// The velocity-level stepper's impulses of the last step, sorted by key.
    pub(crate) impulses: Vec<WarmImpulse>,
    pub(crate) saved: Vec<Body>,
    /// The last committed substep's contacts and their resting forces (normal, friction),
    /// kept as the substep left them; `last_contacts` pairs them up when asked (building the
    /// records every substep moved ~0.4 MB per substep of a 690-sphere bed for nobody).
    last: Vec<Contact>,
    last_forces: (Vec<Real>, Vec<Vec3>),
    last_records: std::cell::OnceCell<Vec<ContactRecord>>,
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

impl Pipeline {
    /// Empty pipeline.
    pub fn new() -> Self {
        Self::default()
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

    pub(crate) fn set_last_contacts(&mut self, contacts: Vec<Contact>, normal: Vec<Real>, friction: Vec<Vec3>) {
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
    pub(crate) fn free_flight(&mut self, dt: Real, report: &mut StepReport) {
        let g = self.params.gravity;
        let max_rot = self.params.max_rotation_per_substep;
        for b in &mut self.bodies {
            let f = g * b.mass;
            report.rotation_substeps += advance(b, &f, &Vec3::zeros(), dt, max_rot) as u64;
        }
    }

    pub(crate) fn pellet<'a>(&'a self, bodies: &'a [Body], index: usize, ty: usize) -> Pellet<'a> {
        Pellet { index, body: &bodies[index], shape: &self.types[ty].shape, geom: &self.geometry.types[ty] }
    }

    /// The projection's bounds on how fast a gap can close (`GapBounds`): a point a gap is
    /// measured from or in lies within the two bodies' bounding radii of either centre (plus a
    /// gap of up to the largest radius, far above any contact's look-ahead). A sphere's turn
    /// changes none of its gaps (each is a function of its centre), so its lever is zero.
    pub fn gap_bounds(&self) -> GapBounds {
        let shape = |b: &Body| &self.types[b.type_id.0 as usize].shape;
        let radius = |b: &Body| self.types[b.type_id.0 as usize].bounding_radius_m;
        let r_max = self.bodies.iter().map(radius).fold(0.0, Real::max);
        let lean = self.params.stepper == Stepper::Velocity;
        let lever = |b: &Body| match shape(b) {
            ShapeDesc::Sphere { .. } => 0.0,
            _ => radius(b) + 2.0 * r_max,
        };
        GapBounds {
            lipschitz: self.types.iter().map(|t| lipschitz(&t.shape)).fold(1.0, Real::max),
            lever: self.bodies.iter().map(lever).collect(),
            jump: self.bodies.iter().map(|b| gap_jump(shape(b), radius(b), lean)).collect(),
        }
    }

    /// Position projection of the bodies, moved from `generated_at` where `contacts` were
    /// found (shared by both steppers), timed into `report`.
    pub(crate) fn project(
        &mut self,
        contacts: &[Contact],
        generated_at: &[Body],
        bounds: &GapBounds,
        slop: Real,
        report: &mut StepReport,
    ) -> ProjectionStats {
        let d = self.reference_size();
        let g = self.params.gravity;
        let (types, geometry, container) = (&self.types, &self.geometry, &self.container);
        let lean = self.params.stepper == Stepper::Velocity;
        let eval = |bodies: &[Body], c: &Contact| reevaluate(types, geometry, container, bodies, c, lean);
        let mut bodies = std::mem::take(&mut self.bodies);
        let clock = std::time::Instant::now();
        let proj = project_positions(&mut bodies, contacts, generated_at, &eval, bounds, slop, 0.01 * d, &g);
        report.wall_seconds[3] += clock.elapsed().as_secs_f64();
        self.bodies = bodies;
        proj
    }

    fn narrow_phase(&self, prox: &Proximity, max_gap: Real, cache: &mut SampleCache) -> Result<Vec<Contact>, SimError> {
        // Room for one contact per pair and wall (what sphere beds give) without regrowing, and
        // for other shapes a reduced patch of 4 per pair and 8 per wall (4 points on each of
        // the two rims that rest on the floor): growing it contact by contact (a copy of the
        // whole vector each time) was 2.2 % of a cylinder bed, and with room for one wall
        // contact only, its regrowth under the wall contacts was still 1.9 % of 20 cylinders.
        let spheres = self.types.iter().all(|t| matches!(t.shape, ShapeDesc::Sphere { .. }));
        let (per_pair, per_wall) = if spheres { (1, 1) } else { (4, 8) };
        let mut out = Vec::with_capacity(per_pair * prox.pairs.len() + per_wall * prox.walls.len());
        cache.next_round();
        for &(i, j) in &prox.pairs {
            let (ti, tj) = (self.bodies[i].type_id.0 as usize, self.bodies[j].type_id.0 as usize);
            let pa = self.pellet(&self.bodies, i, ti);
            let pb = self.pellet(&self.bodies, j, tj);
            collide_pair_cached(pa, pb, max_gap, cache, &mut out)?;
        }
        for &(k, wall) in &prox.walls {
            let t = self.bodies[k].type_id.0 as usize;
            let pa = self.pellet(&self.bodies, k, t);
            collide_wall(&self.container, wall, pa, max_gap, &mut out)?;
        }
        Ok(out)
    }

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
        if self.params.stepper == Stepper::Velocity {
            return self.step_velocity(dt_big, pipeline);
        }
        let mut report = StepReport { dt_min: Real::INFINITY, ..StepReport::default() };
        let t_end = self.time + dt_big;
        let cap = self.params.dt_cap;
        while t_end - self.time > 1e-14 * t_end.abs().max(1e-3) {
            let remaining = t_end - self.time;
            let mut broad = std::mem::take(&mut pipeline.broad);
            let mut prox = self.proximity(&mut broad, remaining.min(cap));
            if prox.pairs.is_empty() && prox.walls.is_empty() {
                prox = self.proximity(&mut broad, remaining);
            }
            pipeline.broad = broad;
            if prox.pairs.is_empty() && prox.walls.is_empty() {
                let dt = remaining.min(prox.t_safe);
                self.free_flight(dt, &mut report);
                report.free_flights += 1;
                self.time = if dt == remaining { t_end } else { self.time + dt };
                pipeline.set_last_contacts(Vec::new(), Vec::new(), Vec::new());
                continue;
            }
            let mut dt = remaining.min(cap).min(prox.t_safe);
            if prox.v_max > 0.0 {
                dt = dt.min(0.2 * self.lambda() / prox.v_max);
            }
            self.substep(dt, &prox, pipeline, &mut report)?;
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

    fn substep(
        &mut self,
        dt0: Real,
        prox: &Proximity,
        pipeline: &mut Pipeline,
        report: &mut StepReport,
    ) -> Result<(), SimError> {
        let d = self.reference_size();
        let delta_c = self.params.contact_distance_factor * d;
        let slop = self.params.slop_factor * d;
        let pen_max = self.params.max_penetration_factor * self.nominal_size();
        pipeline.saved.clone_from(&self.bodies);
        let bounds = self.gap_bounds();
        let mut dt = dt0;
        let mut rewinds = 0;
        loop {
            // Generate contacts a little ahead: up to the distance a pair can close in dt.
            let clock = std::time::Instant::now();
            let contacts = self.narrow_phase(prox, delta_c + prox.v_max * dt, &mut pipeline.samples)?;
            report.wall_seconds[0] += clock.elapsed().as_secs_f64();
            let (cor, mu): (Vec<Real>, Vec<Real>) = contacts
                .iter()
                .map(|c| match c.b {
                    Counterpart::Body(_) => (self.material.cor, self.material.friction),
                    Counterpart::Wall(_) => (self.wall_material.cor, self.wall_material.friction),
                })
                .unzip();
            let clock = std::time::Instant::now();
            let coll = collision_phase(&mut self.bodies, &contacts, &cor, &mu, &self.params, dt, delta_c);
            report.wall_seconds[1] += clock.elapsed().as_secs_f64();
            let clock = std::time::Instant::now();
            let warm = warm_starts(&pipeline.warm, &contacts);
            let (forces, rest) = resting_phase(&self.bodies, &contacts, &mu, &self.params, dt, delta_c, &warm);
            report.wall_seconds[2] += clock.elapsed().as_secs_f64();
            let g = self.params.gravity;
            let max_rot = self.params.max_rotation_per_substep;
            let mut rot_steps = 0u64;
            for (b, w) in self.bodies.iter_mut().zip(&forces.wrench) {
                let f = g * b.mass + w.0;
                rot_steps += advance(b, &f, &w.1, dt, max_rot) as u64;
            }
            // Work of the resting forces: force times the mean relative velocity over the
            // substep, exact for a constant force and a velocity that changes linearly (the start
            // velocity would count twice the energy a resting force takes out of a contact it
            // brings to rest, and the ledger would not close).
            let (mut friction_work, mut normal_work) = (0.0, 0.0);
            // Each body's ω = I⁻¹L once, not at every contact end (R I⁻¹ Rᵀ per call was 3 % of
            // a cylinder bed); the same arithmetic as `relative_velocity`, so the same bits. The
            // start velocities are the resting phase's own.
            let vel1: Vec<Vec3> = self.bodies.iter().map(Body::velocity).collect();
            let omega1: Vec<Vec3> = self.bodies.iter().map(Body::angular_velocity).collect();
            let u0 = &forces.relative_velocity;
            for (i, c) in contacts.iter().enumerate() {
                let (ff, fnormal) = (forces.friction[i], forces.normal[i]);
                if ff == Vec3::zeros() && fnormal == 0.0 {
                    continue;
                }
                let mean = 0.5 * (u0[i] + relative_velocity_from(c, &vel1, &omega1));
                friction_work += ff.dot(&mean) * dt;
                normal_work += fnormal * c.normal.dot(&mean) * dt;
            }
            let proj = self.project(&contacts, &pipeline.saved, &bounds, slop, report);
            if proj.max_penetration_before > pen_max && rewinds < self.params.max_rewinds {
                self.bodies.clone_from(&pipeline.saved);
                dt *= 0.5;
                rewinds += 1;
                report.rewinds += 1;
                continue;
            }
            if let Some(k) = self.bodies.iter().position(|b| !b.is_finite()) {
                return Err(SimError::NonFiniteState(k as u32));
            }
            report.rotation_substeps += rot_steps;
            report.substeps += 1;
            report.dt_min = report.dt_min.min(dt);
            report.dt_max = report.dt_max.max(dt);
            report.contacts += contacts.len() as u64;
            report.colliding += coll.colliding as u64;
            report.resting += rest.resting as u64;
            report.collision_passes += coll.passes as u64;
            report.impulses += coll.impulses as u64;
            report.final_solves += coll.final_solve as u32;
            report.guard_events += coll.guard_events;
            report.friction_guard_drops += rest.friction_dropped;
            report.solver_iterations += (coll.solver_iterations + rest.solver_iterations) as u64;
            report.solver_residual = report.solver_residual.max(rest.residual);
            report.solver_residual_tight = report.solver_residual_tight.max(rest.residual_tight);
            report.unconverged_islands += rest.unconverged as u32;
            report.largest_island = report.largest_island.max(rest.largest_island);
            report.max_penetration = report.max_penetration.max(proj.max_penetration_before);
            report.max_penetration_after_projection =
                report.max_penetration_after_projection.max(proj.max_penetration_after);
            let e = &mut report.energy;
            e.removed_by_collisions += coll.normal_loss;
            e.removed_by_friction += coll.friction_loss - friction_work;
            e.removed_by_projection -= proj.potential_change;
            e.resting_normal_work += normal_work;
            e.resting_work_bound += rest.normal_work_bound;
            pipeline.warm = contacts
                .iter()
                .enumerate()
                .filter(|&(i, _)| forces.normal[i] > 0.0)
                .map(|(i, c)| WarmForce { key: c.key, normal: forces.normal[i], friction: forces.friction[i] })
                .collect();
            pipeline.warm.sort_by_key(|w| w.key);
            pipeline.set_last_contacts(contacts, forces.normal, forces.friction);
            self.time += dt;
            return Ok(());
        }
    }
}

/// Each contact's warm start: the normal and friction force of the last substep's contact with
/// its key in `warm` (sorted by key, keys distinct), or zero. The contacts come in long runs of
/// increasing keys (pairs, then walls), so the search gallops on from the last key found: a
/// binary search per contact, with its branchy key comparisons, was 2.6 % of a 690-sphere bed.
fn warm_starts(warm: &[WarmForce], contacts: &[Contact]) -> Vec<(Real, Vec3)> {
    let mut pos = 0;
    contacts
        .iter()
        .map(|c| {
            let k = &c.key;
            pos = if pos < warm.len() && warm[pos].key < *k {
                // warm[pos] < k: widen [pos + 1, hi) until warm[hi] ≥ k, then bisect it.
                let (mut lo, mut step) = (pos + 1, 1);
                let mut hi = lo;
                while hi < warm.len() && warm[hi].key < *k {
                    lo = hi + 1;
                    hi = lo + step;
                    step *= 2;
                }
                let hi = hi.min(warm.len());
                lo + warm[lo..hi].partition_point(|w| w.key < *k)
            } else {
                warm[..pos.min(warm.len())].partition_point(|w| w.key < *k)
            };
            match warm.get(pos) {
                Some(w) if w.key == *k => (w.normal, w.friction),
                _ => (0.0, Vec3::zeros()),
            }
        })
        .collect()
}

/// Re-evaluates one contact's feature at the given poses (the narrow phase for that feature).
pub(crate) fn reevaluate(
    types: &[BodyType],
    geometry: &GeometryCache,
    container: &Container,
    bodies: &[Body],
    c: &Contact,
    lean: bool,
) -> Option<Contact> {
    let pellet = |k: usize| {
        let t = bodies[k].type_id.0 as usize;
        Pellet { index: k, body: &bodies[k], shape: &types[t].shape, geom: &geometry.types[t] }
    };
    collide_feature(container, pellet(c.a), c.b_body().map(pellet), &c.key, lean)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::container::WallId;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Contacts in runs of increasing keys (pairs, then walls, as the narrow phase gives them) and
    /// in no order at all, against last substep's forces on a random subset of the keys and on
    /// keys that are gone: the galloping search finds what a binary search finds.
    #[test]
    fn the_galloping_search_finds_what_a_binary_search_finds() {
        let mut rng = ChaCha8Rng::seed_from_u64(17);
        for trial in 0..100 {
            let n: u32 = rng.random_range(0..40);
            let mut keys: Vec<ContactKey> = Vec::new();
            for a in 0..n {
                for f in 0..rng.random_range(0..3) {
                    keys.push(ContactKey { a, b: Counterpart::Body(a as usize + 1), feature: f });
                }
                if rng.random_range(0..3) == 0 {
                    keys.push(ContactKey { a, b: Counterpart::Wall(WallId::Floor), feature: 0 });
                }
            }
            let mut warm: Vec<WarmForce> = Vec::new();
            for &key in &keys {
                if rng.random_range(0..3) != 0 {
                    warm.push(WarmForce { key, normal: rng.random_range(0.1..1.0), friction: Vec3::x() });
                }
            }
            // A key of a contact that is gone, after all the others.
            let gone = ContactKey { a: n + 5, b: Counterpart::Body(0), feature: 9 };
            warm.push(WarmForce { key: gone, normal: 1.0, friction: Vec3::y() });
            warm.sort_by_key(|w| w.key);
            // Pairs first, then walls; every third trial shuffled.
            let (mut order, walls): (Vec<_>, Vec<_>) = keys.iter().partition(|k| matches!(k.b, Counterpart::Body(_)));
            order.extend(walls);
            if trial % 3 == 0 {
                for i in (1..order.len()).rev() {
                    order.swap(i, rng.random_range(0..=i));
                }
            }
            let contacts: Vec<Contact> = order.iter().map(|&&k| Contact::bare(k)).collect();
            let found = warm_starts(&warm, &contacts);
            for (c, got) in contacts.iter().zip(found) {
                let expected = warm
                    .binary_search_by(|w| w.key.cmp(&c.key))
                    .map_or((0.0, Vec3::zeros()), |i| (warm[i].normal, warm[i].friction));
                assert_eq!(got, expected, "key {:?}", c.key);
            }
        }
    }
}
