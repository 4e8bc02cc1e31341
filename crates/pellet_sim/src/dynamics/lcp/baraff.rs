//! Baraff's 1994 pivoting method (Dantzig-style principal pivoting).
//!
//! Dense and exact, O(n³): for small islands and as the reference in tests. The Cholesky factor
//! of the clamped block A_CC is updated incrementally (append a row, or delete one), so a pivot
//! costs O(|C|²). Indices whose clamping would make A_CC numerically singular are deferred and
//! revisited with a looser tolerance.

use super::{residual, DenseLcp, LcpMatrix, LcpReport, LcpSolver, LcpStatus};
use crate::math::Real;
use nalgebra::{Cholesky, DMatrix, DVector, Dyn};

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Set {
    Untreated,
    Clamped,
    NotClamped,
    Deferred,
}

/// The exact solver.
#[derive(Debug, Clone, Default)]
pub struct Baraff {
    /// Pivot cap as a multiple of n (0 means the default 50).
    pub pivot_cap_factor: usize,
}

struct State<'m> {
    a: &'m DMatrix<Real>,
    f: Vec<Real>,
    acc: Vec<Real>,
    set: Vec<Set>,
    /// Clamped indices in the order of the factor's rows.
    c_list: Vec<usize>,
    /// Cholesky factor of A_CC in `c_list` order (None while C is empty).
    chol: Option<Cholesky<Real, Dyn>>,
    pivots: usize,
    cap: usize,
    tol_d: Real,
}

enum Drive {
    Done,
    Infeasible,
    Cap,
}

impl State<'_> {
    fn clamped(&self) -> Vec<usize> {
        self.c_list.clone()
    }

    /// Solves A_CC x = rhs with the cached factor (`c_list` order).
    fn solve_cc(&self, rhs: &DVector<Real>) -> Option<DVector<Real>> {
        self.chol.as_ref().map(|ch| ch.solve(rhs))
    }

    /// Whether adding j to C keeps A_CC numerically non-singular (pivot ℓ² test).
    fn can_clamp(&self, c: &[usize], j: usize) -> bool {
        let ajj = self.a[(j, j)];
        if c.is_empty() {
            return ajj > 0.0;
        }
        let col = DVector::from_fn(c.len(), |i, _| self.a[(c[i], j)]);
        match self.solve_cc(&col) {
            Some(x) => ajj - col.dot(&x) > 1e-10 * ajj,
            None => false,
        }
    }

    /// Moves j into C, appending a row to the factor (call only after `can_clamp`).
    fn clamp(&mut self, j: usize) {
        let n = self.c_list.len();
        let col = DVector::from_fn(n + 1, |i, _| if i < n { self.a[(self.c_list[i], j)] } else { self.a[(j, j)] });
        self.chol = match self.chol.take() {
            Some(ch) => Some(ch.insert_column(n, col)),
            None => Cholesky::new(DMatrix::from_element(1, 1, col[0])),
        };
        self.c_list.push(j);
        self.set[j] = Set::Clamped;
    }

    /// Moves j out of C into N, deleting its row from the factor.
    fn unclamp(&mut self, j: usize) {
        if let Some(pos) = self.c_list.iter().position(|&i| i == j) {
            self.c_list.remove(pos);
            self.chol = match self.chol.take() {
                Some(ch) if !self.c_list.is_empty() => Some(ch.remove_column(pos)),
                _ => None,
            };
        }
        self.set[j] = Set::NotClamped;
    }

    fn drive(&mut self, d: usize, tol_a: Real) -> Drive {
        let n = self.f.len();
        while self.acc[d] < -tol_a {
            if self.pivots >= self.cap {
                return Drive::Cap;
            }
            self.pivots += 1;
            let c = self.clamped();
            let mut df = vec![0.0; n];
            df[d] = 1.0;
            if !c.is_empty() {
                let rhs = DVector::from_fn(c.len(), |i, _| -self.a[(c[i], d)]);
                let Some(x) = self.solve_cc(&rhs) else {
                    return Drive::Cap;
                };
                for (k, &i) in c.iter().enumerate() {
                    df[i] = x[k];
                }
            }
            // Δa = A Δf over the non-zero columns C ∪ {d} (column-major: contiguous).
            let mut da = vec![0.0; n];
            for &j in c.iter().chain(std::iter::once(&d)) {
                let w = df[j];
                for (x, aij) in da.iter_mut().zip(self.a.column(j).iter()) {
                    *x += w * aij;
                }
            }
            // max_step, ties broken by the smallest index (Bland's rule).
            let mut s = Real::INFINITY;
            let mut block = None;
            if da[d] > self.tol_d {
                s = -self.acc[d] / da[d];
                block = Some(d);
            }
            for i in 0..n {
                let cand = match self.set[i] {
                    Set::Clamped if df[i] < -self.tol_d => -self.f[i] / df[i],
                    Set::NotClamped if da[i] < -self.tol_d => -self.acc[i] / da[i],
                    _ => continue,
                };
                if cand < s || (cand == s && block.is_some_and(|b| i < b)) {
                    s = cand;
                    block = Some(i);
                }
            }
            let Some(j) = block else {
                return Drive::Infeasible;
            };
            let s = s.max(0.0);
            for i in 0..n {
                self.f[i] += s * df[i];
                self.acc[i] += s * da[i];
            }
            if j == d {
                self.acc[d] = 0.0;
                if self.can_clamp(&c, d) {
                    self.clamp(d);
                } else {
                    // Redundant with C: its acceleration is zero, no force needed.
                    self.set[d] = Set::NotClamped;
                }
                return Drive::Done;
            }
            match self.set[j] {
                Set::Clamped => {
                    self.f[j] = 0.0;
                    self.unclamp(j);
                }
                _ => {
                    self.acc[j] = 0.0;
                    if self.can_clamp(&c, j) {
                        self.clamp(j);
                    } else {
                        self.set[j] = Set::Deferred;
                    }
                }
            }
        }
        if self.set[d] == Set::Untreated || self.set[d] == Set::Deferred {
            self.set[d] = Set::NotClamped;
        }
        Drive::Done
    }
}

