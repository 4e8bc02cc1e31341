//! Projected Gauss–Seidel with symmetric (forward/backward) sweeps (physics.md §4.5).

use super::{residual, LcpMatrix, LcpReport, LcpSolver, LcpStatus};
use crate::math::Real;

/// PGS solver; rows are swept in index order, which callers make bottom-up.
#[derive(Debug, Clone)]
pub struct Pgs {
    /// Sweep cap.
    pub max_iterations: usize,
    /// Over-relaxation factor (1 = plain Gauss–Seidel).
    pub sor: Real,
}

impl Default for Pgs {
    fn default() -> Self {
        Self { max_iterations: 500, sor: 1.0 }
    }
}

impl LcpSolver for Pgs {
    fn solve(&mut self, a: &dyn LcpMatrix, b: &[Real], f: &mut [Real], tol: Real) -> LcpReport {
        let n = a.dim();
        let mut acc = vec![0.0; a.acc_len()];
        for (i, fi) in f.iter_mut().enumerate() {
            *fi = fi.max(0.0);
            if *fi != 0.0 {
                a.add_col(i, *fi, &mut acc);
            }
        }
        let mut it = 0;
        let (mut r, mut min_a) = residual(a, b, f);
        while it < self.max_iterations && r > tol {
            it += 1;
            let forward = it % 2 == 1;
            for k in 0..n {
                let i = if forward { k } else { n - 1 - k };
                let d = a.diag(i);
                if d <= 0.0 {
                    continue;
                }
                let ai = b[i] + a.row_dot(i, &acc);
                let new = (f[i] - self.sor * ai / d).max(0.0);
                if new != f[i] {
                    a.add_col(i, new - f[i], &mut acc);
                    f[i] = new;
                }
            }
            (r, min_a) = residual(a, b, f);
        }
        LcpReport {
            iterations: it,
            residual: r,
            min_a,
            status: if r <= tol { LcpStatus::Converged } else { LcpStatus::MaxIterations },
        }
    }
}
