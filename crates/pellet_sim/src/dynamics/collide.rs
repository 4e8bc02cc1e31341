//! The collision phase of the force-level stepper (`docs/engine.md`, "Time stepping"): passes of
//! simultaneous normal impulses over the contacts colliding at that moment, Coulomb friction per
//! point with the stick or zero clamp, and a final e = 0 solve when the pass cap is reached.

use super::by_body::ByBody;
use super::islands::build_islands;
use super::lcp::solve_auto;
use super::rows::{collision_matrix, relative_velocity, relative_velocity_from};
use crate::body::Body;
use crate::geometry::contact::Contact;
use crate::math::{Real, Vec3};
use crate::params::{EngineParams, FrictionClamp};

/// What the collision phase did in one substep.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CollisionStats {
    /// Contacts colliding at the start of the phase.
    pub colliding: usize,
    /// Passes run.
    pub passes: u32,
    /// Number of non-zero point impulses applied.
    pub impulses: u32,
    /// Whether the final e = 0 solve was needed.
    pub final_solve: bool,
    /// Kinetic energy removed by normal impulses, J (≥ 0).
    pub normal_loss: Real,
    /// Kinetic energy removed by friction impulses, J (≥ 0).
    pub friction_loss: Real,
    /// Friction impulses dropped by the energy guard.
    pub guard_events: u32,
    /// Solver iterations / pivots.
    pub solver_iterations: usize,
}

fn kinetic(bodies: &[Body], ids: &[usize]) -> Real {
    ids.iter().map(|&k| bodies[k].kinetic_translational() + bodies[k].kinetic_rotational()).sum()
}

fn apply(bodies: &mut [Body], c: &Contact, j: &Vec3) {
    bodies[c.a].apply_impulse_at_lever(j, &c.lever_a);
    if let Some(b) = c.b_body() {
        bodies[b].apply_impulse_at_lever(&-j, &c.lever_b);
    }
}

/// The Coulomb friction impulse (stick or zero clamp, `FrictionClamp`) for a contact whose
/// normal impulse `p` was just applied. `slip` is the tangential velocity before the pass;
/// returns None when no friction acts.
fn friction_impulse(
    c: &Contact,
    bodies: &[Body],
    p: Real,
    mu: Real,
    slip: &Vec3,
    clamp: FrictionClamp,
) -> Option<Vec3> {
    let t = slip.normalize();
    let n = c.normal;
    let u = relative_velocity(c, bodies);
    let k = collision_matrix(c, bodies);
    let t1 = t;
    let t2 = n.cross(&t1);
    // Stick: the tangential impulse that zeroes the tangential relative velocity.
    let ktt = nalgebra::Matrix2::new(t1.dot(&(k * t1)), t1.dot(&(k * t2)), t2.dot(&(k * t1)), t2.dot(&(k * t2)));
    let rhs = nalgebra::Vector2::new(-t1.dot(&u), -t2.dot(&u));
    let stick = ktt.try_inverse().map(|inv| {
        let y = inv * rhs;
        t1 * y.x + t2 * y.y
    });
    let slide = -t * (mu * p);
    let reverses = |j: &Vec3| {
        let up = u + k * j;
        (up - n * n.dot(&up)).dot(&t) < 0.0
    };
    match clamp {
        FrictionClamp::Stick => match stick {
            Some(js) if js.norm() <= mu * p => Some(js),
            _ if !reverses(&slide) => Some(slide),
            _ => stick,
        },
        FrictionClamp::Zero => (!reverses(&slide)).then_some(slide),
    }
}