impl Baraff {
    /// Solves the dense problem; `f` is overwritten (pivoting starts from f = 0).
    pub fn solve_dense(&mut self, a: &DMatrix<Real>, b: &[Real], f: &mut [Real], tol: Real) -> LcpReport {
        let n = b.len();
        let max_diag = (0..n).map(|i| a[(i, i)]).fold(0.0, Real::max);
        let factor = if self.pivot_cap_factor == 0 { 50 } else { self.pivot_cap_factor };
        let mut st = State {
            a,
            f: vec![0.0; n],
            acc: b.to_vec(),
            set: vec![Set::Untreated; n],
            c_list: Vec::new(),
            chol: None,
            pivots: 0,
            cap: factor * n.max(1),
            tol_d: 1e-12 * max_diag.max(1e-300),
        };
        let mut status = LcpStatus::Converged;
        for pass_tol in [tol, 100.0 * tol] {
            let allowed = |s: Set| {
                if pass_tol == tol {
                    s == Set::Untreated
                } else {
                    s == Set::Deferred
                }
            };
            loop {
                let d = (0..n)
                    .filter(|&i| allowed(st.set[i]) && st.acc[i] < -pass_tol)
                    .min_by(|&i, &j| st.acc[i].total_cmp(&st.acc[j]).then(i.cmp(&j)));
                let Some(d) = d else { break };
                match st.drive(d, pass_tol) {
                    Drive::Done => {}
                    Drive::Infeasible => {
                        status = LcpStatus::Infeasible;
                        break;
                    }
                    Drive::Cap => {
                        status = LcpStatus::MaxIterations;
                        break;
                    }
                }
            }
            if status != LcpStatus::Converged {
                break;
            }
        }
        f.copy_from_slice(&st.f);
        let dense = DenseLcp(a.clone());
        let (r, min_a) = residual(&dense, b, f);
        LcpReport { iterations: st.pivots, residual: r, min_a, status }
    }
}

impl LcpSolver for Baraff {
    fn solve(&mut self, a: &dyn LcpMatrix, b: &[Real], f: &mut [Real], tol: Real) -> LcpReport {
        let dense = a.dense();
        self.solve_dense(&dense, b, f, tol)
    }
}
