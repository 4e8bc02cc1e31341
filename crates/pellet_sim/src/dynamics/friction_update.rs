//! Friction at resting contacts for fixed normal forces (the resting phase of the force-level
//! stepper): dynamic friction −μ f along the slip at contacts slipping faster than εf, and
//! static friction (a switch) by Gauss–Seidel on the tangential rows of the others.

use super::friction_scatter::FrictionScatter;
use super::rows::{Row, RowSystem};
use crate::math::Real;
use crate::params::{EngineParams, FrictionClamp};

/// Gauss–Seidel sweeps of the static-friction rows per call of [`update_static`]. The fixed
/// point calls this every round, starting from the previous round's friction, so a few sweeps
/// per call suffice. Measured, CPU time of
/// `pack --pellet s.pellet --tube-diameter 40 --count 60 --seed 1|2|3` (10 mm spheres): 20
/// sweeps 16.6 / 15.5 / 21.3 s, 5 sweeps 10.3 / 12.6 / 14.0 s. Starting the sweeps from last
/// substep's friction as well (warm by contact key) gained another ~10 % (9.5 / 11.5 / 12.5 s
/// with 5 sweeps; 3: 12.7 / 13.3 / 10.6 s; 8: 12.6 / 14.1 / 23.8 s) but was not kept: 12
/// spheres in a 25 mm tube then never settled (a stale warm force kept one pellet moving at
/// 0.06 m/s after 6 s; cold, it settles at 0.905 s).
const STATIC_SWEEPS: usize = 5;

/// The relative margin below μ² f² under which a static step skips the exact disc test
/// ([`static_step`]): 2⁻⁴⁰, far above the few ulps that rounding can take.
const INSIDE_MARGIN: Real = 1.0 / (1u64 << 40) as Real;

/// Whether a resting contact slides.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Friction {
    /// Slip faster than εf: Coulomb force −μ f along the slip.
    Dynamic,
    /// Slip at most εf, static friction on: a force in the disc |g| ≤ μ f.
    Static,
}

/// One frictional resting contact of an island.
#[derive(Debug, Clone)]
pub struct FrictionEntry {
    /// Island-local index of the contact (its normal row).
    pub contact: usize,
    /// Dynamic or static.
    pub kind: Friction,
    /// Tangential row along t1 (the slip direction, or any tangent if there is no slip).
    pub t1: Row,
    /// Tangential row along t2 = n × t1.
    pub t2: Row,
    /// Slip velocity along t1 and t2 at the start of the substep, m/s.
    pub slip: (Real, Real),
    /// Friction coefficient.
    pub mu: Real,
}

/// Dynamic contacts: −μ f along the slip, clamped so the slip does not reverse within dt.
/// `clamped` records whether each contact is clamped; it is decided at the first call and then
/// kept, so that a fixed point cannot toggle between the two branches.
pub fn update_dynamic(
    fric: &[FrictionEntry],
    f: &[Real],
    gt: &mut [(Real, Real)],
    clamped: &mut [Option<bool>],
    params: &EngineParams,
    dt: Real,
) {
    for ((x, g), cl) in fric.iter().zip(gt.iter_mut()).zip(clamped.iter_mut()) {
        if x.kind != Friction::Dynamic {
            continue;
        }
        let mag = x.mu * f[x.contact];
        let limit = x.slip.0 / (x.t1.diag * dt);
        let is_clamped = *cl.get_or_insert(mag > limit);
        *g = if !is_clamped {
            (-mag, 0.0)
        } else {
            match params.acceleration.friction_clamp {
                FrictionClamp::Stick => (-limit, 0.0),
                FrictionClamp::Zero => (0.0, 0.0),
            }
        };
    }
}

/// Static contacts: Gauss–Seidel on the tangential rows, target tangential velocity zero at the
/// end of the substep, each force inside the disc |g| ≤ μ f. `free_t` is the free tangential
/// acceleration of each entry along t1 and t2; `scatter` is `fric`'s `FrictionScatter`.
pub(crate) fn update_static(
    fric: &[FrictionEntry],
    free_t: &[(Real, Real)],
    sys: &RowSystem,
    f: &[Real],
    gt: &mut [(Real, Real)],
    dt: Real,
    scatter: &FrictionScatter,
) {
    if !fric.iter().any(|x| x.kind == Friction::Static) {
        return;
    }
    let mut acc = sys.response(f);
    scatter.add(gt, &mut acc);
    // The accumulator as one array per body, read and written whole: a contact often shares a
    // body with the one before it, and reading that body's entries back in other widths than
    // they were stored in (a slice copy) defeated the CPU's store-to-load forwarding, which
    // was the sweeps' largest stall (perf annotate).
    let mut per_body: Vec<[Real; 6]> = acc.chunks_exact(6).map(|c| c.try_into().expect("6 entries per body")).collect();
    for _ in 0..STATIC_SWEEPS {
        for ((x, g), ft) in fric.iter().zip(gt.iter_mut()).zip(free_t) {
            if x.kind != Friction::Static {
                continue;
            }
            // Both tangential rows on the contact's two bodies' entries held in registers
            // (`Row::dot_pair`): the arithmetic of `static_step` and `add_response`.
            let (a, b) = (x.t1.a, x.t1.b);
            let (mut ua, mut ub) = (per_body[a], b.map_or([0.0; 6], |b| per_body[b]));
            let jt = (x.t1.dot_pair(&ua, &ub), x.t2.dot_pair(&ua, &ub));
            let (n1, n2) = static_step(x, *ft, jt, *g, f[x.contact], dt);
            x.t1.add_response_pair(n1 - g.0, &mut ua, &mut ub);
            x.t2.add_response_pair(n2 - g.1, &mut ua, &mut ub);
            *g = (n1, n2);
            per_body[a] = ua;
            if let Some(b) = b {
                per_body[b] = ub;
            }
        }
    }
}

