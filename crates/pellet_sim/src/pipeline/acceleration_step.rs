//! The force-level stepper's time-stepping skeleton (`Stepper::Acceleration`, `docs/engine.md`,
//! "Time stepping"): swept broad phase, free flight when nothing is near, otherwise substeps of
//! δt = min(0.2λ/v_max, cap, time to the next proximity entry) with collision phase, resting
//! phase, midpoint integration, position projection and rewind-and-halve on excess penetration.

use super::proximity::Proximity;
use super::step::{Pipeline, StepReport, WarmForce};
use super::world::World;
use crate::body::Body;
use crate::dynamics::collide::collision_phase;
use crate::dynamics::integrator::advance;
use crate::dynamics::resting::resting_phase;
use crate::dynamics::rows::relative_velocity_from;
use crate::error::SimError;
use crate::geometry::contact::{Contact, Counterpart};
use crate::geometry::narrow_phase::{collide_pair_cached, collide_wall};
use crate::geometry::sample_cache::SampleCache;
use crate::math::{Real, Vec3};
use crate::shape::ShapeDesc;
use crate::team::Team;

impl World {
    /// Advances to `t_end` with the force-level stepper.
    pub(super) fn step_acceleration(
        &mut self,
        t_end: Real,
        pipeline: &mut Pipeline,
        report: &mut StepReport,
    ) -> Result<(), SimError> {
        let cap = self.params.acceleration.dt_cap;
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
                self.free_flight(dt, report);
                report.free_flights += 1;
                self.time = if dt == remaining { t_end } else { self.time + dt };
                pipeline.set_last_contacts(Vec::new(), Vec::new(), Vec::new());
                continue;
            }
            let mut dt = remaining.min(cap).min(prox.t_safe);
            if prox.v_max > 0.0 {
                dt = dt.min(self.params.acceleration.slip_fraction * self.lambda() / prox.v_max);
            }
            self.acceleration_substep(dt, &prox, pipeline, report)?;
        }
        Ok(())
    }

    fn narrow_phase(
        &self,
        prox: &Proximity,
        max_gap: Real,
        cache: &mut SampleCache,
        team: &Team,
    ) -> Result<Vec<Contact>, SimError> {
        // Room for one contact per pair and wall (what sphere beds give) without regrowing, and
        // for other shapes a reduced patch of 4 per pair and 8 per wall (4 points on each of
        // the two rims that rest on the floor): growing it contact by contact (a copy of the
        // whole vector each time) was 2.2 % of a cylinder bed, and with room for one wall
        // contact only, its regrowth under the wall contacts was still 1.9 % of 20 cylinders.
        let spheres = self.types.iter().all(|t| matches!(t.shape, ShapeDesc::Sphere { .. }));
        let (per_pair, per_wall) = if spheres { (1, 1) } else { (4, 8) };
        cache.next_round();
        if team.threads() > 1 {
            let pairs = prox.pairs.iter().map(|&(i, j)| (i, j, max_gap));
            let walls = prox.walls.iter().map(|&(k, wall)| (k, wall, max_gap));
            return self.contacts_on_threads(pairs, walls, cache, None, team);
        }
        let mut out = Vec::with_capacity(per_pair * prox.pairs.len() + per_wall * prox.walls.len());
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

    fn acceleration_substep(
        &mut self,
        dt0: Real,
        prox: &Proximity,
        pipeline: &mut Pipeline,
        report: &mut StepReport,
    ) -> Result<(), SimError> {
        let d = self.reference_size();
        let delta_c = self.params.contact_distance_factor * d;
        pipeline.saved.clone_from(&self.bodies);
        let bounds = self.gap_bounds();
        let mut dt = dt0;
        let mut rewinds = 0;
        loop {
            // Generate contacts a little ahead: up to the distance a pair can close in dt.
            let clock = std::time::Instant::now();
            let contacts = self.narrow_phase(prox, delta_c + prox.v_max * dt, &mut pipeline.samples, &pipeline.team)?;
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
            let Some(proj) =
                self.project_or_rewind(&contacts, &pipeline.saved, &bounds, &mut rewinds, &pipeline.team, report)?
            else {
                dt *= 0.5;
                continue;
            };
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::container::WallId;
    use crate::geometry::contact::ContactKey;
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
