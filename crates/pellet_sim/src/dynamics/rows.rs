//! Constraint rows J_i = [d, r_A×d | −d, −r_B×d] of contact points and the matrix-free operator
//! A = J M⁻¹ Jᵀ over an island. J is never formed as a matrix.

use super::lcp::LcpMatrix;
use super::linear_product::LinearProduct;
use crate::body::Body;
use crate::geometry::contact::Contact;
use crate::math::{Mat3, Real, Vec3};
use std::cell::RefCell;

/// One row: a force direction `dir` applied at a point, +dir on A and −dir on B.
#[derive(Debug, Clone)]
pub struct Row {
    /// Local index of body A in the system.
    pub a: usize,
    /// Local index of body B, if dynamic.
    pub b: Option<usize>,
    /// Direction (the normal for normal rows).
    pub dir: Vec3,
    /// r_A × dir.
    pub ang_a: Vec3,
    /// r_B × dir (unused if B is static).
    pub ang_b: Vec3,
    /// M⁻¹ Jᵀ blocks: dir/m_A, I_A⁻¹(r_A×dir), and the same for B (with B's sign applied).
    w: [Vec3; 4],
    /// A_ii.
    pub diag: Real,
    /// 1 / A_ii, for the Gauss–Seidel updates f − a / A_ii of the friction sweeps and the
    /// coupled polish: there the division sat on the sweeps' dependency chain (a
    /// high-friction cylinder bed took 20 % longer with it).
    pub inv_diag: Real,
    /// The row's torques are zero to round-off (a normal through both centres, as at every
    /// sphere contact): its products skip the angular half.
    linear: bool,
}

/// Per-body mass data of a system.
#[derive(Debug, Clone)]
pub struct BodyMass {
    /// 1/m.
    pub inv_mass: Real,
    /// World inverse inertia.
    pub inv_inertia: Mat3,
}

impl BodyMass {
    /// From a body's current state.
    pub fn of(body: &Body) -> Self {
        Self { inv_mass: body.inv_mass(), inv_inertia: body.inv_inertia_world() }
    }
}

impl Row {
    /// Builds a row from the lever arms of the application points (`lever_b` ignored if B is
    /// static) and the local body indices into `masses`.
    pub fn new(a: usize, b: Option<usize>, lever_a: &Vec3, lever_b: &Vec3, dir: &Vec3, masses: &[BodyMass]) -> Self {
        // |r × d| ≤ 1e-12 |r||d|: the lever is parallel to the direction (sphere contacts give
        // ~1e-16 from the rounding of r = −ρ n). Such a row's torques are taken as exactly zero.
        let parallel = |r: &Vec3, ang: &Vec3| ang.norm_squared() <= 1e-24 * r.norm_squared() * dir.norm_squared();
        let (ang_a, ang_b) = (lever_a.cross(dir), b.map_or_else(Vec3::zeros, |_| lever_b.cross(dir)));
        let linear = parallel(lever_a, &ang_a) && (b.is_none() || parallel(lever_b, &ang_b));
        let (ang_a, ang_b) = if linear { (Vec3::zeros(), Vec3::zeros()) } else { (ang_a, ang_b) };
        let ma = &masses[a];
        let wa_l = dir * ma.inv_mass;
        let wa_a = ma.inv_inertia * ang_a;
        let mut diag = dir.dot(&wa_l) + ang_a.dot(&wa_a);
        let (wb_l, wb_a) = match b {
            Some(bi) => {
                let mb = &masses[bi];
                let wb_l = -dir * mb.inv_mass;
                let wb_a = -(mb.inv_inertia * ang_b);
                diag += dir.dot(&(-wb_l)) + ang_b.dot(&(-wb_a));
                (wb_l, wb_a)
            }
            None => (Vec3::zeros(), Vec3::zeros()),
        };
        Self { a, b, dir: *dir, ang_a, ang_b, w: [wa_l, wa_a, wb_l, wb_a], diag, inv_diag: 1.0 / diag, linear }
    }

    /// Whether the row's torques are zero (a normal through both centres).
    pub fn is_linear(&self) -> bool {
        self.linear
    }

    /// The M⁻¹Jᵀ blocks: A's linear and angular, then B's (B's sign applied; zero for a static
    /// B).
    pub fn response_blocks(&self) -> &[Vec3; 4] {
        &self.w
    }

