//! Constraint rows J_i = [d, r_A×d | −d, −r_B×d] of contact points and the matrix-free operator
//! A = J M⁻¹ Jᵀ over an island (physics.md §4.1). J is never formed as a matrix.

use super::lcp::LcpMatrix;
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
        let ang_a = lever_a.cross(dir);
        let ma = &masses[a];
        let wa_l = dir * ma.inv_mass;
        let wa_a = ma.inv_inertia * ang_a;
        let mut diag = dir.dot(&wa_l) + ang_a.dot(&wa_a);
        let (ang_b, wb_l, wb_a) = match b {
            Some(bi) => {
                let ang_b = lever_b.cross(dir);
                let mb = &masses[bi];
                let wb_l = -dir * mb.inv_mass;
                let wb_a = -(mb.inv_inertia * ang_b);
                diag += dir.dot(&(-wb_l)) + ang_b.dot(&(-wb_a));
                (ang_b, wb_l, wb_a)
            }
            None => (Vec3::zeros(), Vec3::zeros(), Vec3::zeros()),
        };
        Self { a, b, dir: *dir, ang_a, ang_b, w: [wa_l, wa_a, wb_l, wb_a], diag }
    }

    /// J_i · u for stacked body velocities `u` (6 per body: linear, angular).
    #[inline]
    pub fn dot(&self, u: &[Real]) -> Real {
        // One slice per body (one bounds check each); sums in the order of Vec3::dot.
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

    /// The world force and torque (about each centre) that a multiplier `f` puts on A and B.
    pub fn wrench(&self, f: Real) -> [(Vec3, Vec3); 2] {
        [(self.dir * f, self.ang_a * f), (-self.dir * f, -self.ang_b * f)]
    }
}

/// The operator A = J M⁻¹ Jᵀ of a set of rows over `n_bodies` local bodies.
#[derive(Debug, Clone, Default)]
pub struct RowSystem {
    /// Rows.
    pub rows: Vec<Row>,
    /// Number of local bodies.
    pub n_bodies: usize,
    /// The body-space vector of [`LcpMatrix::mul`], kept between products: allocating it
    /// per product (malloc, memset, free) was 4 % of a one-column pour (perf).
    scratch: RefCell<Vec<Real>>,
}

impl RowSystem {
    /// The system of `rows` over `n_bodies` local bodies.
    pub fn new(rows: Vec<Row>, n_bodies: usize) -> Self {
        Self { rows, n_bodies, scratch: RefCell::default() }
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

/// The collision matrix K of a contact (physics.md §3.3).
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
