//! Solving one island of the resting phase: normal forces and friction. Friction enters the
//! normal LCP through b, and the two are iterated to a fixed point (exact in one round when
//! friction does not couple to the normal accelerations, e.g. a sphere on a plane).

use super::coupled_pgs::CoupledProblem;
use super::friction_guard::{drop_energy_gaining, FrictionRow};
use super::friction_scatter::FrictionScatter;
use super::friction_update::{update_dynamic, update_static, Friction, FrictionEntry};
use super::lcp::{solve_auto, DenseLcp, LcpMatrix, LcpReport, LcpStatus};
use super::rows::RowSystem;
use crate::math::Real;
use crate::params::EngineParams;

/// Fixed-point rounds between normal forces and friction.
const FRICTION_ROUNDS: usize = 30;
/// Round cap when the island is solved iteratively (each round is a full iterative solve).
const FRICTION_ROUNDS_ITERATIVE: usize = 10;
/// Rounds an iteratively solved island with a sliding contact always gets; after them its fixed
/// point stops as soon as the contraction of its last round, kept up for the rounds left, would
/// not bring the change under the stop test. In a pour the fixed point contracts at ≈ 0.9 per
/// round from changes of 0.3–7 m/s² (1e3 tol_r) and ends unconverged whatever the cap; its
/// friction is carried to the next substep, which goes on from there. Measured: the default bed's
/// porosity over seeds (40 spheres, D = 40 mm) was 0.4528, 0.4564, 0.4600 and 0.4533 (standard
/// errors 0.002–0.004) with a fixed 3, 5, 10 and 20 rounds, no trend; a one-column pour (D = 56
/// mm, 5 s) took 11.5, 13.8 and 19.8 s of CPU with 3, 5 and 10. Islands whose contacts all stick
/// keep the whole cap: there the fixed point can converge, and where it does not the bed creeps
/// (a fixed 5 left the 100-sphere bench with 556 unconverged islands against 3; stopping them
/// early let the paper's 33.65 mm cylinder bed creep for 22 s, while with the cap it settles at
/// 4.16 s).
const FRICTION_MIN_ROUNDS_ITERATIVE: usize = 3;
/// The friction fixed point stops when it changes b by less than this times the solver tolerance.
const FRICTION_TOL_FACTOR: Real = 0.1;
/// The same for iteratively solved islands: their answers carry noise of order tol_r, so a
/// tighter test would only chase that noise.
const FRICTION_TOL_FACTOR_ITERATIVE: Real = 1.0;
/// An iteratively solved round's tolerance: this times the previous round's change of b (never
/// below the solver tolerance). Measured on the 100-sphere bench (recommended mode, 0.3 s):
/// 0 (every round tight) 968 iterations per substep, 0.1: 326, 0.3: 308 with 3 unconverged
/// islands, 1: 395 with 17.
const INEXACT_ROUND_FACTOR: Real = 0.1;
/// Slip speed, in units of εf, above which a contact marks its island as in motion (a landing
/// or sliding pellet); see the last solve in `solve_with`.
const FAST_SLIP_FACTOR: Real = 10.0;
/// The fixed point is abandoned, and its round with the smallest change kept, once a round's
/// change exceeds the smallest so far by this factor. Where friction feeds the normal forces
/// faster than they bound it (a wedged pellet), the rounds grow geometrically: on a 41-row
/// island of the paper's 40.45 mm ring bed by ×12 per round, from normal forces of 0.07 N to
/// 1e20 N in 30 rounds, which flung the bed out of the tube. Healthy fixed points contract
/// (≈ 0.85–0.9 per round).
const DIVERGENCE_FACTOR: Real = 10.0;
/// Rounds of (friction energy guard, normal re-solve) after the fixed point.
const GUARD_ROUNDS: usize = 3;

/// One island's resting problem.
pub struct IslandProblem<'a> {
    /// Normal rows.
    pub sys: &'a RowSystem,
    /// Normal right-hand side without friction, m/s².
    pub b0: &'a [Real],
    /// Frictional contacts.
    pub fric: &'a [FrictionEntry],
    /// Free tangential accelerations of `fric` along t1, t2, m/s².
    pub free_t: &'a [(Real, Real)],
    /// Warm static friction multipliers of `fric` (zero for dynamic entries), N.
    pub g0: &'a [(Real, Real)],
    /// Engine parameters.
    pub params: &'a EngineParams,
    /// Substep, s.
    pub dt: Real,
}