    /// J_i · u for stacked body velocities `u` (6 per body: linear, angular).
    #[inline]
    pub fn dot(&self, u: &[Real]) -> Real {
        // One slice per body (one bounds check each); sums in the order of Vec3::dot.
        if self.linear {
            let dot3 = |l: &Vec3, k: usize| {
                let v = &u[6 * k..6 * k + 3];
                l.x * v[0] + l.y * v[1] + l.z * v[2]
            };
            let mut s = dot3(&self.dir, self.a);
            if let Some(b) = self.b {
                s -= dot3(&self.dir, b);
            }
            return s;
        }
        let dot6 = |l: &Vec3, w: &Vec3, k: usize| {
            let v = &u[6 * k..6 * k + 6];
            (l.x * v[0] + l.y * v[1] + l.z * v[2]) + (w.x * v[3] + w.y * v[4] + w.z * v[5])
        };
        let mut s = dot6(&self.dir, &self.ang_a, self.a);
        if let Some(b) = self.b {
            s -= dot6(&self.dir, &self.ang_b, b);
        }
        s
    }

    /// u += s · M⁻¹ J_iᵀ.
    #[inline]
    pub fn add_response(&self, s: Real, u: &mut [Real]) {
        if self.linear {
            let mut add = |k: usize, l: &Vec3| {
                let v = &mut u[6 * k..6 * k + 3];
                for c in 0..3 {
                    v[c] += s * l[c];
                }
            };
            add(self.a, &self.w[0]);
            if let Some(b) = self.b {
                add(b, &self.w[2]);
            }
            return;
        }
        let mut add = |k: usize, l: &Vec3, w: &Vec3| {
            let v = &mut u[6 * k..6 * k + 6];
            for c in 0..3 {
                v[c] += s * l[c];
                v[3 + c] += s * w[c];
            }
        };
        add(self.a, &self.w[0], &self.w[1]);
        if let Some(b) = self.b {
            add(b, &self.w[2], &self.w[3]);
        }
    }

    /// [`Self::dot`] over the 6 velocity entries of A and of B held apart (`ub` unread if B is
    /// static): the same arithmetic, so the same bits. Lets a contact's normal and tangential
    /// rows work on their two bodies' entries in registers (`coupled_pgs`).
    #[inline]
    pub fn dot_pair(&self, ua: &[Real; 6], ub: &[Real; 6]) -> Real {
        if self.linear {
            let dot3 = |l: &Vec3, v: &[Real; 6]| l.x * v[0] + l.y * v[1] + l.z * v[2];
            let mut s = dot3(&self.dir, ua);
            if self.b.is_some() {
                s -= dot3(&self.dir, ub);
            }
            return s;
        }
        let dot6 = |l: &Vec3, w: &Vec3, v: &[Real; 6]| {
            (l.x * v[0] + l.y * v[1] + l.z * v[2]) + (w.x * v[3] + w.y * v[4] + w.z * v[5])
        };
        let mut s = dot6(&self.dir, &self.ang_a, ua);
        if self.b.is_some() {
            s -= dot6(&self.dir, &self.ang_b, ub);
        }
        s
    }

    /// [`Self::add_response`] into A's and B's entries held apart (`ub` untouched if B is
    /// static): the same arithmetic.
    #[inline]
    pub fn add_response_pair(&self, s: Real, ua: &mut [Real; 6], ub: &mut [Real; 6]) {
        let end = |v: &mut [Real; 6], l: &Vec3, w: &Vec3, angular: bool| {
            for c in 0..3 {
                v[c] += s * l[c];
                if angular {
                    v[3 + c] += s * w[c];
                }
            }
        };
        end(ua, &self.w[0], &self.w[1], !self.linear);
        if self.b.is_some() {
            end(ub, &self.w[2], &self.w[3], !self.linear);
        }
    }

    /// The world force and torque (about each centre) that a multiplier `f` puts on A and B.
    pub fn wrench(&self, f: Real) -> [(Vec3, Vec3); 2] {
        [(self.dir * f, self.ang_a * f), (-self.dir * f, -self.ang_b * f)]
    }
}

/// Body `a`'s and (if dynamic) body `b`'s 6 entries of a stacked body vector, for
/// [`Row::dot_pair`] and [`Row::add_response_pair`] (zeros for a static B).
#[inline]
pub fn load_pair(u: &[Real], a: usize, b: Option<usize>) -> ([Real; 6], [Real; 6]) {
    let six = |k: usize| -> [Real; 6] { u[6 * k..6 * k + 6].try_into().expect("6 entries per body") };
    (six(a), b.map_or([0.0; 6], six))
}

