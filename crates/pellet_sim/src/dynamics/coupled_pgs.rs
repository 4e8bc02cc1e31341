//! Normal forces and static friction of one island in one projected Gauss–Seidel: every sweep
//! visits each contact, updates its normal multiplier (f ≥ 0) and then its static friction, in
//! the disc |g| ≤ μ f of the normal force just computed.
//!
//! Why: the fixed point of `island_solve` alternates a full normal solve with a few sweeps of
//! static friction at fixed normal forces. On islands of ~1300 rows (a ring bed of 98 rings
//! in a 40.45 mm tube) its 10 rounds × 5 sweeps end far from the answer every substep, and the
//! bed creeps. Coupled in one sweep, a change of a normal force reaches the
//! friction bound of the same contact at once, and each sweep costs one pass over the rows, so
//! the cost is bounded by the sweep cap. `island_solve` uses it only on islands whose
//! frictional contacts are all static, so dynamic (sliding) entries are left as given.

use super::friction_update::{add_friction_response, static_step, Friction, FrictionEntry};
use super::lcp::{LcpReport, LcpStatus};
use super::polish_momentum::Momentum;
use super::rows::{load_pair, store_pair, RowSystem};
use crate::math::Real;

/// One island's coupled problem.
pub struct CoupledProblem<'a> {
    /// Normal rows.
    pub sys: &'a RowSystem,
    /// Normal right-hand side without friction, m/s².
    pub b0: &'a [Real],
    /// Frictional contacts.
    pub fric: &'a [FrictionEntry],
    /// Free tangential accelerations of `fric` along t1, t2, m/s².
    pub free_t: &'a [(Real, Real)],
    /// Substep, s.
    pub dt: Real,
    /// A nonsmooth conjugate-gradient step after each forward–backward pair of sweeps
    /// (`polish_momentum`).
    pub accelerate: bool,
}

impl CoupledProblem<'_> {
    /// Solves from the warm start in `f` (normal) and `gt` (friction) until no row moves its
    /// acceleration by more than `tol` (m/s²) in a sweep and the normal rows' natural residual
    /// is below `tol`, or `max_sweeps` sweeps. Sweeps alternate forward and backward. The
    /// report's residual is the worse of the two measures.
    ///
    /// Gauss–Seidel with a friction disc that follows the normal force is not a projection onto
    /// a fixed convex set and can diverge, by the same feedback (friction raising the normal
    /// forces that bound it) that made `island_solve`'s fixed point diverge on a wedged ring (see
    /// its `DIVERGENCE_FACTOR`); not seen in these sweeps so far. So the iterate with the smallest
    /// measure is kept, and the sweeps stop once the measure has grown a thousandfold over the
    /// best: the answer is never worse than the warm start.
    pub fn solve(&self, f: &mut [Real], gt: &mut [(Real, Real)], tol: Real, max_sweeps: usize) -> LcpReport {
        let (sys, fric) = (self.sys, self.fric);
        let n = sys.rows.len();
        let mut entry_of: Vec<Option<usize>> = vec![None; n];
        for (e, x) in fric.iter().enumerate() {
            entry_of[x.contact] = Some(e);
        }
        f.iter_mut().for_each(|fi| *fi = fi.max(0.0));
        let mut acc = sys.response(f);
        add_friction_response(fric, gt, &mut acc);
        let (mut sweeps, mut worst, mut min_a) = (0, Real::INFINITY, 0.0);
        // The best measured iterate: (measure, min_a, f, gt). Sweep k measures the iterate it
        // starts from, so that iterate is saved before the sweep.
        let mut best: (Real, Real, Vec<Real>, Vec<(Real, Real)>) = (Real::INFINITY, 0.0, Vec::new(), Vec::new());
        let (mut start_f, mut start_gt) = (f.to_vec(), gt.to_vec());
        let mut momentum = self.accelerate.then(|| Momentum::new(n, fric.len(), acc.len()));
        while sweeps < max_sweeps && worst > tol {
            if sweeps > 0 && worst.is_finite() && worst < best.0 {
                best = (worst, min_a, std::mem::take(&mut start_f), std::mem::take(&mut start_gt));
            } else if sweeps > 0 && (worst.is_nan() || worst > 1e3 * best.0) {
                break;
            }
            start_f.clear();
            start_f.extend_from_slice(f);
            start_gt.clear();
            start_gt.extend_from_slice(gt);
            sweeps += 1;
            (worst, min_a) = (0.0, 0.0);
            if let Some(m) = momentum.as_mut().filter(|_| sweeps % 2 == 1) {
                m.start(f, gt, &acc);
            }
            for k in 0..n {
                let i = if sweeps % 2 == 1 { k } else { n - 1 - k };
                let row = &sys.rows[i];
                // A contact with static friction: its normal row and friction together.
                if let Some(e) = entry_of[i].filter(|&e| fric[e].kind == Friction::Static) {
                    let (w, a) = self.contact_step(i, e, f, &mut gt[e], &mut acc);
                    worst = worst.max(w);
                    if let Some(a) = a {
                        min_a = Real::min(min_a, a);
                    }
                } else if row.diag > 0.0 {
                    let a = self.b0[i] + row.dot(&acc);
                    let (measure, new) = normal_step(row.diag, row.inv_diag, f[i], a);
                    worst = worst.max(measure);
                    min_a = Real::min(min_a, a);
                    if new != f[i] {
                        row.add_response(new - f[i], &mut acc);
                        f[i] = new;
                    }
                }
            }
            // After a backward sweep (the pair's end), unless the pair's start was converged:
            // the iterate then is the sweep's answer, as without the step.
            if let Some(m) = momentum.as_mut().filter(|_| sweeps % 2 == 0 && worst > tol) {
                m.step(sys, fric, f, gt, &mut acc);
            }
        }
        if worst <= tol {
            return LcpReport { iterations: sweeps, residual: worst, min_a, status: LcpStatus::Converged };
        }
        // Not converged: the last sweep's measure belongs to the iterate it started from.
        if worst.is_finite() && worst < best.0 {
            best = (worst, min_a, start_f, start_gt);
        }
        if !best.2.is_empty() {
            f.copy_from_slice(&best.2);
            gt.copy_from_slice(&best.3);
        }
        LcpReport { iterations: sweeps, residual: best.0, min_a: best.1, status: LcpStatus::MaxIterations }
    }
}

