//! The resting phase of the force-level stepper: normal forces from the LCP a = A f + b over each
//! island, with dynamic Coulomb friction at contacts slipping faster than εf and, as a switch,
//! static friction at contacts slipping slower. Friction enters the normal problem through b, and
//! the two are iterated to a fixed point (exact in one round when friction does not couple to the
//! normal accelerations, e.g. a sphere on a plane).

use super::friction_update::{Friction, FrictionEntry};
use super::island_solve::IslandProblem;
use super::islands::build_islands;
use super::lcp::LcpStatus;
use super::rows::{relative_velocity_from, Row};
use crate::body::Body;
use crate::geometry::contact::{Contact, GapKinematics, NormalOwner};
use crate::math::{Real, Vec3};
use crate::params::EngineParams;

/// What the resting phase did in one substep.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RestingStats {
    /// Resting contacts.
    pub resting: usize,
    /// Islands solved.
    pub islands: usize,
    /// Largest island (rows).
    pub largest_island: usize,
    /// Solver iterations (summed over islands and friction rounds).
    pub solver_iterations: usize,
    /// Worst final residual, m/s².
    pub residual: Real,
    /// Worst final residual of the islands whose last solve had the engine's tolerance, m/s²:
    /// all but islands in motion, whose last solve an unconverged friction fixed point leaves
    /// at the rounds' looser tolerance (`island_solve`), so `residual` can be metres per
    /// second squared in a pour while the islands near rest meet the tolerance.
    pub residual_tight: Real,
    /// Islands whose solver did not converge (cap hit or infeasible).
    pub unconverged: usize,
    /// Σ f_i εp δt over resting contacts (the bound of T13 b on their work; the work itself is
    /// measured over the substep by the pipeline), J.
    pub normal_work_bound: Real,
    /// Dynamic friction forces dropped by the coupled energy guard (`friction_guard`).
    pub friction_dropped: u32,
}

/// Forces from the resting phase.
#[derive(Debug, Clone, Default)]
pub struct RestingForces {
    /// Per body: total contact force and torque about the centre (world).
    pub wrench: Vec<(Vec3, Vec3)>,
    /// Per contact: normal force (0 for contacts not resting).
    pub normal: Vec<Real>,
    /// Per contact: friction force on A (world).
    pub friction: Vec<Vec3>,
    /// Per contact: relative velocity A − B at the contact point before the phase (world), the
    /// one it classified by; the pipeline measures the forces' work from it.
    pub relative_velocity: Vec<Vec3>,
}

/// A body's velocity, angular velocity ω = I⁻¹L and free angular acceleration α = I⁻¹(L×ω),
/// computed once per resting phase: per contact end (both tangents and the normal asked for
/// them again) they were ~6 % of a one-column pour (perf).
#[derive(Debug, Clone, Copy)]
struct BodyRates {
    v: Vec3,
    w: Vec3,
    alpha: Vec3,
}

impl BodyRates {
    fn of(body: &Body) -> Self {
        let w = body.angular_velocity();
        Self { v: body.velocity(), w, alpha: body.inv_inertia_world() * body.angular_momentum.cross(&w) }
    }
}

/// Free (contact-force-free) acceleration of a body at lever arm `r`: ā = g + α×r + ω×(ω×r).
fn free_point_accel(k: &BodyRates, r: &Vec3, g: &Vec3) -> Vec3 {
    g + k.alpha.cross(r) + k.w.cross(&k.w.cross(r))
}

/// b_i of a normal row: the gap's second derivative without contact forces.
fn normal_rhs(c: &Contact, rates: &[BodyRates], g: &Vec3) -> Real {
    let a = &rates[c.a];
    match c.kinematics {
        GapKinematics::SpherePlane => c.normal.dot(g),
        GapKinematics::SphereTube { rho } => {
            let vh = Vec3::new(a.v.x, a.v.y, 0.0);
            let e = -c.normal;
            let vperp = vh - e * e.dot(&vh);
            c.normal.dot(g) - vperp.norm_squared() / rho.max(1e-300)
        }
        GapKinematics::Point { owner } => {
            let acc_a = free_point_accel(a, &c.lever_a, g);
            let vel_a = a.v + a.w.cross(&c.lever_a);
            let (acc_b, vel_b, w_b) = match c.b_body() {
                Some(bi) => {
                    let b = &rates[bi];
                    (free_point_accel(b, &c.lever_b, g), b.v + b.w.cross(&c.lever_b), b.w)
                }
                None => (Vec3::zeros(), Vec3::zeros(), Vec3::zeros()),
            };
            let n_dot = match owner {
                NormalOwner::A => a.w.cross(&c.normal),
                NormalOwner::B => w_b.cross(&c.normal),
                NormalOwner::Fixed => Vec3::zeros(),
            };
            c.normal.dot(&(acc_a - acc_b)) + 2.0 * n_dot.dot(&(vel_a - vel_b))
        }
        GapKinematics::PointTube { rho } => {
            let vel = a.v + a.w.cross(&c.lever_a);
            let vh = Vec3::new(vel.x, vel.y, 0.0);
            let e = -c.normal;
            let vperp = vh - e * e.dot(&vh);
            c.normal.dot(&free_point_accel(a, &c.lever_a, g)) - vperp.norm_squared() / rho.max(1e-300)
        }
        GapKinematics::SphereSphere { distance } => {
            let b = &rates[c.b_body().expect("sphere pair has two bodies")];
            let dv = a.v - b.v;
            let perp = dv - c.normal * c.normal.dot(&dv);
            perp.norm_squared() / distance.max(1e-300)
        }
    }
}