/// What an island solve returns.
#[derive(Debug, Clone)]
pub struct IslandSolution {
    /// Normal forces (multipliers), one per normal row.
    pub f: Vec<Real>,
    /// Friction multipliers along (t1, t2) of each entry of `fric`.
    pub gt: Vec<(Real, Real)>,
    /// The last solver report.
    pub report: Option<LcpReport>,
    /// The tolerance the last solve was asked for, m/s² (0 before any): the engine's own
    /// tolerance, or a looser one for an island in motion (`solve_with`).
    pub tolerance: Real,
    /// Solver iterations, summed.
    pub iterations: usize,
    /// Dynamic friction forces dropped by the energy guard.
    pub dropped: u32,
}

impl IslandProblem<'_> {
    /// Whether `solve` gives this island to Baraff when its iterative solve ends unconverged.
    fn exact_fallback(&self) -> bool {
        self.sys.dim() <= self.params.acceleration.exact_fallback_max_rows
    }

    fn has_dynamic(&self) -> bool {
        self.fric.iter().any(|x| x.kind == Friction::Dynamic)
    }

    /// The energy guard (`friction_guard`) with a re-solve after each round that drops forces.
    fn guard(&self, sol: &mut IslandSolution, mut resolve: impl FnMut(&mut IslandSolution)) {
        if !self.has_dynamic() {
            return;
        }
        for _ in 0..GUARD_ROUNDS {
            let rows: Vec<FrictionRow<'_>> = self
                .fric
                .iter()
                .zip(self.free_t)
                .map(|(x, ft)| FrictionRow {
                    t1: &x.t1,
                    t2: &x.t2,
                    slip: x.slip,
                    free: *ft,
                    dynamic: x.kind == Friction::Dynamic,
                })
                .collect();
            let dropped = drop_energy_gaining(self.sys, &sol.f, &rows, &mut sol.gt, self.dt);
            sol.dropped += dropped;
            if dropped == 0 {
                break;
            }
            resolve(sol);
        }
    }

    /// Solves the island from warm normal forces `f0`: friction through b, iterated to a fixed
    /// point with the normal LCP, then the energy guard. Islands up to
    /// `exact_solver_max_rows` go to Baraff; larger ones to the iterative solver, and those up to
    /// `exact_fallback_max_rows` whose iterative solve ends unconverged are solved again by
    /// Baraff.
    pub fn solve(&self, f0: Vec<Real>) -> IslandSolution {
        let (p, dim) = (self.params, self.sys.dim());
        let exact = dim <= p.acceleration.exact_solver_max_rows;
        let sol = self.solve_with(&f0, exact);
        let unconverged = sol.report.is_some_and(|r| r.status != LcpStatus::Converged);
        if !exact && unconverged && self.exact_fallback() {
            let mut again = self.solve_with(&f0, true);
            again.iterations += sol.iterations;
            // Kept only if no worse: in the paper's 40.45 mm ring bed the exact path's friction
            // fixed point on a 41-row island diverged (residual 8e18 m/s² against 0.19 for the
            // iterative answer) and flung the bed out of the tube.
            let residual = |s: &IslandSolution| s.report.map_or(Real::INFINITY, |r| r.residual);
            if residual(&again) <= residual(&sol) {
                return again;
            }
            return IslandSolution { iterations: again.iterations, ..sol };
        }
        sol
    }

    /// [`Self::solve`] with the exact (Baraff) or the iterative solver.
    fn solve_with(&self, f0: &[Real], exact: bool) -> IslandSolution {
        let (p, sys, fric, dt) = (self.params, self.sys, self.fric, self.dt);
        let tol = p.solver_tolerance();
        let max_exact = if exact { usize::MAX } else { 0 };
        let exact_follows = !exact && self.exact_fallback();
        let (rounds, friction_tol) = match (fric.is_empty(), exact) {
            (true, _) => (1, 0.0),
            (false, true) => (FRICTION_ROUNDS, FRICTION_TOL_FACTOR * tol),
            (false, false) => (FRICTION_ROUNDS_ITERATIVE, FRICTION_TOL_FACTOR_ITERATIVE * tol),
        };
        // Normal accelerations caused by friction multipliers `gt`: b0 + J M⁻¹ Jₜᵀ g (from the
        // entries' own rows: a RowSystem of them copied ~200 bytes per row per solve).
        let scatter = FrictionScatter::new(fric, sys.n_bodies);
        let coupled_rhs = |gt: &[(Real, Real)]| -> Vec<Real> {
            let mut u = vec![0.0; 6 * sys.n_bodies];
            scatter.add(gt, &mut u);
            self.b0.iter().zip(&sys.rows).map(|(b, r)| b + r.dot(&u)).collect()
        };
        let update = |f: &[Real], gt: &mut [(Real, Real)], clamped: &mut [Option<bool>]| {
            update_dynamic(fric, f, gt, clamped, p, dt);
            update_static(fric, self.free_t, sys, f, gt, dt, &scatter);
        };
        // Small islands go to Baraff, which works on the dense matrix: form it once per island.
        let dense = exact.then(|| DenseLcp(sys.dense()));
        let op: &dyn LcpMatrix = match &dense {
            Some(d) => d,
            None => sys,
        };
        // Baraff's tolerance on a_i ≥ 0 is 1e-13 g: an unsupported
        // acceleration below it is accepted, and a body resting on the 2-point line Baraff
        // picks from a flat 4-point patch can topple about that line unseen. In a 2-stack
        // that mode grew ×3 per 25 ms until its point accelerations reached the tolerance
        // (|ω| 3e-8 rad/s at 1e-9 g, 4e-12 at 1e-13 g). Round-off of a is ~1e-16 g.
        let solve = |b: &[Real], sol: &mut IslandSolution, round_tol: Real| {
            let rep = solve_auto(
                op,
                b,
                &mut sol.f,
                1e-13 * tol / p.acceleration.solver_tolerance_factor,
                round_tol,
                max_exact,
                p.acceleration.iterative_solver,
                p.acceleration.apgd_max_iterations,
                p.acceleration.pgs_max_iterations,
                exact_follows,
            );
            sol.iterations += rep.iterations;
            sol.report = Some(rep);
            sol.tolerance = round_tol;
        };
        // The fixed point from the warm normal forces `f0`; with `warm_friction` its first
        // round's b already holds the friction of `f0`. Returns the solution and the last
        // round's change of b (0 when the island has no friction).
        let sliding = self.has_dynamic();
        // An island with a contact slipping faster than FAST_SLIP_FACTOR · εf is in motion
        // (a pellet landing or sliding down the pile), and its last solve gets the rounds'
        // inexact tolerance (below).
        let fast_slip = FAST_SLIP_FACTOR * p.acceleration.eps_f;
        let fast_sliding =
            !exact && fric.iter().any(|x| x.kind == Friction::Dynamic && x.slip.0.hypot(x.slip.1) > fast_slip);
        let fixed_point = |warm_friction: bool| -> (IslandSolution, Real) {
            let mut sol = IslandSolution {
                f: f0.to_vec(),
                gt: if warm_friction { self.g0.to_vec() } else { vec![(0.0, 0.0); fric.len()] },
                report: None,
                tolerance: 0.0,
                iterations: 0,
                dropped: 0,
            };
            let mut clamped: Vec<Option<bool>> = vec![None; fric.len()];
            // How far the friction update from the warm normal forces moves b: the change of
            // "round −1", which sets the first round's tolerance of an iterative island below.
            let b_warm = (warm_friction && !fric.is_empty() && !exact).then(|| coupled_rhs(&sol.gt));
            if warm_friction && !fric.is_empty() {
                update(f0, &mut sol.gt, &mut clamped);
                clamped.iter_mut().for_each(|c| *c = None);
            }
            let mut b = if fric.is_empty() { self.b0.to_vec() } else { coupled_rhs(&sol.gt) };
            let warm_change = b_warm.map_or(0.0, |bw| max_abs_diff(&b, &bw));
            // Inexact fixed point (iterative islands): a round's normal solve only needs to be
            // a little more accurate than the fixed point itself, whose change per round is 1e-1
            // to 1e1 m/s² in a pile while the solver's tolerance is 1e-3 m/s². The last solve
            // is tight. The first round too is inexact, by the change of the warm friction
            // update: solved tightly it took 55 % of all iterations of a one-column pour
            // (spheres, D = 56 mm, the first 5 s: 1948 of 15 907 islands hit the APGD + PGS
            // caps in it), and the friction it was solved against then moved b by 1–7 m/s².
            let mut round_tol = tol.max(INEXACT_ROUND_FACTOR * warm_change);
            let (mut last_tol, mut change) = (round_tol, 0.0);
            // The round with the smallest change so far: (change, solution, b, its tolerance).
            let mut best: Option<(Real, IslandSolution, Vec<Real>, Real)> = None;
            let mut prev_change = Real::INFINITY;
            for round in 0..rounds {
                solve(&b, &mut sol, round_tol);
                last_tol = round_tol;
                if fric.is_empty() {
                    break;
                }
                update(&sol.f, &mut sol.gt, &mut clamped);
                // Converged once friction changes the normal problem by less than the solver's
                // own tolerance (exactly zero for a sphere on a plane: one round).
                let b_new = coupled_rhs(&sol.gt);
                change = max_abs_diff(&b_new, &b);
                b = b_new;
                if change <= friction_tol {
                    break;
                }
                if let Some((best_change, ..)) = best {
                    if change > DIVERGENCE_FACTOR * best_change {
                        let (c, s, bb, lt) = best.take().expect("checked");
                        (change, b, last_tol) = (c, bb, lt);
                        sol = IslandSolution { iterations: sol.iterations, ..s };
                        break;
                    }
                }
                if best.as_ref().is_none_or(|x| change < x.0) {
                    best = Some((change, sol.clone(), b.clone(), last_tol));
                }
                if !exact && sliding && round + 1 >= FRICTION_MIN_ROUNDS_ITERATIVE {
                    let contraction = change / prev_change;
                    let left = (rounds - round - 1) as i32;
                    if contraction >= 1.0 || contraction.powi(left) * change > friction_tol {
                        break;
                    }
                }
                prev_change = change;
                if !exact {
                    round_tol = tol.max(INEXACT_ROUND_FACTOR * change);
                }
            }
            // The last solve is tight, except in an island in motion whose fixed point ended
            // unconverged: its b is itself off by about the last round's change, so it gets the
            // rounds' tolerance. Islands near rest keep the tight solve, which is what brings a
            // bed to rest (loosened for every sliding island, two of eight small cylinder beds
            // crept for 30 s).
            if last_tol > tol {
                let final_tol = if fast_sliding { tol.max(INEXACT_ROUND_FACTOR * change) } else { tol };
                solve(&b, &mut sol, final_tol);
            }
            (sol, change)
        };
        // Warm friction (from last substep's normal forces) saves rounds in a pile: in the
        // 100-sphere bench, starting cold gives 486 instead of 326 iterations per substep and
        // 113 unconverged islands instead of 0. But when a contact's key changed, its warm force
        // is 0 while its partner's is whole, the friction of those forces is far from the answer,
        // and the fixed point (contracting at ~0.85 per round) ends its 30 rounds unconverged:
        // in the 5-cylinder stack that left static forces of 1e-4 N unbalanced and |v| 1.3e-6
        // m/s. So a small island whose warm fixed point fails is solved again from cold friction,
        // and the run with the smaller final change is kept.
        let (mut sol, change) = fixed_point(true);
        if exact && change > friction_tol {
            let (cold, cold_change) = fixed_point(false);
            let spent = sol.iterations + cold.iterations;
            if cold_change < change {
                sol = cold;
            }
            sol.iterations = spent;
        }
        // An iteratively solved island at rest in friction (no contact sliding) whose fixed point
        // ended unconverged: polish by coupled Gauss–Seidel from the fixed point's answer
        // (`coupled_pgs`). Only there: the beds that crept (rings in a 40.45 mm tube) are all
        // static, while in a pour, where contacts slide, the coupled sweeps converge slowly
        // (100-row sphere islands hit 1000 sweeps) and the fixed point's answer settles the
        // bed anyway.
        let all_static = !fric.is_empty() && fric.iter().all(|x| x.kind == Friction::Static);
        if !exact && all_static && change > friction_tol && p.acceleration.coupled_friction_sweeps > 0 {
            let problem = CoupledProblem {
                sys,
                b0: self.b0,
                fric,
                free_t: self.free_t,
                dt,
                accelerate: p.acceleration.coupled_friction_nncg,
            };
            let rep = problem.solve(&mut sol.f, &mut sol.gt, tol, p.acceleration.coupled_friction_sweeps);
            sol.iterations += rep.iterations;
            sol.report = Some(rep);
            sol.tolerance = tol;
        }
        // Dropping friction changes the normal problem (friction enters it through b).
        self.guard(&mut sol, |s| solve(&coupled_rhs(&s.gt), s, tol));
        sol
    }
}

/// The largest absolute difference of two equally long vectors.
fn max_abs_diff(x: &[Real], y: &[Real]) -> Real {
    x.iter().zip(y).map(|(a, b)| (a - b).abs()).fold(0.0, Real::max)
}
