//! The stacked body accelerations M⁻¹Jₜᵀg of an island's friction multipliers, summed body by
//! body: `friction_update::add_friction_response` in the same order per body, so the same bits.
//!
//! Why: the friction fixed point adds the friction entries' response twice per round (for the
//! normal problem's right-hand side and to start the static sweeps), row by row into the
//! stacked vector in memory, and each add waited for the store of the one before it on the
//! same body (the two tangential rows of a contact, and a body's contacts follow one another).
//! Built once per island solve, summed in registers per body.

use super::by_body::ByBody;
use super::friction_update::FrictionEntry;
use crate::math::{Real, Vec3};

/// One tangential row's share of one body.
#[derive(Debug, Clone, Copy, Default)]
struct Term {
    /// Friction entry and which of its rows (t2 if set).
    entry: u32,
    second: bool,
    /// M⁻¹Jᵀ on this body: linear, then angular (B's sign applied).
    w: [Real; 6],
}

/// The friction rows' responses by body.
#[derive(Debug, Clone, Default)]
pub(crate) struct FrictionScatter {
    /// Per body, its terms in entry order (t1 before t2).
    terms: ByBody<Term>,
}

impl FrictionScatter {
    /// The scatter of `fric` over `n_bodies` local bodies.
    pub(crate) fn new(fric: &[FrictionEntry], n_bodies: usize) -> Self {
        let term = |entry: usize, second: bool, lin: &Vec3, ang: &Vec3| Term {
            entry: entry as u32,
            second,
            w: [lin.x, lin.y, lin.z, ang.x, ang.y, ang.z],
        };
        let mut pairs = Vec::with_capacity(4 * fric.len());
        for (e, x) in fric.iter().enumerate() {
            for (row, second) in [(&x.t1, false), (&x.t2, true)] {
                let w = row.response_blocks();
                pairs.push((row.a, term(e, second, &w[0], &w[1])));
                if let Some(b) = row.b {
                    pairs.push((b, term(e, second, &w[2], &w[3])));
                }
            }
        }
        let terms = ByBody::new(n_bodies, &pairs).expect("an island's friction rows fit u32 indices");
        Self { terms }
    }

    /// acc += M⁻¹Jₜᵀ g for the multipliers `gt` (along t1, t2 of each entry).
    ///
    /// The row-by-row form skips zero multipliers (and a row's angular half when it has no
    /// torque); adding their zero products instead leaves the bits alone, since every entry of
    /// `acc` is a sum that started at +0 and so is never −0.
    pub(crate) fn add(&self, gt: &[(Real, Real)], acc: &mut [Real]) {
        for (k, v) in acc.chunks_exact_mut(6).enumerate() {
            let terms = self.terms.of(k);
            if terms.is_empty() {
                continue;
            }
            let mut sum: [Real; 6] = v.try_into().expect("6 entries per body");
            for t in terms {
                let g = gt[t.entry as usize];
                let s = if t.second { g.1 } else { g.0 };
                for (sc, wc) in sum.iter_mut().zip(&t.w) {
                    *sc += s * wc;
                }
            }
            v.copy_from_slice(&sum);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::friction_update::{add_friction_response, Friction};
    use crate::dynamics::rows::{BodyMass, Row};
    use crate::math::{Mat3, Vec3};
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Random friction entries (pairs and walls, rows with and without torques) and multipliers
    /// with zeros of both signs: the body-by-body sums give the bits of the row-by-row ones.
    #[test]
    fn the_body_by_body_sums_give_the_bits_of_the_row_scatter() {
        let mut rng = ChaCha8Rng::seed_from_u64(13);
        let n_bodies = 30;
        let masses: Vec<BodyMass> = (0..n_bodies)
            .map(|_| {
                let d = Vec3::new(rng.random_range(1.0..9.0), rng.random_range(1.0..9.0), rng.random_range(1.0..9.0));
                BodyMass { inv_mass: rng.random_range(0.5..3.0), inv_inertia: Mat3::from_diagonal(&d) }
            })
            .collect();
        let unit = |rng: &mut ChaCha8Rng| {
            Vec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)).normalize()
        };
        let fric: Vec<FrictionEntry> = (0..200)
            .map(|k| {
                let a = rng.random_range(0..n_bodies);
                let b = (rng.random_range(0..4) != 0).then(|| (a + rng.random_range(1..n_bodies)) % n_bodies);
                let (n, t) = (unit(&mut rng), unit(&mut rng));
                let t1 = (t - n * n.dot(&t)).normalize();
                let t2 = n.cross(&t1);
                // Every fifth entry has its lever along its row's direction (no torque).
                let lever = |d: &Vec3, rng: &mut ChaCha8Rng| if k % 5 == 0 { *d * 0.004 } else { unit(rng) * 0.005 };
                let row = |d: &Vec3, rng: &mut ChaCha8Rng| {
                    let (la, lb) = (lever(d, rng), lever(d, rng));
                    Row::new(a, b, &la, &lb, d, &masses)
                };
                FrictionEntry {
                    contact: k,
                    kind: if k % 3 == 0 { Friction::Dynamic } else { Friction::Static },
                    t1: row(&t1, &mut rng),
                    t2: row(&t2, &mut rng),
                    slip: (0.0, 0.0),
                    mu: 0.5,
                }
            })
            .collect();
        let scatter = FrictionScatter::new(&fric, n_bodies);
        for _ in 0..20 {
            let pick = |rng: &mut ChaCha8Rng| -> Real {
                match rng.random_range(0..5) {
                    0 => 0.0,
                    1 => -0.0,
                    _ => rng.random_range(-2.0..2.0),
                }
            };
            let gt: Vec<(Real, Real)> = fric.iter().map(|_| (pick(&mut rng), pick(&mut rng))).collect();
            // A start like the sweeps' (a sum from +0), then the friction on top.
            let start: Vec<Real> = (0..6 * n_bodies).map(|_| 0.0 + pick(&mut rng)).collect();
            let (mut rows, mut bodies) = (start.clone(), start);
            add_friction_response(&fric, &gt, &mut rows);
            scatter.add(&gt, &mut bodies);
            assert_eq!(
                rows.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                bodies.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
            );
        }
    }
}
