//! The searches that place a rim sample's contact at its deepest point: along the rim (a rim
//! crossing the other body), then into the rim's two faces (a face lying against the other body
//! with its overlap cut off by the rims, which falls between the face's samples).

use super::samples::Rim;
use crate::math::{Real, Vec3};

/// Resolution of the search along a rim, as a fraction of its bracket: the minimum is placed
/// to about this, no coarser than 14 golden-section steps would (interval × 0.618¹⁴ ≈ 1.2e-3,
/// half of it either way).
const RIM_TOL: Real = 3e-4;
/// Evaluations after which the search along a rim stops (Brent's method takes about 6 on a
/// smooth minimum and 14 on a kink, where the golden section took 16).
const RIM_EVALS: usize = 40;
/// Golden-section iterations of the search into a face: its interval (`EDGE_BAND` · R_b,
/// ~70 µm for the paper's pellets) × 0.618¹² ≈ 3e-3, 0.2 µm, the resolution of the depth there.
const FACE_ITERS: usize = 12;

/// The minimum of `f` on [lo, hi] (f unimodal there), by Brent's method: parabolic steps
/// through the three best points, a golden-section step where a parabola would not shrink the
/// bracket fast enough. Returns (argmin, min). Why not golden section alone: the depth along a
/// rim is smooth except where it crosses an edge, and there parabolas converge in about half
/// the evaluations, each a signed distance and a sine and cosine of the rim angle.
pub(crate) fn rim_min(f: impl Fn(Real) -> Real, lo: Real, hi: Real) -> (Real, Real) {
    brent(f, lo, hi, RIM_TOL * (hi - lo), RIM_EVALS)
}

/// Brent's localmin (Forsythe, Malcolm and Moler's `fmin`), started from the bracket's middle,
/// with an absolute resolution `tol`.
fn brent(f: impl Fn(Real) -> Real, mut a: Real, mut b: Real, tol: Real, max_evals: usize) -> (Real, Real) {
    let c = 0.5 * (3.0 - 5f64.sqrt());
    let mut x = 0.5 * (a + b);
    let mut fx = f(x);
    let (mut w, mut fw, mut v, mut fv) = (x, fx, x, fx);
    let (mut d, mut e): (Real, Real) = (0.0, 0.0);
    for _ in 1..max_evals {
        let xm = 0.5 * (a + b);
        let tol2 = 2.0 * tol;
        if (x - xm).abs() <= tol2 - 0.5 * (b - a) {
            break;
        }
        let mut parabolic = false;
        if e.abs() > tol {
            let r = (x - w) * (fx - fv);
            let q = (x - v) * (fx - fw);
            let mut p = (x - v) * q - (x - w) * r;
            let mut q = 2.0 * (q - r);
            if q > 0.0 {
                p = -p;
            } else {
                q = -q;
            }
            let last = e;
            e = d;
            // The parabola's vertex, when it lies inside the bracket and the step is less
            // than half the one before last (else the search could stall).
            if p.abs() < (0.5 * q * last).abs() && p > q * (a - x) && p < q * (b - x) {
                d = p / q;
                let u = x + d;
                if u - a < tol2 || b - u < tol2 {
                    d = tol.copysign(xm - x);
                }
                parabolic = true;
            }
        }
        if !parabolic {
            e = if x >= xm { a - x } else { b - x };
            d = c * e;
        }
        let u = if d.abs() >= tol { x + d } else { x + tol.copysign(d) };
        let fu = f(u);
        if fu <= fx {
            if u >= x {
                a = x;
            } else {
                b = x;
            }
            (v, fv, w, fw, x, fx) = (w, fw, x, fx, u, fu);
        } else {
            if u < x {
                a = u;
            } else {
                b = u;
            }
            if fu <= fw || w == x {
                (v, fv, w, fw) = (w, fw, u, fu);
            } else if fu <= fv || v == x || v == w {
                (v, fv) = (u, fu);
            }
        }
    }
    (x, fx)
}

fn golden(f: impl Fn(Real) -> Real, mut lo: Real, mut hi: Real, iters: usize) -> (Real, Real) {
    let r = 0.5 * (5f64.sqrt() - 1.0);
    let mut x1 = hi - r * (hi - lo);
    let mut x2 = lo + r * (hi - lo);
    let (mut f1, mut f2) = (f(x1), f(x2));
    for _ in 0..iters {
        if f1 <= f2 {
            hi = x2;
            (x2, f2) = (x1, f1);
            x1 = hi - r * (hi - lo);
            f1 = f(x1);
        } else {
            lo = x1;
            (x1, f1) = (x2, f2);
            x2 = lo + r * (hi - lo);
            f2 = f(x2);
        }
    }
    if f1 <= f2 {
        (x1, f1)
    } else {
        (x2, f2)
    }
}

/// Cosine and sine of angles near `t0`, by the angle-sum formulas from `t0`'s own and a Taylor
/// series of the offset (within 1 ulp or so of `cos`/`sin` for offsets up to `NEAR`, `cos`/`sin`
/// themselves beyond): a rim search evaluates a dozen angles within one sample spacing of its
/// start, and `sin`/`cos` at each were a tenth of a cylinder bed's CPU.
#[derive(Debug, Clone, Copy)]
pub(crate) struct AngleNear {
    t0: Real,
    c0: Real,
    s0: Real,
}

