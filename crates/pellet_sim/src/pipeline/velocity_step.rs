//! The velocity-level stepper (`Stepper::Velocity`, `docs/engine.md` "Velocity-level
//! stepping"): per step of length h, the contacts of every pair and wall whose gap can close
//! within h (speculative contacts), classified by their relative normal velocity at the start
//! of the step, solved together on impulses with restitution and Coulomb friction
//! (`dynamics::impulse_solve`), a semi-implicit step x⁺ = x + h v⁺, and position projection that
//! leaves velocities alone. Steps are sized by kinematics: no near pair's relative surface
//! travel over a step beyond `VelocityParams::travel` of the pellet size, and no step beyond
//! `VelocityParams::max_step`; gravity does not limit it, because the class of a contact is
//! decided before gravity's increment.

use super::proximity::wall_closing;
use super::step::{Pipeline, StepReport, WarmImpulse};
use super::world::World;
use crate::body::Body;
use crate::container::WallId;
use crate::dynamics::impulse_solve::{
    collision_passes, solve_impulses, NormalTarget, Touching, VelocityState, WarmStart,
};
use crate::dynamics::integrator::advance;
use crate::dynamics::rows::relative_velocity_from;
use crate::error::SimError;
use crate::geometry::contact::{Contact, ContactKey, Counterpart};
use crate::math::{Real, Vec3};
use crate::shape::ShapeDesc;

/// Near pairs and walls over the coming step, with the bound on each one's relative surface
/// speed (m/s) that sizes its speculative contacts.
pub(super) struct Near {
    pub(super) pairs: Vec<(usize, usize, Real)>,
    pub(super) walls: Vec<(usize, WallId, Real)>,
    /// The speed that sizes the step: the largest relative surface speed of a touching pair,
    /// or closing speed of one that does not touch yet.
    step_speed: Real,
}

/// The near set's broad-phase skin as a factor of λ: the grid's candidates are reused until a
/// body has moved (or its swept radius grown) by this much. The pairs found are the same for
/// any skin; a falling body outruns λ in a step or two, and the 690-sphere bed's first 0.3 s
/// rebuilt the grid in 654 of 928 steps with λ, in 128 with 4 λ (17.5 against 16.0 billion
/// instructions, callgrind; 8 λ: 57 rebuilds and 15.9 billion, with twice the candidates to
/// filter at rest).
const NEAR_SKIN_FACTOR: Real = 4.0;

impl World {
    fn round(&self, k: usize) -> bool {
        matches!(self.types[self.bodies[k].type_id.0 as usize].shape, ShapeDesc::Sphere { .. })
    }

    /// The patch each contact point stands for: its radius (m), `VelocityParams::patch_radius`
    /// of the pellet size, and whether it resists rolling as well as spin. Between two spheres
    /// it resists spin only: a sphere rolling in the groove between two spheres meets a third
    /// within a diameter, but one held between two nearly opposite points spins about the line
    /// through them with nothing to stop it. One rolling along the wall, in the groove between
    /// a sphere or the floor and the wall, goes round the tube for ever (`docs/engine.md`,
    /// "Contact points as small patches").
    fn patches(&self, contacts: &[Contact]) -> Vec<(Real, bool)> {
        let a = self.params.velocity.patch_radius * self.nominal_size();
        contacts
            .iter()
            .map(|c| {
                let spheres = self.round(c.a) && c.b_body().is_some_and(|b| self.round(b));
                (a, !spheres)
            })
            .collect()
    }