impl CoupledProblem<'_> {
    /// One sweep's visit of contact `i` with static friction entry `e`: its normal multiplier,
    /// then its friction, with both bodies' 6 accumulator entries in registers. The arithmetic
    /// of the row-by-row visit in [`Self::solve`], so the same bits; three rows' products over
    /// the stacked accumulator (reads, writes and bounds checks of the same 12 entries) were
    /// most of a high-friction cylinder bed's time. Returns the visit's contribution to the
    /// sweep's measure and the normal row's acceleration (none if the row has no diagonal).
    fn contact_step(
        &self,
        i: usize,
        e: usize,
        f: &mut [Real],
        g: &mut (Real, Real),
        acc: &mut [Real],
    ) -> (Real, Option<Real>) {
        let (row, x) = (&self.sys.rows[i], &self.fric[e]);
        let (mut ua, mut ub) = load_pair(acc, row.a, row.b);
        let (mut worst, mut normal_a) = (0.0, None);
        if row.diag > 0.0 {
            let a = self.b0[i] + row.dot_pair(&ua, &ub);
            let new;
            (worst, new) = normal_step(row.diag, row.inv_diag, f[i], a);
            normal_a = Some(a);
            if new != f[i] {
                row.add_response_pair(new - f[i], &mut ua, &mut ub);
                f[i] = new;
            }
        }
        let jt = (x.t1.dot_pair(&ua, &ub), x.t2.dot_pair(&ua, &ub));
        let (n1, n2) = static_step(x, self.free_t[e], jt, *g, f[i], self.dt);
        let change = ((n1 - g.0) * x.t1.diag).abs().max(((n2 - g.1) * x.t2.diag).abs());
        worst = Real::max(worst, change);
        x.t1.add_response_pair(n1 - g.0, &mut ua, &mut ub);
        x.t2.add_response_pair(n2 - g.1, &mut ua, &mut ub);
        *g = (n1, n2);
        store_pair(acc, row.a, row.b, &ua, &ub);
        (worst, normal_a)
    }
}