/// Writes back what [`load_pair`] read.
#[inline]
pub fn store_pair(u: &mut [Real], a: usize, b: Option<usize>, ua: &[Real; 6], ub: &[Real; 6]) {
    u[6 * a..6 * a + 6].copy_from_slice(ua);
    if let Some(k) = b {
        u[6 * k..6 * k + 6].copy_from_slice(ub);
    }
}

/// The operator A = J M⁻¹ Jᵀ of a set of rows over `n_bodies` local bodies.
#[derive(Debug, Clone, Default)]
pub struct RowSystem {
    /// Rows.
    pub rows: Vec<Row>,
    /// Number of local bodies.
    pub n_bodies: usize,
    /// The rows in compact form when every row is linear (the normal rows of a sphere island):
    /// products over them do the same arithmetic on half the memory.
    linear: Option<LinearProduct>,
    /// The body-space vector of [`LcpMatrix::mul`], kept between products: allocating it
    /// per product (malloc, memset, free) was 4 % of a one-column pour (perf).
    scratch: RefCell<Vec<Real>>,
}

impl RowSystem {
    /// The system of `rows` over `n_bodies` local bodies.
    pub fn new(rows: Vec<Row>, n_bodies: usize) -> Self {
        let linear = LinearProduct::new(&rows, n_bodies);
        Self { rows, n_bodies, linear, scratch: RefCell::default() }
    }

    /// Stacked body velocity change M⁻¹ Jᵀ f (6 per body).
    pub fn response(&self, f: &[Real]) -> Vec<Real> {
        let mut u = Vec::new();
        self.response_into(f, &mut u);
        u
    }

    /// [`Self::response`] into `u`, which is resized and overwritten.
    fn response_into(&self, f: &[Real], u: &mut Vec<Real>) {
        u.clear();
        u.resize(6 * self.n_bodies, 0.0);
        for (row, &fi) in self.rows.iter().zip(f) {
            if fi != 0.0 {
                row.add_response(fi, u);
            }
        }
    }
}

impl LcpMatrix for RowSystem {
    fn dim(&self) -> usize {
        self.rows.len()
    }
    fn diag(&self, i: usize) -> Real {
        self.rows[i].diag
    }
    fn mul(&self, x: &[Real], y: &mut [Real]) {
        if let Some(linear) = &self.linear {
            return linear.mul(x, y, &mut self.scratch.borrow_mut());
        }
        let mut u = self.scratch.borrow_mut();
        self.response_into(x, &mut u);
        for (yi, row) in y.iter_mut().zip(&self.rows) {
            *yi = row.dot(&u);
        }
    }
    fn acc_len(&self) -> usize {
        6 * self.n_bodies
    }
    fn row_dot(&self, i: usize, acc: &[Real]) -> Real {
        self.rows[i].dot(acc)
    }
    fn add_col(&self, i: usize, s: Real, acc: &mut [Real]) {
        self.rows[i].add_response(s, acc);
    }
}

/// Relative velocity at a contact point, A minus B, world frame.
pub fn relative_velocity(c: &Contact, bodies: &[Body]) -> Vec3 {
    let a = &bodies[c.a];
    let va = a.velocity() + a.angular_velocity().cross(&c.lever_a);
    match c.b_body() {
        Some(b) => {
            let b = &bodies[b];
            va - b.velocity() - b.angular_velocity().cross(&c.lever_b)
        }
        None => va,
    }
}

/// [`relative_velocity`] from each body's velocity and angular velocity, computed beforehand
/// (the same arithmetic, so the same bits): the collision phase's passes ask for every
/// contact's velocity again after each pass, and ω = I⁻¹L per contact end was 10 % of a batch
/// pour (perf).
pub fn relative_velocity_from(c: &Contact, vel: &[Vec3], omega: &[Vec3]) -> Vec3 {
    let va = vel[c.a] + omega[c.a].cross(&c.lever_a);
    match c.b_body() {
        Some(b) => va - vel[b] - omega[b].cross(&c.lever_b),
        None => va,
    }
}