    /// Pairs and walls that may come within δ_c of each other over `horizon` (swept bounding
    /// spheres: nothing that can touch within the step is left out, so nothing tunnels).
    fn near(&self, pipeline: &mut Pipeline, horizon: Real) -> Near {
        let delta_c = self.params.contact_distance_factor * self.reference_size();
        let g = self.params.gravity.norm();
        let fall = g * horizon * horizon;
        let centres: Vec<Vec3> = self.bodies.iter().map(|b| b.position).collect();
        let speeds: Vec<Real> = self.bodies.iter().map(|b| b.velocity().norm()).collect();
        let radii: Vec<Real> = self
            .bodies
            .iter()
            .zip(&speeds)
            .map(|(b, s)| b.bounding_radius + s * horizon + fall + 0.5 * delta_c)
            .collect();
        // A sphere's spin moves none of its surface through another body.
        let spins: Vec<Real> = (0..self.bodies.len())
            .map(|k| {
                if self.round(k) {
                    0.0
                } else {
                    self.bodies[k].angular_velocity().norm() * self.bodies[k].bounding_radius
                }
            })
            .collect();
        let mut near = Near { pairs: Vec::new(), walls: Vec::new(), step_speed: 0.0 };
        let skin = NEAR_SKIN_FACTOR * self.lambda();
        for &(i, j) in pipeline.broad.overlapping_pairs(&centres, &radii, skin) {
            let (i, j) = (i as usize, j as usize);
            let (bi, bj) = (&self.bodies[i], &self.bodies[j]);
            let c = bi.position - bj.position;
            let distance = c.norm();
            let gap = distance - bi.bounding_radius - bj.bounding_radius;
            let v = bi.velocity() - bj.velocity();
            let full = v.norm() + spins[i] + spins[j];
            // Spheres apart close at most at the rate their centres approach; touching ones
            // (and any pair of other shapes, whose bounding gap says little) slide and roll.
            let step_speed = if self.round(i) && self.round(j) && gap > delta_c && distance > 0.0 {
                (-v.dot(&c) / distance).max(0.0)
            } else {
                full
            };
            near.step_speed = near.step_speed.max(step_speed);
            near.pairs.push((i, j, full));
        }
        for (k, b) in self.bodies.iter().enumerate() {
            let reach = speeds[k] * horizon + fall + delta_c;
            let round = self.round(k);
            self.container.wall_gaps(&b.position, b.bounding_radius, |wall, gap| {
                if gap > reach {
                    return;
                }
                let full = speeds[k] + spins[k] + g * horizon;
                let step_speed = if round && gap > delta_c {
                    wall_closing(&self.container, wall, b, true, self.params.velocity.max_step) + g * horizon
                } else {
                    full
                };
                near.step_speed = near.step_speed.max(step_speed);
                near.walls.push((k, wall, full));
            });
        }
        near
    }

    /// Advances to `t_end` with the velocity-level stepper.
    pub(super) fn step_velocity(
        &mut self,
        t_end: Real,
        pipeline: &mut Pipeline,
        report: &mut StepReport,
    ) -> Result<(), SimError> {
        let vp = self.params.velocity;
        let d = self.reference_size();
        while t_end - self.time > 1e-14 * t_end.abs().max(1e-3) {
            let remaining = t_end - self.time;
            let horizon = remaining.min(vp.max_step);
            let near = self.near(pipeline, horizon);
            if near.pairs.is_empty() && near.walls.is_empty() {
                self.free_flight(horizon, report);
                report.free_flights += 1;
                self.time = if horizon == remaining { t_end } else { self.time + horizon };
                pipeline.impulses.clear();
                pipeline.manifolds.clear();
                pipeline.set_last_contacts(Vec::new(), Vec::new(), Vec::new());
                continue;
            }
            let mut h = horizon;
            if near.step_speed > 0.0 {
                h = h.min(vp.travel * d / near.step_speed);
            }
            // Equal steps to the end of the big step, not a sliver at its end.
            let n = (remaining / h * (1.0 - 1e-12)).ceil().max(1.0);
            h = remaining / n;
            self.velocity_substep(h, n == 1.0, t_end, &near, pipeline, report)?;
        }
        Ok(())
    }