/// acc += M⁻¹ Jₜᵀ g: the stacked body velocity changes of friction multipliers `gt` (along t1,
/// t2 of each entry of `fric`), entry by entry. Zero multipliers are skipped (a dynamic entry's
/// t2 always is); adding their zero products would leave `acc` bit for bit the same.
pub fn add_friction_response(fric: &[FrictionEntry], gt: &[(Real, Real)], acc: &mut [Real]) {
    for (x, &(g1, g2)) in fric.iter().zip(gt) {
        if g1 != 0.0 {
            x.t1.add_response(g1, acc);
        }
        if g2 != 0.0 {
            x.t2.add_response(g2, acc);
        }
    }
}

/// One Gauss–Seidel step of a static contact: the friction multipliers (t1, t2) that bring its
/// tangential velocity to zero at the end of the substep, from the current multipliers `g` and
/// `jt`, the products of its two tangential rows with the accumulator (stacked body
/// accelerations of every force so far), projected onto the disc |g| ≤ μ f of its normal force
/// `f_normal`. `ft` is its free tangential acceleration.
#[inline]
pub fn static_step(
    x: &FrictionEntry,
    ft: (Real, Real),
    jt: (Real, Real),
    g: (Real, Real),
    f_normal: Real,
    dt: Real,
) -> (Real, Real) {
    let a1 = ft.0 + jt.0 + x.slip.0 / dt;
    let a2 = ft.1 + jt.1 + x.slip.1 / dt;
    let n1 = g.0 - a1 * x.t1.inv_diag;
    let n2 = g.1 - a2 * x.t2.inv_diag;
    onto_disc(n1, n2, x.mu * f_normal)
}

/// (n1, n2) projected onto the disc of radius `cap` by scaling: n · cap / |n| outside it.
#[inline]
pub(crate) fn onto_disc(mut n1: Real, mut n2: Real, cap: Real) -> (Real, Real) {
    let squared = n1 * n1 + n2 * n2;
    // Well inside the disc the projection is the identity, and the square root and division
    // (most of a jammed pile's polish, `coupled_pgs`, where they sit on the sweep's dependency
    // chain) are not needed. Safe to the bit: with c2 = fl(cap²) a normal number, squared ≤
    // fl(c2 (1 − 2⁻⁴⁰)) gives √squared < cap (1 − 2⁻⁴²), so fl(√squared) < cap, the test below.
    // And a contact without normal force (cap = 0: look-ahead contacts, mostly) loses its
    // friction: n · (cap / norm) is n · cap for every norm > 0, also to the bit.
    let cap_squared = cap * cap;
    if cap_squared >= Real::MIN_POSITIVE && squared <= cap_squared * (1.0 - INSIDE_MARGIN) {
        return (n1, n2);
    }
    if cap == 0.0 && squared > 0.0 {
        return (n1 * cap, n2 * cap);
    }
    let norm = squared.sqrt();
    if norm > cap {
        n1 *= cap / norm;
        n2 *= cap / norm;
    }
    (n1, n2)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// The projection as it was before its two shortcuts.
    fn onto_disc_exact(mut n1: Real, mut n2: Real, cap: Real) -> (Real, Real) {
        let norm = (n1 * n1 + n2 * n2).sqrt();
        if norm > cap {
            n1 *= cap / norm;
            n2 *= cap / norm;
        }
        (n1, n2)
    }

    /// The shortcuts (well inside the disc; no normal force) give the bits of the full
    /// projection, also for points within a few ulps of the rim, on it, at the origin and for
    /// signed zeros.
    #[test]
    fn the_disc_projection_shortcuts_change_no_bit() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let mut cases = vec![(0.0, 0.0, 0.0), (-0.0, 0.0, 0.0), (0.0, -0.0, 1.0), (3.0, 4.0, 5.0), (-3.0, 4.0, 0.0)];
        for _ in 0..200_000 {
            let cap = if rng.random_range(0..4) == 0 { 0.0 } else { 10f64.powf(rng.random_range(-12.0..3.0)) };
            let angle: Real = rng.random_range(0.0..std::f64::consts::TAU);
            // Radii from well inside to well outside, most within 1e-13 of the rim.
            let radius = if rng.random_range(0..2) == 0 {
                cap.max(1e-9) * rng.random_range(0.0..2.0)
            } else {
                cap * (1.0 + rng.random_range(-1e-13..1e-13))
            };
            cases.push((radius * angle.cos(), radius * angle.sin(), cap));
        }
        for (n1, n2, cap) in cases {
            let (fast, exact) = (onto_disc(n1, n2, cap), onto_disc_exact(n1, n2, cap));
            assert_eq!(
                (fast.0.to_bits(), fast.1.to_bits()),
                (exact.0.to_bits(), exact.1.to_bits()),
                "n = ({n1:e}, {n2:e}), cap {cap:e}: {fast:?} against {exact:?}"
            );
        }
    }
}