/// Free relative acceleration of the contact point, A minus B (vertex–face approximation); its
/// component along a tangent is that friction row's free acceleration.
fn free_contact_accel(c: &Contact, rates: &[BodyRates], g: &Vec3) -> Vec3 {
    let mut acc = free_point_accel(&rates[c.a], &c.lever_a, g);
    if let Some(bi) = c.b_body() {
        acc -= free_point_accel(&rates[bi], &c.lever_b, g);
    }
    acc
}

/// Runs the resting phase over contacts with |v_rel| ≤ εp whose gap is, or would become within
/// `dt`, at most δ_c (the same look-ahead as the collision phase, so that a body arriving inside
/// the resting band is not first accelerated out of it by a substep of free fall). `warm[i]` is
/// contact i's normal force and friction force on A in the previous substep, by its key (the
/// solver's warm start).
pub fn resting_phase(
    bodies: &[Body],
    contacts: &[Contact],
    mu: &[Real],
    params: &EngineParams,
    dt: Real,
    delta_c: Real,
    warm: &[(Real, Vec3)],
) -> (RestingForces, RestingStats) {
    let g = params.gravity;
    let rates: Vec<BodyRates> = bodies.iter().map(BodyRates::of).collect();
    let vel: Vec<Vec3> = rates.iter().map(|r| r.v).collect();
    let omega: Vec<Vec3> = rates.iter().map(|r| r.w).collect();
    let u: Vec<Vec3> = contacts.iter().map(|c| relative_velocity_from(c, &vel, &omega)).collect();
    let mut out = RestingForces {
        wrench: vec![(Vec3::zeros(), Vec3::zeros()); bodies.len()],
        normal: vec![0.0; contacts.len()],
        friction: vec![Vec3::zeros(); contacts.len()],
        relative_velocity: Vec::new(),
    };
    let mut stats = RestingStats::default();
    let vn: Vec<Real> = contacts.iter().zip(&u).map(|(c, u)| c.normal.dot(u)).collect();
    let resting: Vec<usize> = (0..contacts.len())
        .filter(|&i| vn[i].abs() <= params.eps_p && contacts[i].gap + vn[i].min(0.0) * dt <= delta_c)
        .collect();
    stats.resting = resting.len();
    for island in build_islands(contacts, &resting, bodies.len()) {
        stats.islands += 1;
        stats.largest_island = stats.largest_island.max(island.contacts.len());
        let masses = island.masses(bodies);
        let sys = island.normal_system(contacts, &masses);
        let b0: Vec<Real> = island
            .contacts
            .iter()
            .map(|&ci| {
                let c = &contacts[ci];
                let mut b = normal_rhs(c, &rates, &g);
                if params.acceleration.velocity_bias {
                    b += (vn[ci] + c.gap.max(0.0) / dt) / dt;
                }
                b
            })
            .collect();
        // Friction rows: per frictional contact, t1 along the slip (or any tangent), t2 = n × t1.
        // Sized up front: an entry holds two rows (~450 bytes), and growing by doubling copied
        // ~1 MB per substep of a 690-sphere bed (memmove was 9 % of a bed at rest in perf).
        let mut fric: Vec<FrictionEntry> = Vec::with_capacity(island.contacts.len());
        for (k, &ci) in island.contacts.iter().enumerate() {
            let c = &contacts[ci];
            if mu[ci] <= 0.0 {
                continue;
            }
            let slip = u[ci] - c.normal * vn[ci];
            let kind = if slip.norm() > params.acceleration.eps_f {
                Friction::Dynamic
            } else if params.acceleration.static_friction {
                Friction::Static
            } else {
                continue;
            };
            let t1 = if slip.norm() > 0.0 {
                slip.normalize()
            } else {
                let a = if c.normal.x.abs() < 0.9 { Vec3::x() } else { Vec3::y() };
                (a - c.normal * c.normal.dot(&a)).normalize()
            };
            let t2 = c.normal.cross(&t1);
            let (la, lb) = island.ends[k];
            fric.push(FrictionEntry {
                contact: k,
                kind,
                t1: Row::new(la, lb, &c.lever_a, &c.lever_b, &t1, &masses),
                t2: Row::new(la, lb, &c.lever_a, &c.lever_b, &t2, &masses),
                slip: (t1.dot(&slip), t2.dot(&slip)),
                mu: mu[ci],
            });
        }
        let free_t: Vec<(Real, Real)> = fric
            .iter()
            .map(|x| {
                let acc = free_contact_accel(&contacts[island.contacts[x.contact]], &rates, &g);
                (x.t1.dir.dot(&acc), x.t2.dir.dot(&acc))
            })
            .collect();
        let warm_forces: Vec<(Real, Vec3)> = island.contacts.iter().map(|&ci| warm[ci]).collect();
        let f0: Vec<Real> = warm_forces.iter().map(|w| w.0).collect();
        let g0 = warm_static_friction(&fric, &warm_forces, sys.rows.len() > params.acceleration.exact_solver_max_rows);
        let problem = IslandProblem { sys: &sys, b0: &b0, fric: &fric, free_t: &free_t, g0: &g0, params, dt };
        let sol = problem.solve(f0);
        stats.solver_iterations += sol.iterations;
        stats.friction_dropped += sol.dropped;
        if let Some(rep) = sol.report {
            stats.residual = stats.residual.max(rep.residual);
            if sol.tolerance <= params.solver_tolerance() {
                stats.residual_tight = stats.residual_tight.max(rep.residual);
            }
            if rep.status != LcpStatus::Converged {
                stats.unconverged += 1;
            }
        }
        for (k, &ci) in island.contacts.iter().enumerate() {
            let c = &contacts[ci];
            out.normal[ci] = sol.f[k];
            stats.normal_work_bound += sol.f[k] * params.eps_p * dt;
            add_force(&mut out.wrench, c, &(c.normal * sol.f[k]));
        }
        for (x, &(g1, g2)) in fric.iter().zip(&sol.gt) {
            let ci = island.contacts[x.contact];
            let force = x.t1.dir * g1 + x.t2.dir * g2;
            out.friction[ci] = force;
            add_force(&mut out.wrench, &contacts[ci], &force);
        }
    }
    out.relative_velocity = u;
    (out, stats)
}