/// Offsets (rad) the series covers: its first omitted terms, d¹⁷/17! and d¹⁸/18!, are below
/// 5e-22 there.
const NEAR: Real = 0.4;
/// Terms of the series after the first.
const SERIES: usize = 8;
/// 1/((2k)(2k + 1)) and 1/((2k − 1)(2k)) for k = 1…8: the ratios of consecutive terms.
const SIN_STEPS: [Real; SERIES] = steps(1);
const COS_STEPS: [Real; SERIES] = steps(0);

const fn steps(odd: usize) -> [Real; SERIES] {
    let mut r = [0.0; SERIES];
    let mut k = 0;
    while k < SERIES {
        let n = 2 * (k + 1) + odd;
        r[k] = 1.0 / ((n - 1) * n) as Real;
        k += 1;
    }
    r
}

impl AngleNear {
    pub(crate) fn new(t0: Real) -> Self {
        let (s0, c0) = t0.sin_cos();
        Self { t0, c0, s0 }
    }

    /// Angles near `t0`, whose cosine `c0` and sine `s0` are known already.
    pub(crate) fn with_cos_sin(t0: Real, c0: Real, s0: Real) -> Self {
        Self { t0, c0, s0 }
    }

    /// (cos t, sin t).
    pub(crate) fn cos_sin(&self, t: Real) -> (Real, Real) {
        let d = t - self.t0;
        if d.abs() > NEAR {
            let (s, c) = t.sin_cos();
            return (c, s);
        }
        let q = d * d;
        let mut sd = 1.0;
        let mut cd = 1.0;
        // Horner on the series: sin d = d (1 − d²/(2·3) (1 − d²/(4·5) (…))), cos likewise.
        for k in (0..SERIES).rev() {
            sd = 1.0 - q * SIN_STEPS[k] * sd;
            cd = 1.0 - q * COS_STEPS[k] * cd;
        }
        let sd = d * sd;
        (self.c0 * cd - self.s0 * sd, self.s0 * cd + self.c0 * sd)
    }

    /// The point of a rim circle (radius, height z) at angle `t`.
    pub(crate) fn rim_point(&self, radius: Real, z: Real, t: Real) -> Vec3 {
        let (c, s) = self.cos_sin(t);
        Vec3::new(radius * c, radius * s, z)
    }
}

/// The two faces that meet at `rim`'s point at angle `t` (body frame; `near` gives its cosine and sine): for each, the unit
/// direction that leaves the rim into the face at right angles to it, and the face's outward
/// normal. Cap first, then the side.
pub(crate) fn rim_faces(rim: &Rim, t: Real, near: &AngleNear) -> [(Vec3, Vec3); 2] {
    let (c, s) = near.cos_sin(t);
    let er = Vec3::new(c, s, 0.0);
    let ez = Vec3::new(0.0, 0.0, rim.z.signum());
    // An outer rim's cap runs inwards and its side faces out; a ring's bore rim the reverse.
    let out = if rim.outer { er } else { -er };
    [(-out, ez), (-ez, out)]
}

/// The deepest point of `f`, the other body's signed distance along a line leaving a rim point
/// into one of its faces (`f0` at the rim), within `len` of the rim: (offset, value) when it is
/// deeper than the rim point. The other body's SDF is convex for a cylinder, so along a line it
/// has one valley: where it rises over the search's resolution from the rim, the rim is its
/// bottom to that resolution, and one evaluation settles it (the common case, a rim crossing).
/// Inside the other body near one of its edges the valley lies where its two faces are equally
/// deep, a kink that golden section brackets at its own rate.
pub(crate) fn deepest_on_line(f: impl Fn(Real) -> Real, f0: Real, len: Real) -> Option<(Real, Real)> {
    let tol = len * 0.618f64.powi(FACE_ITERS as i32);
    if f(tol) >= f0 {
        return None;
    }
    let (u, v) = golden(f, tol, len, FACE_ITERS);
    (v < f0).then_some((u, v))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn angles_near_a_start_match_cos_and_sin() {
        for t0 in [0.0, 0.3, 1.9, -2.5, 6.1] {
            let near = AngleNear::new(t0);
            for k in -40..=40 {
                let t = t0 + 0.0125 * k as Real;
                let (c, s) = near.cos_sin(t);
                assert!((c - t.cos()).abs() < 4e-16 && (s - t.sin()).abs() < 4e-16, "t0 {t0}, t {t}: {c} {s}");
            }
        }
    }

    #[test]
    fn brent_finds_a_smooth_minimum_and_a_kink_to_its_resolution() {
        let smooth = |t: Real| (t - 0.0123).powi(2) + 1.0;
        let (t, v) = rim_min(smooth, -0.05, 0.05);
        assert!((t - 0.0123).abs() < 3e-4 * 0.1 && (v - 1.0).abs() < 1e-9, "{t} {v}");
        let kink = |t: Real| 2.0 * (t - 0.031).max(0.0) - (t - 0.031).min(0.0);
        let (t, _) = rim_min(kink, -0.05, 0.05);
        assert!((t - 0.031).abs() < 3e-4 * 0.1, "{t}");
    }
}
