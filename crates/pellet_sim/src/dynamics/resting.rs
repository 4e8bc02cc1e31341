//! The resting phase (physics.md §4): normal forces from the LCP a = A f + b over each island,
//! with dynamic Coulomb friction at contacts slipping faster than εf and, as a switch, static
//! friction at contacts slipping slower. Friction enters the normal problem through b, and the
//! two are iterated to a fixed point (exact in one round when friction does not couple to the
//! normal accelerations, e.g. a sphere on a plane).

use super::friction_guard::{drop_energy_gaining, FrictionRow};
use super::islands::build_islands;
use super::lcp::{solve_auto, DenseLcp, LcpMatrix, LcpStatus};
use super::rows::{relative_velocity, Row, RowSystem};
use crate::body::Body;
use crate::geometry::contact::{Contact, ContactKey, GapKinematics, NormalOwner};
use crate::math::{Real, Vec3};
use crate::params::{EngineParams, FrictionClamp, IterativeSolver};

/// Fixed-point rounds between normal forces and friction.
const FRICTION_ROUNDS: usize = 30;
/// Round cap when the island is solved iteratively (each round is a full iterative solve).
const FRICTION_ROUNDS_ITERATIVE: usize = 10;
/// The friction fixed point stops when it changes b by less than this times the solver tolerance.
const FRICTION_TOL_FACTOR: Real = 0.1;
/// The same for iteratively solved islands: their answers carry noise of order tol_r, so a
/// tighter test would only chase that noise.
const FRICTION_TOL_FACTOR_ITERATIVE: Real = 1.0;
/// Rounds of (friction energy guard, normal re-solve) after the fixed point.
const GUARD_ROUNDS: usize = 3;
/// Gauss–Seidel sweeps of the static-friction rows per round.
const STATIC_SWEEPS: usize = 20;

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
    /// Islands whose solver did not converge (cap hit or infeasible).
    pub unconverged: usize,
    /// Σ f_i v_rel,i δt over resting contacts (the work bound of T13), J.
    pub normal_work: Real,
    /// Σ f_i εp δt, J.
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
}

/// Free (contact-force-free) acceleration of body `k` at lever arm `r`: ā = g + α×r + ω×(ω×r).
fn free_point_accel(body: &Body, r: &Vec3, g: &Vec3) -> Vec3 {
    let w = body.angular_velocity();
    let alpha = body.inv_inertia_world() * body.angular_momentum.cross(&w);
    g + alpha.cross(r) + w.cross(&w.cross(r))
}

/// b_i of a normal row: the gap's second derivative without contact forces (physics.md §4.2).
fn normal_rhs(c: &Contact, bodies: &[Body], g: &Vec3) -> Real {
    let a = &bodies[c.a];
    match c.kinematics {
        GapKinematics::SpherePlane => c.normal.dot(g),
        GapKinematics::SphereTube { rho } => {
            let vh = Vec3::new(a.velocity().x, a.velocity().y, 0.0);
            let e = -c.normal;
            let vperp = vh - e * e.dot(&vh);
            c.normal.dot(g) - vperp.norm_squared() / rho.max(1e-300)
        }
        GapKinematics::Point { owner } => {
            let acc_a = free_point_accel(a, &c.lever_a, g);
            let vel_a = a.velocity() + a.angular_velocity().cross(&c.lever_a);
            let (acc_b, vel_b, w_b) = match c.b_body() {
                Some(bi) => {
                    let b = &bodies[bi];
                    let w = b.angular_velocity();
                    (free_point_accel(b, &c.lever_b, g), b.velocity() + w.cross(&c.lever_b), w)
                }
                None => (Vec3::zeros(), Vec3::zeros(), Vec3::zeros()),
            };
            let n_dot = match owner {
                NormalOwner::A => a.angular_velocity().cross(&c.normal),
                NormalOwner::B => w_b.cross(&c.normal),
                NormalOwner::Fixed => Vec3::zeros(),
            };
            c.normal.dot(&(acc_a - acc_b)) + 2.0 * n_dot.dot(&(vel_a - vel_b))
        }
        GapKinematics::PointTube { rho } => {
            let vel = a.velocity() + a.angular_velocity().cross(&c.lever_a);
            let vh = Vec3::new(vel.x, vel.y, 0.0);
            let e = -c.normal;
            let vperp = vh - e * e.dot(&vh);
            c.normal.dot(&free_point_accel(a, &c.lever_a, g)) - vperp.norm_squared() / rho.max(1e-300)
        }
        GapKinematics::SphereSphere { distance } => {
            let b = &bodies[c.b_body().expect("sphere pair has two bodies")];
            let dv = a.velocity() - b.velocity();
            let perp = dv - c.normal * c.normal.dot(&dv);
            perp.norm_squared() / distance.max(1e-300)
        }
    }
}

