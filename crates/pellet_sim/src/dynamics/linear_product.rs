//! The product y = A x of a system whose rows all pass through their bodies' centres (the
//! normal rows of a sphere island), in a compact form: 3 velocity entries per body instead of
//! 6, and the scatter M⁻¹Jᵀx done body by body.
//!
//! Why body by body: a row-by-row scatter adds each row's share into the stacked vector in
//! memory, and a body's rows follow one another (contacts are sorted by body), so every add
//! waited for the store of the one before it. Summed in registers per body, in the same row
//! order, the additions are the same ones in the same order (the same bits), and the bodies'
//! sums are independent of each other.

use super::by_body::ByBody;
use super::rows::Row;
use crate::math::{Real, Vec3};

/// A row through both centres: the numbers of [`Row`]'s linear path the gather reads.
#[derive(Debug, Clone, Copy)]
struct GatherRow {
    a: u32,
    /// `u32::MAX` for a static B.
    b: u32,
    dir: [Real; 3],
}

/// One row's share of one body: the row and its M⁻¹Jᵀ block for that body.
#[derive(Debug, Clone, Copy, Default)]
struct BodyTerm {
    row: u32,
    w: [Real; 3],
}

/// The compact linear system (built only when every row is linear).
#[derive(Debug, Clone, Default)]
pub(crate) struct LinearProduct {
    rows: Vec<GatherRow>,
    /// Per body, its terms in row order.
    terms: ByBody<BodyTerm>,
}

impl LinearProduct {
    /// The compact form of `rows` over `n_bodies` bodies, or None if a row is not linear (or
    /// the indices do not fit 32 bits).
    pub(crate) fn new(rows: &[Row], n_bodies: usize) -> Option<Self> {
        if !rows.iter().all(Row::is_linear) || rows.len() >= u32::MAX as usize || n_bodies >= u32::MAX as usize {
            return None;
        }
        let block = |w: &Vec3| [w.x, w.y, w.z];
        let mut pairs = Vec::with_capacity(2 * rows.len());
        for (i, r) in rows.iter().enumerate() {
            let (w, row) = (r.response_blocks(), i as u32);
            pairs.push((r.a, BodyTerm { row, w: block(&w[0]) }));
            if let Some(b) = r.b {
                pairs.push((b, BodyTerm { row, w: block(&w[2]) }));
            }
        }
        let terms = ByBody::new(n_bodies, &pairs)?;
        let rows = rows
            .iter()
            .map(|r| GatherRow {
                a: r.a as u32,
                b: r.b.map_or(u32::MAX, |b| b as u32),
                dir: [r.dir.x, r.dir.y, r.dir.z],
            })
            .collect();
        Some(Self { rows, terms })
    }

    /// y = A x, with `u` as scratch (3 entries per body): the arithmetic of `Row::add_response`
    /// over the rows in order, then `Row::dot`, on the linear path (so the same bits).
    pub(crate) fn mul(&self, x: &[Real], y: &mut [Real], u: &mut Vec<Real>) {
        u.clear();
        u.resize(3 * self.terms.n_bodies(), 0.0);
        for (k, uk) in u.chunks_exact_mut(3).enumerate() {
            // The row scatter skipped rows with x = 0; adding their zero products instead
            // leaves the bits alone (a sum that starts at +0 is never −0, and ±0 added to it
            // changes nothing) and saves a branch that MPRGP's mixed zero and free rows made
            // hard to predict.
            let mut sum = [0.0; 3];
            for t in self.terms.of(k) {
                let s = x[t.row as usize];
                sum[0] += s * t.w[0];
                sum[1] += s * t.w[1];
                sum[2] += s * t.w[2];
            }
            uk.copy_from_slice(&sum);
        }
        for (yi, row) in y.iter_mut().zip(&self.rows) {
            let l = &row.dir;
            let a = 3 * row.a as usize;
            let v = &u[a..a + 3];
            let mut s = l[0] * v[0] + l[1] * v[1] + l[2] * v[2];
            if row.b != u32::MAX {
                let b = 3 * row.b as usize;
                let v = &u[b..b + 3];
                s -= l[0] * v[0] + l[1] * v[1] + l[2] * v[2];
            }
            *yi = s;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::lcp::LcpMatrix;
    use crate::dynamics::rows::{BodyMass, RowSystem};
    use crate::math::Mat3;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// A random pile of sphere rows (body pairs and walls, several rows per body, in no body
    /// order) and inputs with zeros of both signs: the body-by-body product gives the bits of
    /// the rows' own scatter and gather.
    #[test]
    fn the_body_by_body_product_gives_the_bits_of_the_row_scatter() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let n_bodies = 40;
        let masses: Vec<BodyMass> = (0..n_bodies)
            .map(|_| BodyMass { inv_mass: rng.random_range(0.5..3.0), inv_inertia: Mat3::from_diagonal_element(9.0) })
            .collect();
        let rows: Vec<Row> = (0..300)
            .map(|_| {
                let a = rng.random_range(0..n_bodies);
                let b = (rng.random_range(0..4) != 0).then(|| (a + rng.random_range(1..n_bodies)) % n_bodies);
                let n =
                    Vec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0))
                        .normalize();
                Row::new(a, b, &(-n * 0.005), &(n * 0.005), &n, &masses)
            })
            .collect();
        assert!(LinearProduct::new(&rows, n_bodies).is_some(), "all rows pass through the centres");
        // Through the system's product, which must take the compact path for these rows.
        let sys = RowSystem::new(rows.clone(), n_bodies);
        for trial in 0..20 {
            let x: Vec<Real> = (0..rows.len())
                .map(|_| match rng.random_range(0..4) {
                    0 => 0.0,
                    1 if trial % 2 == 0 => -0.0,
                    _ => rng.random_range(-2.0..2.0),
                })
                .collect();
            let mut y = vec![0.0; rows.len()];
            sys.mul(&x, &mut y);
            let mut u = vec![0.0; 6 * n_bodies];
            for (r, &xi) in rows.iter().zip(&x) {
                if xi != 0.0 {
                    r.add_response(xi, &mut u);
                }
            }
            for (r, yi) in rows.iter().zip(&y) {
                assert_eq!(r.dot(&u).to_bits(), yi.to_bits());
            }
        }
    }

    /// A row with a torque (a lever off its direction) has no compact form.
    #[test]
    fn rows_with_torques_have_no_compact_form() {
        let masses = [BodyMass { inv_mass: 1.0, inv_inertia: Mat3::identity() }];
        let n = Vec3::z();
        let row = Row::new(0, None, &Vec3::new(1e-3, 0.0, -5e-3), &Vec3::zeros(), &n, &masses);
        assert!(LinearProduct::new(&[row], 1).is_none());
    }
}