/// A normal row's Gauss–Seidel step from its multiplier `f` and acceleration `a` (diagonal
/// `diag` > 0, reciprocal `inv_diag`): its contribution to the sweep's measure (the natural
/// residual |min(diag f, a)|) and its new multiplier, projected on f ≥ 0. A row without force
/// that separates keeps none; its update would give ±0, which the caller's `new != f` treats
/// as no change, so the multiply is left out.
#[inline]
fn normal_step(diag: Real, inv_diag: Real, f: Real, a: Real) -> (Real, Real) {
    let measure = (diag * f).min(a).abs();
    let new = if f == 0.0 && a >= 0.0 { f } else { (f - a * inv_diag).max(0.0) };
    (measure, new)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::rows::{BodyMass, Row};
    use crate::math::{Mat3, Vec3};

    const G: Real = 9.81;

    /// A unit-mass body resting at its centre on a plane tilted by `angle`: the normal force and
    /// static friction of one contact, with gravity resolved in the plane's frame.
    fn incline(angle: Real, mu: Real) -> (Real, (Real, Real), LcpReport) {
        let masses = [BodyMass { inv_mass: 1.0, inv_inertia: Mat3::identity() }];
        let (n, t1, t2) = (Vec3::z(), Vec3::x(), Vec3::y());
        let z = Vec3::zeros();
        let sys = RowSystem::new(vec![Row::new(0, None, &z, &z, &n, &masses)], 1);
        let fric = [FrictionEntry {
            contact: 0,
            kind: Friction::Static,
            t1: Row::new(0, None, &z, &z, &t1, &masses),
            t2: Row::new(0, None, &z, &z, &t2, &masses),
            slip: (0.0, 0.0),
            mu,
        }];
        // Gravity in the plane's frame: −g cos θ along n, −g sin θ along t1.
        let b0 = [-G * angle.cos()];
        let free_t = [(-G * angle.sin(), 0.0)];
        let problem = CoupledProblem { sys: &sys, b0: &b0, fric: &fric, free_t: &free_t, dt: 1e-3, accelerate: false };
        let (mut f, mut gt) = (vec![0.0], vec![(0.0, 0.0)]);
        let rep = problem.solve(&mut f, &mut gt, 1e-9, 100);
        (f[0], gt[0], rep)
    }

    #[test]
    fn static_friction_holds_a_body_below_the_friction_angle() {
        let angle = Real::atan(0.3);
        let (f, g, rep) = incline(angle, 0.5);
        assert_eq!(rep.status, LcpStatus::Converged, "{rep:?}");
        assert!((f - G * angle.cos()).abs() < 1e-9, "normal force {f}");
        assert!((g.0 - G * angle.sin()).abs() < 1e-9 && g.1.abs() < 1e-12, "friction {g:?}");
    }

    #[test]
    fn friction_is_capped_at_mu_f_above_the_friction_angle() {
        let angle = Real::atan(0.7);
        let (f, g, _) = incline(angle, 0.5);
        assert!((f - G * angle.cos()).abs() < 1e-9, "normal force {f}");
        assert!((g.0 - 0.5 * f).abs() < 1e-9, "friction {g:?} should be μ f = {}", 0.5 * f);
    }

    /// Two unit masses stacked on the floor: contact forces 2 m g (floor) and m g (between), with
    /// a row order (top first) that makes Gauss–Seidel iterate.
    #[test]
    fn a_two_body_stack_carries_its_weight() {
        let masses = vec![BodyMass { inv_mass: 1.0, inv_inertia: Mat3::identity() }; 2];
        let (n, z) = (Vec3::z(), Vec3::zeros());
        let rows = vec![Row::new(1, Some(0), &z, &z, &n, &masses), Row::new(0, None, &z, &z, &n, &masses)];
        let sys = RowSystem::new(rows, 2);
        // Free normal accelerations: between the bodies 0, at the floor −g.
        let b0 = [0.0, -G];
        let problem = CoupledProblem { sys: &sys, b0: &b0, fric: &[], free_t: &[], dt: 1e-3, accelerate: false };
        let mut f = vec![0.0, 0.0];
        let rep = problem.solve(&mut f, &mut [], 1e-9, 200);
        assert_eq!(rep.status, LcpStatus::Converged, "{rep:?}");
        assert!(rep.iterations > 2, "Gauss–Seidel needs sweeps here: {rep:?}");
        assert!((f[0] - G).abs() < 1e-8 && (f[1] - 2.0 * G).abs() < 1e-8, "forces {f:?}");
    }
}
