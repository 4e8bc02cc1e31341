//! The searches that place a rim sample's contact at its deepest point: along the rim (a rim
//! crossing the other body), then into the rim's two faces (a face lying against the other body
//! with its overlap cut off by the rims, which falls between the face's samples).

use super::samples::Rim;
use crate::math::{Real, Vec3};

/// Golden-section iterations of the rim refinement (interval × 0.618¹⁴ ≈ 1.2e-3).
const GOLDEN_ITERS: usize = 14;
/// Golden-section iterations of the search into a face: its interval (`EDGE_BAND` · R_b,
/// ~70 µm for the paper's pellets) × 0.618¹² ≈ 3e-3, 0.2 µm, the resolution of the depth there.
const FACE_ITERS: usize = 12;

/// Golden-section minimum of `f` on [lo, hi] (f unimodal there); returns (argmin, min).
pub(crate) fn golden_min(f: impl Fn(Real) -> Real, lo: Real, hi: Real) -> (Real, Real) {
    golden(f, lo, hi, GOLDEN_ITERS)
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

/// The two faces that meet at `rim`'s point at angle `t` (body frame): for each, the unit
/// direction that leaves the rim into the face at right angles to it, and the face's outward
/// normal. Cap first, then the side.
pub(crate) fn rim_faces(rim: &Rim, t: Real) -> [(Vec3, Vec3); 2] {
    let er = Vec3::new(t.cos(), t.sin(), 0.0);
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