/// Free tangential acceleration along `dir` at the contact point (vertex–face approximation).
fn tangential_rhs(c: &Contact, bodies: &[Body], dir: &Vec3, g: &Vec3) -> Real {
    let a = &bodies[c.a];
    let mut acc = free_point_accel(a, &c.lever_a, g);
    if let Some(bi) = c.b_body() {
        let b = &bodies[bi];
        acc -= free_point_accel(b, &c.lever_b, g);
    }
    dir.dot(&acc)
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Friction {
    Dynamic,
    Static,
}

/// Runs the resting phase over contacts with |v_rel| ≤ εp whose gap is, or would become within
/// `dt`, at most δ_c (the same look-ahead as the collision phase, so that a body arriving inside
/// the resting band is not first accelerated out of it by a substep of free fall). `warm(key)` gives the previous substep's normal force of a contact (the solver's warm start).
pub fn resting_phase(
    bodies: &[Body],
    contacts: &[Contact],
    mu: &[Real],
    params: &EngineParams,
    dt: Real,
    delta_c: Real,
    warm: &dyn Fn(&ContactKey) -> Real,
) -> (RestingForces, RestingStats) {
    let g = params.gravity;
    let mut out = RestingForces {
        wrench: vec![(Vec3::zeros(), Vec3::zeros()); bodies.len()],
        normal: vec![0.0; contacts.len()],
        friction: vec![Vec3::zeros(); contacts.len()],
    };
    let mut stats = RestingStats::default();
    let u: Vec<Vec3> = contacts.iter().map(|c| relative_velocity(c, bodies)).collect();
    let vn: Vec<Real> = contacts.iter().zip(&u).map(|(c, u)| c.normal.dot(u)).collect();
    let resting: Vec<usize> = (0..contacts.len())
        .filter(|&i| vn[i].abs() <= params.eps_p && contacts[i].gap + vn[i].min(0.0) * dt <= delta_c)
        .collect();
    stats.resting = resting.len();
    let tol = params.solver_tolerance();
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
                let mut b = normal_rhs(c, bodies, &g);
                if params.velocity_bias {
                    b += (vn[ci] + c.gap.max(0.0) / dt) / dt;
                }
                b
            })
            .collect();
        // Friction rows: per frictional contact, t1 along the slip (or any tangent), t2 = n × t1.
        let mut fric: Vec<(usize, Friction, Row, Row, Real, Real, Real)> = Vec::new();
        for (k, &ci) in island.contacts.iter().enumerate() {
            let c = &contacts[ci];
            if mu[ci] <= 0.0 {
                continue;
            }
            let slip = u[ci] - c.normal * vn[ci];
            let kind = if slip.norm() > params.eps_f {
                Friction::Dynamic
            } else if params.static_friction {
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
            let la = island.local(c.a);
            let lb = c.b_body().map(|b| island.local(b));
            let r1 = Row::new(la, lb, &c.lever_a, &c.lever_b, &t1, &masses);
            let r2 = Row::new(la, lb, &c.lever_a, &c.lever_b, &t2, &masses);
            let s1 = t1.dot(&slip);
            let s2 = t2.dot(&slip);
            fric.push((k, kind, r1, r2, s1, s2, mu[ci]));
        }
        let free_t: Vec<(Real, Real)> = fric
            .iter()
            .map(|(k, _, r1, r2, ..)| {
                let c = &contacts[island.contacts[*k]];
                (tangential_rhs(c, bodies, &r1.dir, &g), tangential_rhs(c, bodies, &r2.dir, &g))
            })
            .collect();
        let mut f: Vec<Real> = island.contacts.iter().map(|&ci| warm(&contacts[ci].key)).collect();
        let mut gt = vec![(0.0, 0.0); fric.len()];
        let apgd = params.iterative_solver == IterativeSolver::Apgd;
        let exact = sys.dim() <= params.exact_solver_max_rows;
        let (rounds, friction_tol) = match (fric.is_empty(), exact) {
            (true, _) => (1, 0.0),
            (false, true) => (FRICTION_ROUNDS, FRICTION_TOL_FACTOR * tol),
            (false, false) => (FRICTION_ROUNDS_ITERATIVE, FRICTION_TOL_FACTOR_ITERATIVE * tol),
        };
        let mut last_rep = None;
        // Normal accelerations caused by friction multipliers `gt`.
        let fsys = RowSystem {
            rows: fric.iter().flat_map(|x| [x.2.clone(), x.3.clone()]).collect(),
            n_bodies: island.bodies.len(),
        };
        let coupled_rhs = |gt: &[(Real, Real)]| -> Vec<Real> {
            let gflat: Vec<Real> = gt.iter().flat_map(|&(a, b)| [a, b]).collect();
            let ufric = fsys.response(&gflat);
            b0.iter().zip(&sys.rows).map(|(b, r)| b + r.dot(&ufric)).collect()
        };
        // Warm start of the fixed point: dynamic friction from last substep's normal forces.
        let mut clamped: Vec<Option<bool>> = vec![None; fric.len()];
        if !fric.is_empty() {
            let f_warm = f.clone();
            update_friction(&fric, &free_t, &sys, &f_warm, &mut gt, &mut clamped, params, dt);
            clamped.iter_mut().for_each(|c| *c = None);
        }
        let mut b = if fric.is_empty() { b0.clone() } else { coupled_rhs(&gt) };
        // Whether each dynamic contact's friction is clamped; decided in the first round and then
        // kept, so that the fixed point cannot toggle between the two branches.
        // Small islands go to Baraff, which works on the dense matrix: form it once per island.
        let dense = (sys.dim() <= params.exact_solver_max_rows).then(|| DenseLcp(sys.dense()));
        let op: &dyn LcpMatrix = match &dense {
            Some(d) => d,
            None => &sys,
        };
        // Baraff's tolerance on a_i ≥ 0 is 1e-13 g (it was 1e-9 g): an unsupported
        // acceleration below it is accepted, and a body resting on the 2-point line Baraff
        // picks from a flat 4-point patch can topple about that line unseen. In a 2-stack
        // that mode grew ×3 per 25 ms until its point accelerations reached the tolerance
        // (|ω| 3e-8 rad/s at 1e-9 g, 4e-12 at 1e-13 g). Round-off of a is ~1e-16 g.
        let solve = |b: &[Real], f: &mut [Real]| {
            solve_auto(
                op,
                b,
                f,
                1e-13 * tol / params.solver_tolerance_factor,
                tol,
                params.exact_solver_max_rows,
                apgd,
                params.apgd_max_iterations,
                params.pgs_max_iterations,
            )
        };
        for _ in 0..rounds {
            let rep = solve(&b, &mut f);
            stats.solver_iterations += rep.iterations;
            last_rep = Some(rep);
            if fric.is_empty() {
                break;
            }
            update_friction(&fric, &free_t, &sys, &f, &mut gt, &mut clamped, params, dt);
            // Converged once friction changes the normal problem by less than the solver's
            // own tolerance (exactly zero for a sphere on a plane: one round).
            let b_new = coupled_rhs(&gt);
            let change = b_new.iter().zip(&b).map(|(x, y)| (x - y).abs()).fold(0.0, Real::max);
            b = b_new;
            if change <= friction_tol {
                break;
            }
        }
        if fric.iter().any(|x| x.1 == Friction::Dynamic) {
            let rows: Vec<FrictionRow<'_>> = fric
                .iter()
                .zip(&free_t)
                .map(|(x, ft)| FrictionRow {
                    t1: &x.2,
                    t2: &x.3,
                    slip: (x.4, x.5),
                    free: *ft,
                    dynamic: x.1 == Friction::Dynamic,
                })
                .collect();
            // Dropping friction changes the normal problem (friction enters it through b):
            // re-solve the normal forces, then check again (a few rounds).
            for _ in 0..GUARD_ROUNDS {
                let dropped = drop_energy_gaining(&sys, &f, &rows, &mut gt, dt);
                stats.friction_dropped += dropped;
                if dropped == 0 {
                    break;
                }
                let rep = solve(&coupled_rhs(&gt), &mut f);
                stats.solver_iterations += rep.iterations;
                last_rep = Some(rep);
            }
        }
        if let Some(rep) = last_rep {
            stats.residual = stats.residual.max(rep.residual);
            if rep.status != LcpStatus::Converged {
                stats.unconverged += 1;
            }
        }
        for (k, &ci) in island.contacts.iter().enumerate() {
            let c = &contacts[ci];
            out.normal[ci] = f[k];
            stats.normal_work += f[k] * vn[ci] * dt;
            stats.normal_work_bound += f[k] * params.eps_p * dt;
            add_force(&mut out.wrench, c, &(c.normal * f[k]));
        }
        for (x, &(g1, g2)) in fric.iter().zip(&gt) {
            let ci = island.contacts[x.0];
            let force = x.2.dir * g1 + x.3.dir * g2;
            out.friction[ci] = force;
            add_force(&mut out.wrench, &contacts[ci], &force);
        }
    }
    (out, stats)
}