    #[allow(clippy::too_many_arguments)]
    fn velocity_substep(
        &mut self,
        h0: Real,
        to_end: bool,
        t_end: Real,
        near: &Near,
        pipeline: &mut Pipeline,
        report: &mut StepReport,
    ) -> Result<(), SimError> {
        let d = self.reference_size();
        let delta_c = self.params.contact_distance_factor * d;
        let eps_p = self.params.eps_p;
        let g = self.params.gravity;
        let max_rot = self.params.max_rotation_per_substep;
        let vp = self.params.velocity;
        pipeline.saved.clone_from(&self.bodies);
        let bounds = self.gap_bounds();
        let mut h = h0;
        let mut rewinds = 0;
        loop {
            let clock = std::time::Instant::now();
            let contacts = self.speculative_contacts(near, h, pipeline)?;
            report.wall_seconds[0] += clock.elapsed().as_secs_f64();
            let clock = std::time::Instant::now();
            let vel0: Vec<Vec3> = self.bodies.iter().map(Body::velocity).collect();
            let omega0: Vec<Vec3> = self.bodies.iter().map(Body::angular_velocity).collect();
            let u0: Vec<Vec3> = contacts.iter().map(|c| relative_velocity_from(c, &vel0, &omega0)).collect();
            let memory = remembered(&pipeline.impulses, &contacts);
            let patches = self.patches(&contacts);
            let (mut colliding, mut resting) = (0u64, 0u64);
            let mut targets = Vec::with_capacity(contacts.len());
            let mut warm = Vec::with_capacity(contacts.len());
            let mut colliding_now = Vec::with_capacity(contacts.len());
            let mut first = Vec::new();
            let mut touching = Vec::new();
            for (k, (((c, u), m), &(patch, rolls))) in contacts.iter().zip(&u0).zip(&memory).zip(&patches).enumerate() {
                let (cor, mu) = match c.b {
                    Counterpart::Body(_) => (self.material.cor, self.material.friction),
                    Counterpart::Wall(_) => (self.wall_material.cor, self.wall_material.friction),
                };
                let un = c.normal.dot(u);
                let pending = m.approach < 0.0;
                let approach = if pending { un.min(m.approach) } else { un };
                // Newton's law acts at the start of the step; gravity's increment of the
                // relative velocity over the step (against a wall; none between two pellets)
                // follows it.
                let fall = if c.b_body().is_none() { c.normal.dot(&g) * h } else { 0.0 };
                // An open contact closing fast is first brought to the touching gap, and bounces
                // the step after, from there: bouncing at once from up to δ_c would move the
                // bounce point from one impact to the next, and a ball bouncing on the spot
                // then gains what it falls further.
                let arriving = approach < -eps_p && c.gap > 0.0 && !pending;
                let collide = approach < -eps_p && !arriving;
                if collide {
                    colliding += 1;
                    // Never below what keeps the gap from closing.
                    first.push((k, (-cor * approach + fall).max(-c.gap.max(0.0) / h)));
                } else if arriving {
                    // Stopped at the touching gap by the collision passes, its two bodies alone
                    // (e = 0: the bounce follows from the remembered approach), not by the
                    // step's solve, where the pellets behind the one it meets would stop it as
                    // one rigid body.
                    first.push((k, -c.gap / h));
                } else if c.gap <= delta_c {
                    resting += 1;
                }
                if c.gap <= delta_c && !arriving {
                    touching.push(Touching { index: k, cor, fall });
                }
                colliding_now.push(collide);
                // The step's solve is inelastic for every contact: a colliding one enters it
                // with the impulse of its collision already applied, and cold.
                targets.push(NormalTarget { min_speed: -c.gap.max(0.0) / h, mu, patch, rolls });
                warm.push(if collide {
                    WarmStart::default()
                } else {
                    WarmStart { normal: m.normal * h, friction: m.friction * h, torque: m.torque * h }
                });
            }
            let mut st = VelocityState::free(&self.bodies, &g, h);
            let fastest = vel0.iter().map(|v| v.norm()).fold(0.0, Real::max);
            let tolerance = (vp.tolerance_factor * eps_p).max(vp.relative_tolerance * fastest);
            let collisions = (!first.is_empty()).then(|| {
                collision_passes(
                    &contacts,
                    &targets,
                    &first,
                    &touching,
                    eps_p,
                    &mut st,
                    tolerance,
                    vp.max_sweeps,
                    &pipeline.team,
                )
            });
            let mut sol = solve_impulses(&contacts, &targets, &warm, &mut st, tolerance, vp.max_sweeps, &pipeline.team);
            // The next step starts from this solve's impulses, without the collisions': a
            // bounce's impulse is not the load of a contact that stays.
            let carried = collisions.is_some().then(|| (sol.normal.clone(), sol.friction.clone(), sol.torque.clone()));
            if let Some(passes) = &collisions {
                for (k, n) in passes.normal.iter().enumerate() {
                    sol.normal[k] += n;
                    sol.friction[k] += passes.friction[k];
                    sol.torque[k] += passes.torque[k];
                }
                sol.sweeps += passes.sweeps;
                sol.converged &= passes.converged;
                report.collision_passes += passes.passes as u64;
                report.final_solves += u32::from(passes.capped || passes.gained);
            }
            report.wall_seconds[2] += clock.elapsed().as_secs_f64();
            // Each body's momenta after the step: gravity's increment plus the contact impulses.
            // A body that no contact pushes flies exactly (a semi-implicit step under gravity
            // alone takes ½ m g²h² out per step: a small bounce near the floor, a few steps
            // long, lost a third of its energy that way).
            let mut touched = vec![false; self.bodies.len()];
            let mut dp = vec![Vec3::zeros(); self.bodies.len()];
            let mut dl = vec![Vec3::zeros(); self.bodies.len()];
            for (k, c) in contacts.iter().enumerate() {
                if sol.normal[k] == 0.0 {
                    continue;
                }
                let j = c.normal * sol.normal[k] + sol.friction[k];
                touched[c.a] = true;
                dp[c.a] += j;
                dl[c.a] += c.lever_a.cross(&j) + sol.torque[k];
                if let Some(b) = c.b_body() {
                    touched[b] = true;
                    dp[b] -= j;
                    dl[b] -= c.lever_b.cross(&j) + sol.torque[k];
                }
            }
            // Each body on its own, on the pipeline's threads; the energy summed in body order.
            let mut bodies: Vec<(usize, &mut Body)> = self.bodies.iter_mut().enumerate().collect();
            let Ok(moved) = pipeline.team.in_order(&mut bodies, |chunk, out| {
                for (k, b) in chunk.iter_mut() {
                    out.push(if touched[*k] {
                        let v_before = b.velocity();
                        b.linear_momentum += g * (b.mass * h) + dp[*k];
                        b.angular_momentum += dl[*k];
                        let work = 0.5 * b.mass * h * g.dot(&(b.velocity() - v_before));
                        (Some(work), advance(b, &Vec3::zeros(), &Vec3::zeros(), h, max_rot) as u64)
                    } else {
                        (None, advance(b, &(g * b.mass), &Vec3::zeros(), h, max_rot) as u64)
                    });
                }
                Ok::<(), std::convert::Infallible>(())
            });
            let mut integrator = 0.0;
            let mut rot_steps = 0u64;
            for (work, steps) in moved {
                if let Some(work) = work {
                    integrator += work;
                }
                rot_steps += steps;
            }
            let Some(proj) =
                self.project_or_rewind(&contacts, &pipeline.saved, &bounds, &mut rewinds, &pipeline.team, report)?
            else {
                h *= 0.5;
                continue;
            };
            // Work of the impulses: Σ λ·(u⁻ + u⁺)/2 with u⁻ the velocity before gravity's
            // increment, exact for velocities linear in the impulses.
            let (mut normal_work, mut friction_work) = (0.0, 0.0);
            let mut impacts = 0u64;
            for (k, c) in contacts.iter().enumerate() {
                let mean = 0.5 * (u0[k] + sol.relative_after[k]);
                normal_work += sol.normal[k] * c.normal.dot(&mean);
                friction_work += sol.friction[k].dot(&mean);
                if patches[k].0 > 0.0 {
                    let turn = |w: &[Vec3]| w[c.a] - c.b_body().map_or(Vec3::zeros(), |b| w[b]);
                    friction_work += sol.torque[k].dot(&(0.5 * (turn(&omega0) + turn(&st.w))));
                }
                if sol.normal[k] > 0.0 && colliding_now[k] {
                    impacts += 1;
                }
            }
            report.rotation_substeps += rot_steps;
            report.substeps += 1;
            report.dt_min = report.dt_min.min(h);
            report.dt_max = report.dt_max.max(h);
            report.contacts += contacts.len() as u64;
            report.contact_pairs += contact_pairs(&contacts);
            for (k, m) in memory.iter().enumerate() {
                if sol.normal[k] > 0.0 {
                    report.loaded_contacts += 1;
                    report.loaded_warm += u64::from(m.normal > 0.0);
                }
            }
            report.colliding += colliding;
            report.resting += resting;
            report.impulses += impacts;
            report.solver_iterations += sol.sweeps as u64;
            report.solver_residual = report.solver_residual.max(sol.residual);
            report.solver_residual_tight = report.solver_residual_tight.max(sol.residual);
            report.unconverged_islands += !sol.converged as u32;
            report.largest_island = report.largest_island.max(contacts.len());
            report.max_penetration = report.max_penetration.max(proj.max_penetration_before);
            report.max_penetration_after_projection =
                report.max_penetration_after_projection.max(proj.max_penetration_after);
            let e = &mut report.energy;
            e.removed_by_collisions -= normal_work;
            e.removed_by_friction -= friction_work;
            e.removed_by_projection -= proj.potential_change;
            e.removed_by_integrator += integrator;
            // What the next step starts from; a contact stopped at the touching gap while
            // closing fast keeps its approach speed for the restitution of the next step.
            pipeline.impulses = contacts
                .iter()
                .enumerate()
                .filter_map(|(k, c)| {
                    let un = c.normal.dot(&u0[k]);
                    let approach = if memory[k].approach < 0.0 { un.min(memory[k].approach) } else { un };
                    let stopped = c.gap > 0.0 && approach < -eps_p && sol.normal[k] > 0.0 && !colliding_now[k];
                    // The speed at the touching gap: against a wall, gravity has sped the
                    // closing up over the gap (u² + 2aφ, exact for a body falling on the floor).
                    let pull = if c.b_body().is_none() { -c.normal.dot(&g) } else { 0.0 };
                    let approach =
                        if stopped { -(approach * approach + 2.0 * pull.max(0.0) * c.gap).sqrt() } else { 0.0 };
                    let (normal, friction, torque) = match &carried {
                        Some((n, f, t)) => (n[k], f[k], t[k]),
                        None => (sol.normal[k], sol.friction[k], sol.torque[k]),
                    };
                    (normal > 0.0 || stopped).then(|| WarmImpulse {
                        key: c.key,
                        normal: normal / h,
                        friction: friction / h,
                        torque: torque / h,
                        approach,
                    })
                })
                .collect();
            pipeline.impulses.sort_by_key(|w| w.key);
            let normal: Vec<Real> = sol.normal.iter().map(|l| l / h).collect();
            let friction: Vec<Vec3> = sol.friction.iter().map(|l| l / h).collect();
            pipeline.set_last_contacts(contacts, normal, friction);
            self.time = if to_end && rewinds == 0 { t_end } else { self.time + h };
            return Ok(());
        }
    }
}