/// The collision matrix K of a contact: the change of the relative velocity at the contact per
/// unit impulse, Σ (I/m − R I⁻¹ R) over its bodies, R the cross-product matrix of the
/// body's lever.
pub fn collision_matrix(c: &Contact, bodies: &[Body]) -> Mat3 {
    use crate::math::skew;
    let ba = &bodies[c.a];
    let ra = skew(&c.lever_a);
    let mut k = Mat3::identity() * ba.inv_mass() - ra * ba.inv_inertia_world() * ra;
    if let Some(b) = c.b_body() {
        let bb = &bodies[b];
        let rb = skew(&c.lever_b);
        k += Mat3::identity() * bb.inv_mass() - rb * bb.inv_inertia_world() * rb;
    }
    k
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The products over two bodies' entries held apart give the bits of the products over the
    /// stacked vector, for rows with and without torques, with a dynamic and a static B.
    #[test]
    fn products_over_a_pair_of_bodies_equal_the_stacked_ones() {
        let masses = [
            BodyMass { inv_mass: 2.0, inv_inertia: Mat3::from_diagonal(&Vec3::new(3.0, 4.0, 5.0)) },
            BodyMass { inv_mass: 0.5, inv_inertia: Mat3::from_diagonal(&Vec3::new(6.0, 7.0, 8.0)) },
            BodyMass { inv_mass: 1.5, inv_inertia: Mat3::from_diagonal(&Vec3::new(9.0, 2.0, 4.0)) },
        ];
        let n = Vec3::new(0.3, -0.7, 0.2).normalize();
        let off = Vec3::new(1e-4, -2e-4, 3e-5);
        let rows = [
            Row::new(2, Some(0), &(-n * 0.005 + off), &(n * 0.004), &n, &masses),
            Row::new(2, Some(0), &(-n * 0.005), &(n * 0.004), &n, &masses),
            Row::new(1, None, &(n * 0.003 + off), &Vec3::zeros(), &n, &masses),
            Row::new(1, None, &(n * 0.003), &Vec3::zeros(), &n, &masses),
        ];
        for row in &rows {
            let mut u: Vec<Real> = (0..18).map(|k| (k as Real * 0.77).sin()).collect();
            let pick = |u: &[Real], k: usize| -> [Real; 6] { u[6 * k..6 * k + 6].try_into().unwrap() };
            let b = row.b.unwrap_or(0);
            let (mut ua, mut ub) = load_pair(&u, row.a, row.b);
            assert_eq!(row.dot_pair(&ua, &ub).to_bits(), row.dot(&u).to_bits());
            row.add_response(-1.37, &mut u);
            row.add_response_pair(-1.37, &mut ua, &mut ub);
            assert_eq!(ua.map(Real::to_bits), pick(&u, row.a).map(Real::to_bits));
            if row.b.is_some() {
                assert_eq!(ub.map(Real::to_bits), pick(&u, b).map(Real::to_bits));
            }
        }
    }

    /// A row through both centres (a sphere contact, lever = −ρ n with its rounding) takes the
    /// linear-only path and agrees with the full formula; a lever off the normal does not.
    #[test]
    fn rows_through_the_centres_skip_the_angular_half() {
        let masses = [
            BodyMass { inv_mass: 2.0, inv_inertia: Mat3::from_diagonal(&Vec3::new(3.0, 4.0, 5.0)) },
            BodyMass { inv_mass: 0.5, inv_inertia: Mat3::from_diagonal(&Vec3::new(6.0, 7.0, 8.0)) },
        ];
        let n = Vec3::new(0.3, -0.7, 0.2).normalize();
        let u: Vec<Real> = (0..12).map(|k| (k as Real * 0.77).sin()).collect();
        let through = Row::new(0, Some(1), &(-n * 0.005), &(n * 0.004), &n, &masses);
        assert!(through.linear);
        let expected_dot = n.dot(&Vec3::new(u[0], u[1], u[2])) - n.dot(&Vec3::new(u[6], u[7], u[8]));
        assert!((through.dot(&u) - expected_dot).abs() <= 1e-15);
        assert!((through.diag - 2.5).abs() <= 1e-15);
        let mut acc = vec![0.0; 12];
        through.add_response(2.0, &mut acc);
        for c in 0..3 {
            assert!((acc[c] - 4.0 * n[c]).abs() <= 1e-15 && (acc[6 + c] + n[c]).abs() <= 1e-15);
            assert_eq!((acc[3 + c], acc[9 + c]), (0.0, 0.0));
        }
        let off = Row::new(0, Some(1), &(-n * 0.005 + Vec3::new(1e-4, 0.0, 0.0)), &(n * 0.004), &n, &masses);
        assert!(!off.linear);
        assert!(off.diag > 2.5);
    }
}