/// The warm start of static friction: last substep's friction force of each static contact,
/// on the new tangents, inside the disc of last substep's normal force. Only iteratively solved
/// islands get it (`iterative`); the others start from zero.
///
/// Why: the static-friction sweeps of one substep (5 per fixed-point round, ≤ 10 rounds) move
/// a correction about one contact per sweep, and a bed held up by wall friction is tens of
/// contacts deep; from the last answer the substeps add up. Measured with patches that merged
/// normals within 11.5° (cos 0.98, see `PATCH_COS`): 40 cylinders in a 40 mm tube settle at
/// 4.35 s in 188 s of CPU (8.12 s, 533 s from zero), 20 rings at 1.62 s (not settled in 6 s).
/// Small, exactly solved islands start from zero: with a warm start there, 12 spheres in a
/// 25 mm tube never settled.
fn warm_static_friction(fric: &[FrictionEntry], warm: &[(Real, Vec3)], iterative: bool) -> Vec<(Real, Real)> {
    fric.iter()
        .map(|x| {
            let (f, force) = warm[x.contact];
            if !iterative || x.kind != Friction::Static || f <= 0.0 {
                return (0.0, 0.0);
            }
            let (g1, g2) = (x.t1.dir.dot(&force), x.t2.dir.dot(&force));
            let (norm, cap) = ((g1 * g1 + g2 * g2).sqrt(), x.mu * f);
            let scale = if norm > cap { cap / norm } else { 1.0 };
            (g1 * scale, g2 * scale)
        })
        .collect()
}

fn add_force(wrench: &mut [(Vec3, Vec3)], c: &Contact, force: &Vec3) {
    wrench[c.a].0 += force;
    wrench[c.a].1 += c.lever_a.cross(force);
    if let Some(b) = c.b_body() {
        wrench[b].0 -= force;
        wrench[b].1 -= c.lever_b.cross(force);
    }
}