/// What a contact remembers of the last step: its forces (N), its patch's torque (N·m) and
/// pending approach (m/s).
#[derive(Clone, Copy, Default)]
struct Memory {
    normal: Real,
    friction: Vec3,
    torque: Vec3,
    approach: Real,
}

/// The features of pair (i, j)'s contacts of the last step (`memory` sorted by key), sorted.
pub(super) fn kept_features(memory: &[WarmImpulse], i: usize, j: usize, out: &mut Vec<u32>) {
    out.clear();
    let of = |feature| ContactKey { a: i as u32, b: Counterpart::Body(j), feature };
    let from = memory.partition_point(|w| w.key < of(0));
    out.extend(memory[from..].iter().take_while(|w| w.key <= of(u32::MAX)).map(|w| w.key.feature));
}

/// How many pairs (a body and a body or a wall) the contacts are between; contacts of a pair
/// are adjacent (the narrow phase emits them pair by pair).
fn contact_pairs(contacts: &[Contact]) -> u64 {
    contacts.windows(2).filter(|w| (w[0].a, w[0].b) != (w[1].a, w[1].b)).count() as u64
        + u64::from(!contacts.is_empty())
}

/// Each contact's memory from the last step (`memory` sorted by key), by key. Matching a
/// contact whose key changed to its pair's nearest remembered point instead makes cylinder beds
/// settle later (`docs/engine.md`, "Alternatives tried, not kept").
fn remembered(memory: &[WarmImpulse], contacts: &[Contact]) -> Vec<Memory> {
    contacts
        .iter()
        .map(|c| match memory.binary_search_by(|w| w.key.cmp(&c.key)) {
            Ok(i) => Memory {
                normal: memory[i].normal,
                friction: memory[i].friction,
                torque: memory[i].torque,
                approach: memory[i].approach,
            },
            Err(_) => Memory::default(),
        })
        .collect()
}
