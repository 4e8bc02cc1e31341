//! Linear complementarity problems a = A f + b, f ≥ 0, a ≥ 0, f·a = 0: the resting contacts of the
//! force-level stepper.
//!
//! One problem, several solvers behind one interface: Baraff's exact pivoting method (small
//! islands, reference), APGD and PGS (large islands). All report residual, iterations, status.

pub mod apgd;
pub mod baraff;
pub mod mprgp;
pub mod pgs;

use crate::math::Real;
use crate::params::IterativeSolver;
use nalgebra::DMatrix;

/// Access to the matrix A of an LCP, either dense or matrix-free.
///
/// The "accumulator" methods support Gauss–Seidel: `acc` is an auxiliary vector (for contact
/// systems the stacked body velocity changes M⁻¹Jᵀf) such that (A f)_i = row_dot(i, acc) when
/// `acc` was built by `add_col` over all columns.
pub trait LcpMatrix {
    /// Number of rows.
    fn dim(&self) -> usize;
    /// Diagonal entry A_ii.
    fn diag(&self, i: usize) -> Real;
    /// y = A x.
    fn mul(&self, x: &[Real], y: &mut [Real]);
    /// Length of the accumulator vector.
    fn acc_len(&self) -> usize;
    /// (A f)_i from the accumulator.
    fn row_dot(&self, i: usize, acc: &[Real]) -> Real;
    /// acc += s · (column i in accumulator space).
    fn add_col(&self, i: usize, s: Real, acc: &mut [Real]);
    /// The dense matrix.
    fn dense(&self) -> DMatrix<Real> {
        let n = self.dim();
        let mut m = DMatrix::zeros(n, n);
        let mut e = vec![0.0; n];
        let mut y = vec![0.0; n];
        for j in 0..n {
            e[j] = 1.0;
            self.mul(&e, &mut y);
            for i in 0..n {
                m[(i, j)] = y[i];
            }
            e[j] = 0.0;
        }
        m
    }
}

/// A dense matrix as an [`LcpMatrix`] (the accumulator is A f itself).
#[derive(Debug, Clone)]
pub struct DenseLcp(pub DMatrix<Real>);

impl LcpMatrix for DenseLcp {
    fn dim(&self) -> usize {
        self.0.nrows()
    }
    fn diag(&self, i: usize) -> Real {
        self.0[(i, i)]
    }
    fn mul(&self, x: &[Real], y: &mut [Real]) {
        for (i, yi) in y.iter_mut().enumerate() {
            *yi = (0..x.len()).map(|j| self.0[(i, j)] * x[j]).sum();
        }
    }
    fn acc_len(&self) -> usize {
        self.0.nrows()
    }
    fn row_dot(&self, i: usize, acc: &[Real]) -> Real {
        acc[i]
    }
    fn add_col(&self, i: usize, s: Real, acc: &mut [Real]) {
        for (k, a) in acc.iter_mut().enumerate() {
            *a += s * self.0[(k, i)];
        }
    }
    fn dense(&self) -> DMatrix<Real> {
        self.0.clone()
    }
}

/// How a solve ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LcpStatus {
    /// Converged to the tolerance.
    Converged,
    /// Hit the iteration or pivot cap; the best iterate is returned.
    MaxIterations,
    /// No solution exists (e.g. inconsistent b on redundant rows).
    Infeasible,
}

/// What a solver reports.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LcpReport {
    /// Iterations (iterative solvers) or pivots (Baraff).
    pub iterations: usize,
    /// Natural residual max_i |min(A_ii f_i, a_i)|, in the units of b.
    pub residual: Real,
    /// Most negative a_i (unsupported acceleration), ≤ 0.
    pub min_a: Real,
    /// Outcome.
    pub status: LcpStatus,
}

/// A solver of the LCP. `f` holds the warm start on entry and the answer on return.
pub trait LcpSolver {
    /// Solves a = A f + b to residual `tol`.
    fn solve(&mut self, a: &dyn LcpMatrix, b: &[Real], f: &mut [Real], tol: Real) -> LcpReport;
}

/// Iterations over which PGS (as the fallback of APGD or MPRGP) and APGD (when Baraff follows)
/// measure their contraction to decide whether their cap is still in reach.
pub const STALL_WINDOW: usize = 50;

