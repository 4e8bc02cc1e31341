//! The turning rows of a contact that stands for a small patch (`docs/engine.md`, "Contact
//! points as small patches"): after the contact's normal row and friction pair, a spin row
//! bounded by the patch's Coulomb torque and a rolling pair bounded by the normal force at
//! its rim, on the bodies' relative angular velocity.

use super::{onto_disk, Block, NormalTarget, Velocities, VelocityState};
use crate::geometry::contact::Contact;
use crate::math::{Real, Vec3};

/// Hertz's full-slip torque of a circular patch, M = (3π/16) μ a P (Johnson, Contact
/// Mechanics, §7.4), as the factor of μ a P.
pub(super) const SPIN_FACTOR: Real = 3.0 * std::f64::consts::PI / 16.0;

/// A contact's turning rows, for the patch it stands for: spin about the normal and rolling
/// about the two tangents, on the relative angular velocity ω_A − ω_B.
#[derive(Debug, Clone)]
pub(super) struct PatchBlock {
    /// I_A⁻¹ d and I_B⁻¹ d for the normal and the two tangents.
    wa: [Vec3; 3],
    wb: [Vec3; 3],
    /// 1 / K_ss of the spin row.
    inv_kss: Real,
    k_ss: Real,
    /// Inverse of the rolling 2×2 block, and its trace.
    kr_inv: [[Real; 2]; 2],
    kr_trace: Real,
    /// Spin bound and rolling bound per unit normal impulse, m.
    spin: Real,
    roll: Real,
    /// The contact point's largest distance from the bodies' centres: a change of the
    /// relative angular velocity moves the bodies' surfaces by up to this lever, m.
    reach: Real,
}

impl PatchBlock {
    pub(super) fn new(c: &Contact, blk: &Block, st: &VelocityState, target: &NormalTarget) -> Option<Self> {
        if target.patch <= 0.0 {
            return None;
        }
        let ia = &st.inv_inertia[blk.a];
        let wa = blk.dir.map(|d| ia * d);
        let wb = match c.b_body() {
            Some(j) => blk.dir.map(|d| st.inv_inertia[j] * d),
            None => [Vec3::zeros(); 3],
        };
        let k = |i: usize, j: usize| blk.dir[i].dot(&(wa[j] + wb[j]));
        let k_ss = k(0, 0);
        let (k11, k12, k22) = (k(1, 1), k(1, 2), k(2, 2));
        let det = k11 * k22 - k12 * k12;
        let reach = c.lever_a.norm().max(if c.b_body().is_some() { c.lever_b.norm() } else { 0.0 });
        Some(Self {
            wa,
            wb,
            inv_kss: 1.0 / k_ss,
            k_ss,
            kr_inv: [[k22 / det, -k12 / det], [-k12 / det, k11 / det]],
            kr_trace: k11 + k22,
            spin: SPIN_FACTOR * target.mu * target.patch,
            roll: if target.rolls { target.patch } else { 0.0 },
            reach,
        })
    }

    /// Relative angular velocity ω_A − ω_B along row `i`.
    #[inline]
    fn turn(&self, blk: &Block, st: &mut impl Velocities, i: usize) -> Real {
        let mut w = blk.dir[i].dot(st.w(blk.a));
        if blk.b != usize::MAX {
            w -= blk.dir[i].dot(st.w(blk.b));
        }
        w
    }

    #[inline]
    pub(super) fn apply(&self, blk: &Block, st: &mut impl Velocities, i: usize, dl: Real) {
        *st.w(blk.a) += self.wa[i] * dl;
        if blk.b != usize::MAX {
            *st.w(blk.b) -= self.wb[i] * dl;
        }
    }

    /// Clamps the impulses `l` (spin, then the rolling pair) to the bounds of normal impulse
    /// `ln`.
    pub(super) fn clamp(&self, l: &mut [Real; 3], ln: Real) {
        let spin = self.spin * ln;
        l[0] = l[0].clamp(-spin, spin);
        [l[1], l[2]] = onto_disk([l[1], l[2]], self.roll * ln);
    }

    /// One Gauss–Seidel visit of the spin row and the rolling pair under the normal impulse
    /// `ln`; returns the largest surface speed it changed, m/s.
    pub(super) fn visit(
        &self,
        blk: &Block,
        st: &mut impl Velocities,
        l: &mut [Real; 3],
        ln: Real,
        negligible: Real,
    ) -> Real {
        if ln == 0.0 && *l == [0.0; 3] {
            // Bounds of zero on impulses of zero: nothing to change (an open speculative contact).
            return 0.0;
        }
        let mut dv: Real = 0.0;
        let spin = self.spin * ln;
        let s = (l[0] - self.turn(blk, st, 0) * self.inv_kss).clamp(-spin, spin);
        let ds = s - l[0];
        if ds.abs() * self.k_ss * self.reach > negligible {
            self.apply(blk, st, 0, ds);
            l[0] = s;
            dv = ds.abs() * self.k_ss * self.reach;
        }
        if self.roll == 0.0 {
            return dv;
        }
        let (w1, w2) = (self.turn(blk, st, 1), self.turn(blk, st, 2));
        let old = [l[1], l[2]];
        let r = onto_disk(
            [
                old[0] - (self.kr_inv[0][0] * w1 + self.kr_inv[0][1] * w2),
                old[1] - (self.kr_inv[1][0] * w1 + self.kr_inv[1][1] * w2),
            ],
            self.roll * ln,
        );
        let d = [r[0] - old[0], r[1] - old[1]];
        let dr = (d[0] * d[0] + d[1] * d[1]).sqrt() * self.kr_trace * self.reach;
        if dr > negligible {
            self.apply(blk, st, 1, d[0]);
            self.apply(blk, st, 2, d[1]);
            l[1] = r[0];
            l[2] = r[1];
            dv = dv.max(dr);
        }
        dv
    }
}