fn add_force(wrench: &mut [(Vec3, Vec3)], c: &Contact, force: &Vec3) {
    wrench[c.a].0 += force;
    wrench[c.a].1 += c.lever_a.cross(force);
    if let Some(b) = c.b_body() {
        wrench[b].0 -= force;
        wrench[b].1 -= c.lever_b.cross(force);
    }
}

/// New friction multipliers for fixed normal forces `f`.
#[allow(clippy::too_many_arguments)]
fn update_friction(
    fric: &[(usize, Friction, Row, Row, Real, Real, Real)],
    free_t: &[(Real, Real)],
    sys: &RowSystem,
    f: &[Real],
    gt: &mut [(Real, Real)],
    clamped: &mut [Option<bool>],
    params: &EngineParams,
    dt: Real,
) {
    // Dynamic contacts: −μ f along the slip, clamped so the slip does not reverse within dt.
    for ((x, g), cl) in fric.iter().zip(gt.iter_mut()).zip(clamped.iter_mut()) {
        if x.1 != Friction::Dynamic {
            continue;
        }
        let (k, r1, s1, mu) = (x.0, &x.2, x.4, x.6);
        let mag = mu * f[k];
        let limit = s1 / (r1.diag * dt);
        let is_clamped = *cl.get_or_insert(mag > limit);
        *g = if !is_clamped {
            (-mag, 0.0)
        } else {
            match params.friction_clamp {
                FrictionClamp::Stick => (-limit, 0.0),
                FrictionClamp::Zero => (0.0, 0.0),
            }
        };
    }
    if !fric.iter().any(|x| x.1 == Friction::Static) {
        return;
    }
    // Static contacts: Gauss–Seidel on the tangential rows, target tangential velocity zero at
    // the end of the substep, each force inside the disc |g| ≤ μ f.
    let mut acc = sys.response(f);
    for (x, g) in fric.iter().zip(gt.iter()) {
        x.2.add_response(g.0, &mut acc);
        x.3.add_response(g.1, &mut acc);
    }
    for _ in 0..STATIC_SWEEPS {
        for ((x, g), ft) in fric.iter().zip(gt.iter_mut()).zip(free_t) {
            if x.1 != Friction::Static {
                continue;
            }
            let (k, r1, r2, s1, s2, mu) = (x.0, &x.2, &x.3, x.4, x.5, x.6);
            let a1 = ft.0 + r1.dot(&acc) + s1 / dt;
            let a2 = ft.1 + r2.dot(&acc) + s2 / dt;
            let mut n1 = g.0 - a1 / r1.diag;
            let mut n2 = g.1 - a2 / r2.diag;
            let norm = (n1 * n1 + n2 * n2).sqrt();
            let cap = mu * f[k];
            if norm > cap {
                n1 *= cap / norm;
                n2 *= cap / norm;
            }
            r1.add_response(n1 - g.0, &mut acc);
            r2.add_response(n2 - g.1, &mut acc);
            *g = (n1, n2);
        }
    }
}