/// At the end of a window (every [`STALL_WINDOW`] sweeps): true when the window's contraction
/// of the best residual, `r_best / window_start`, kept up for the sweeps left before `cap`,
/// would not bring it to `tol` (the friction rounds' test). In a 3.55 N cylinder pour (1.5 s)
/// 3093 island solves fell back to PGS after APGD's 200 iterations (the redundant rows of
/// cylinder contacts); 2983 of them ran PGS's 500 sweeps to no avail, most ending worse than
/// they started, and those sweeps were 60 % of all solver iterations. All those islands had
/// 43–54 rows, so Baraff solved each again after them; APGD's 200 iterations before were
/// another 25 %. A linear extrapolation misjudges the plateaus of PGS and of accelerated
/// methods on ill-conditioned random systems (T12.4: PGS capped on 7 of 200 at 20 000 sweeps
/// instead of 1, APGD stopped on a system it solves by 2000), so only fallbacks use it.
pub fn cap_out_of_reach(r_best: Real, window_start: Real, it: usize, cap: usize, tol: Real) -> bool {
    let windows_left = cap.saturating_sub(it) as Real / STALL_WINDOW as Real;
    let contraction = r_best / window_start;
    contraction >= 1.0 || contraction.powf(windows_left) * r_best > tol
}

/// [`cap_out_of_reach`] as a solver applies it: at the end of every window, against the best
/// residual at the window's start.
pub(crate) struct StallWindow {
    start: Real,
}

impl StallWindow {
    /// A first window starting from residual `r0`.
    pub(crate) fn new(r0: Real) -> Self {
        Self { start: r0 }
    }

    /// After iteration `it`, with the best residual so far: true when the solver should stop.
    pub(crate) fn hopeless(&mut self, it: usize, r_best: Real, cap: usize, tol: Real) -> bool {
        if !it.is_multiple_of(STALL_WINDOW) {
            return false;
        }
        if cap_out_of_reach(r_best, self.start, it, cap, tol) {
            return true;
        }
        self.start = r_best;
        false
    }
}

/// Natural residual and most negative a of `f`.
pub fn residual(a: &dyn LcpMatrix, b: &[Real], f: &[Real]) -> (Real, Real) {
    let mut af = vec![0.0; f.len()];
    a.mul(f, &mut af);
    residual_from(a, b, f, &af)
}

/// As [`residual`] with A f already computed.
pub fn residual_from(a: &dyn LcpMatrix, b: &[Real], f: &[Real], af: &[Real]) -> (Real, Real) {
    residual_with_diag(|i| a.diag(i), b, f, af)
}

/// As [`residual_from`] with the diagonal given directly (APGD reads it once per solve: through
/// the trait object it was 2 % of a pack run, perf).
pub(crate) fn residual_with_diag(diag: impl Fn(usize) -> Real, b: &[Real], f: &[Real], af: &[Real]) -> (Real, Real) {
    let mut r: Real = 0.0;
    let mut min_a: Real = 0.0;
    for i in 0..f.len() {
        let ai = af[i] + b[i];
        r = r.max((diag(i) * f[i]).min(ai).abs());
        min_a = min_a.min(ai);
    }
    (r, min_a)
}

/// Solves an island's LCP (Baraff to `exact_tol`, iterative solvers to `tol`) with the solver its size calls for: Baraff up to `max_exact` rows
/// (falling back to PGS if pivoting fails), else the iterative solver (APGD or MPRGP with a PGS
/// polish). `f` carries the warm start for the iterative path. PGS after APGD or MPRGP
/// stops once its cap is out of reach ([`cap_out_of_reach`]); with `exact_follows` (the caller
/// solves the island again by Baraff when this ends unconverged) APGD does too.
#[allow(clippy::too_many_arguments)]
pub fn solve_auto(
    a: &dyn LcpMatrix,
    b: &[Real],
    f: &mut [Real],
    exact_tol: Real,
    tol: Real,
    max_exact: usize,
    solver: IterativeSolver,
    apgd_iterations: usize,
    pgs_iterations: usize,
    exact_follows: bool,
) -> LcpReport {
    if a.dim() <= max_exact {
        let rep = baraff::Baraff::default().solve(a, b, f, exact_tol);
        if rep.status == LcpStatus::Converged || rep.status == LcpStatus::Infeasible {
            return rep;
        }
    }
    let first = match solver {
        IterativeSolver::Apgd => {
            let mut apgd = apgd::Apgd { max_iterations: apgd_iterations, stall_test: exact_follows };
            apgd.solve(a, b, f, tol)
        }
        IterativeSolver::Mprgp => mprgp::Mprgp { max_iterations: apgd_iterations }.solve(a, b, f, tol),
    };
    if first.status == LcpStatus::Converged {
        return first;
    }
    let mut rep = pgs::Pgs { max_iterations: pgs_iterations, sor: 1.0, stall_test: true }.solve(a, b, f, tol);
    rep.iterations += first.iterations;
    rep
}
