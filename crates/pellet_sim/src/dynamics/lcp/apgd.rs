//! Accelerated projected gradient descent (Nesterov with backtracking and adaptive restart), as
//! in Chrono's ChSolverAPGD. Matrix-free: needs only y ↦ A y.

use super::{residual_with_diag, LcpMatrix, LcpReport, LcpSolver, LcpStatus, StallWindow};
use crate::math::Real;

/// APGD solver.
#[derive(Debug, Clone)]
pub struct Apgd {
    /// Iteration cap.
    pub max_iterations: usize,
    /// Stop once the cap is out of reach ([`cap_out_of_reach`](super::cap_out_of_reach)): for callers with a fallback.
    pub stall_test: bool,
}

impl Default for Apgd {
    fn default() -> Self {
        Self { max_iterations: 200, stall_test: false }
    }
}

fn dot(x: &[Real], y: &[Real]) -> Real {
    x.iter().zip(y).map(|(a, b)| a * b).sum()
}

fn residual(diag: &[Real], b: &[Real], f: &[Real], af: &[Real]) -> (Real, Real) {
    residual_with_diag(|i| diag[i], b, f, af)
}

impl LcpSolver for Apgd {
    fn solve(&mut self, a: &dyn LcpMatrix, b: &[Real], f: &mut [Real], tol: Real) -> LcpReport {
        let n = a.dim();
        if n == 0 {
            return LcpReport { iterations: 0, residual: 0.0, min_a: 0.0, status: LcpStatus::Converged };
        }
        let mut x: Vec<Real> = f.iter().map(|v| v.max(0.0)).collect();
        let diag: Vec<Real> = (0..n).map(|i| a.diag(i)).collect();
        let mut ax = vec![0.0; n];
        a.mul(&x, &mut ax);
        let (r0, m0) = residual(&diag, b, &x, &ax);
        let mut best = x.clone();
        let (mut r_best, mut min_a_best) = (r0, m0);
        if r_best <= tol {
            f.copy_from_slice(&best);
            return LcpReport { iterations: 0, residual: r_best, min_a: min_a_best, status: LcpStatus::Converged };
        }
        // Lipschitz estimate from the diagonal bound and a probe direction.
        let ones: Vec<Real> = x.iter().map(|v| v - 1.0).collect();
        let mut tmp = vec![0.0; n];
        a.mul(&ones, &mut tmp);
        let mut l = (dot(&tmp, &tmp).sqrt() / dot(&ones, &ones).sqrt().max(1e-300))
            .max(diag.iter().copied().fold(0.0, Real::max))
            .max(1e-300);
        let mut y = x.clone();
        let mut ay = ax.clone();
        let mut theta: Real = 1.0;
        let mut xn = vec![0.0; n];
        let mut axn = vec![0.0; n];
        let mut g = vec![0.0; n];
        let mut it = 0;
        let mut stall = StallWindow::new(r_best);
        // The vector work is fused into three passes per iteration (gradient with q(y); the
        // projected step; q(xn) with the residual and the restart test) with every sum taken
        // in index order as before, so the iterates are bit-identical to the unfused loops.
        while it < self.max_iterations {
            it += 1;
            let (mut y_ay, mut b_y): (Real, Real) = (-0.0, -0.0);
            for (((gi, &ayi), &bi), &yi) in g.iter_mut().zip(&ay).zip(b).zip(&y) {
                *gi = ayi + bi;
                y_ay += yi * ayi;
                b_y += bi * yi;
            }
            let qy = 0.5 * y_ay + b_y;
            let (r, min_a, restart) = loop {
                // Projected gradient step and the sufficient-decrease test, fused.
                // (Iterators, not indices: with bounds checks the two sums lived on the stack
                // and this loop was a tenth of a pack run.)
                let (mut gd, mut dd): (Real, Real) = (0.0, 0.0);
                for ((xi, &yi), &gi) in xn.iter_mut().zip(&y).zip(&g) {
                    *xi = (yi - gi / l).max(0.0);
                    let d = *xi - yi;
                    gd += gi * d;
                    dd += d * d;
                }
                a.mul(&xn, &mut axn);
                let (mut x_ax, mut b_x, mut g_dx): (Real, Real, Real) = (-0.0, -0.0, -0.0);
                let (mut r, mut min_a): (Real, Real) = (0.0, 0.0);
                for (i, (&xni, &axni)) in xn.iter().zip(&axn).enumerate() {
                    x_ax += xni * axni;
                    b_x += b[i] * xni;
                    g_dx += g[i] * (xni - x[i]);
                    let ai = axni + b[i];
                    r = r.max((diag[i] * xni).min(ai).abs());
                    min_a = min_a.min(ai);
                }
                let qx = 0.5 * x_ax + b_x;
                if qx <= qy + gd + 0.5 * l * dd + 1e-14 * qy.abs() || l > 1e300 {
                    break (r, min_a, g_dx > 0.0);
                }
                l *= 2.0;
            };
            let theta_n = (-theta * theta + theta * (theta * theta + 4.0).sqrt()) / 2.0;
            let beta = theta * (1.0 - theta) / (theta * theta + theta_n);
            if r < r_best {
                best.copy_from_slice(&xn);
                r_best = r;
                min_a_best = min_a;
            }
            if r_best <= tol {
                break;
            }
            if self.stall_test && stall.hopeless(it, r_best, self.max_iterations, tol) {
                break;
            }
            if restart {
                y.copy_from_slice(&xn);
                ay.copy_from_slice(&axn);
                theta = 1.0;
            } else {
                for (((yi, ayi), (&xni, &xi)), (&axni, &axi)) in
                    y.iter_mut().zip(ay.iter_mut()).zip(xn.iter().zip(&x)).zip(axn.iter().zip(&ax))
                {
                    *yi = xni + beta * (xni - xi);
                    *ayi = axni + beta * (axni - axi);
                }
                theta = theta_n;
            }
            // x ← xn (xn is overwritten by the next step).
            std::mem::swap(&mut x, &mut xn);
            std::mem::swap(&mut ax, &mut axn);
            l *= 0.9;
        }
        f.copy_from_slice(&best);
        LcpReport {
            iterations: it,
            residual: r_best,
            min_a: min_a_best,
            status: if r_best <= tol { LcpStatus::Converged } else { LcpStatus::MaxIterations },
        }
    }
}