/// Runs the collision phase on `contacts` (restitution `cor[i]`, friction `mu[i]`).
///
/// A contact collides if it approaches faster than εp and its gap would fall below δ_c within
/// the substep `dt` (contacts are generated a little ahead, so that an impact is resolved at the
/// pre-collision state, as the paper's roll-back does, instead of one substep late).
pub fn collision_phase(
    bodies: &mut [Body],
    contacts: &[Contact],
    cor: &[Real],
    mu: &[Real],
    params: &EngineParams,
    dt: Real,
    delta_c: Real,
) -> CollisionStats {
    let mut stats = CollisionStats::default();
    // Each body's velocity and angular velocity, refreshed for the bodies a pass changed.
    let mut vel: Vec<Vec3> = bodies.iter().map(Body::velocity).collect();
    let mut omega: Vec<Vec3> = bodies.iter().map(Body::angular_velocity).collect();
    // Each contact's relative velocity and its normal part; after a pass, only the contacts of
    // the bodies it changed are computed again (the rest keep their bits). Computing all of
    // them for every pass was a third of the phase in a batch pour, where a landing takes many
    // passes over a few colliding contacts among thousands.
    let mut u: Vec<Vec3> = contacts.iter().map(|c| relative_velocity_from(c, &vel, &omega)).collect();
    let mut vn: Vec<Real> = contacts.iter().zip(&u).map(|(c, u)| c.normal.dot(u)).collect();
    let mut contacts_of: Option<ByBody<u32>> = None;
    let mut changed: Vec<usize> = Vec::new();
    loop {
        if !changed.is_empty() {
            let by_body = contacts_of.get_or_insert_with(|| {
                let mut ends = Vec::with_capacity(2 * contacts.len());
                for (i, c) in contacts.iter().enumerate() {
                    ends.push((c.a, i as u32));
                    ends.extend(c.b_body().map(|b| (b, i as u32)));
                }
                ByBody::new(bodies.len(), &ends).expect("a substep's contacts fit u32 indices")
            });
            for &k in &changed {
                for &ci in by_body.of(k) {
                    let c = &contacts[ci as usize];
                    let ui = relative_velocity_from(c, &vel, &omega);
                    vn[ci as usize] = c.normal.dot(&ui);
                    u[ci as usize] = ui;
                }
            }
            changed.clear();
        }
        let colliding: Vec<usize> =
            (0..contacts.len()).filter(|&i| vn[i] < -params.eps_p && contacts[i].gap + vn[i] * dt <= delta_c).collect();
        if stats.passes == 0 {
            stats.colliding = colliding.len();
        }
        if colliding.is_empty() {
            break;
        }
        // Velocity tolerance relative to the impact speeds of this pass.
        let vmax = colliding.iter().map(|&i| -vn[i]).fold(params.eps_p, Real::max);
        let vtol = 1e-12 * vmax;
        let final_solve = stats.passes >= params.acceleration.collision_pass_cap;
        let set: Vec<usize> = if final_solve {
            (0..contacts.len())
                .filter(|&i| vn[i] <= params.eps_p && contacts[i].gap + vn[i].min(0.0) * dt <= delta_c)
                .collect()
        } else {
            colliding
        };
        stats.passes += 1;
        for island in build_islands(contacts, &set, bodies.len()) {
            let masses = island.masses(bodies);
            let sys = island.normal_system(contacts, &masses);
            let b: Vec<Real> = island
                .contacts
                .iter()
                .map(|&ci| {
                    let e = if final_solve { 0.0 } else { cor[ci] };
                    (1.0 + e) * vn[ci]
                })
                .collect();
            let mut p = vec![0.0; b.len()];
            let rep = solve_auto(
                &sys,
                &b,
                &mut p,
                vtol,
                1e3 * vtol,
                params.acceleration.exact_solver_max_rows,
                params.acceleration.iterative_solver,
                10 * params.acceleration.apgd_max_iterations,
                10 * params.acceleration.pgs_max_iterations,
                false,
            );
            stats.solver_iterations += rep.iterations;
            let ke0 = kinetic(bodies, &island.bodies);
            for (k, &ci) in island.contacts.iter().enumerate() {
                if p[k] > 0.0 {
                    apply(bodies, &contacts[ci], &(contacts[ci].normal * p[k]));
                    stats.impulses += 1;
                }
            }
            let ke1 = kinetic(bodies, &island.bodies);
            stats.normal_loss += ke0 - ke1;
            if final_solve {
                continue;
            }
            for (k, &ci) in island.contacts.iter().enumerate() {
                let c = &contacts[ci];
                let slip = u[ci] - c.normal * vn[ci];
                if p[k] <= 0.0 || mu[ci] <= 0.0 || slip.norm() <= params.acceleration.eps_f {
                    continue;
                }
                let Some(j) = friction_impulse(c, bodies, p[k], mu[ci], &slip, params.acceleration.friction_clamp)
                else {
                    continue;
                };
                let um = relative_velocity(c, bodies);
                let up = um + collision_matrix(c, bodies) * j;
                let d_ke = j.dot(&(um + up)) * 0.5;
                let ke_scale = kinetic(bodies, &island.bodies).max(1e-300);
                if d_ke > 1e-12 * ke_scale {
                    stats.guard_events += 1;
                    continue;
                }
                apply(bodies, c, &j);
                stats.friction_loss -= d_ke;
            }
            for &k in &island.bodies {
                vel[k] = bodies[k].velocity();
                omega[k] = bodies[k].angular_velocity();
            }
            changed.extend_from_slice(&island.bodies);
        }
        if final_solve {
            stats.final_solve = true;
            break;
        }
    }
    stats
}
