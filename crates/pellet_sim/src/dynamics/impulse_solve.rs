//! The velocity-level contact problem of one step, solved on impulses: every contact is a
//! normal row with a lower bound on its relative normal velocity after the step, u_n⁺ ≥ target
//! (restitution for colliding contacts, 0 or "close the gap but not beyond" for the rest), and
//! two friction rows whose impulse lies in the Coulomb disk |λ_t| ≤ μ λ_n. Projected
//! Gauss–Seidel over the contacts, each contact's block solved in turn: the normal impulse
//! clamped at zero, then the tangential pair from its own 2×2 block and projected onto the
//! disk (the exact circular cone, not a facetted one; the projection of a 2×2 step that is not
//! isotropic slides a contact slightly off the direction opposite its slip, by the block's
//! anisotropy, which is zero for spheres and walls). A contact point stands for a small patch
//! and resists the relative turning of its bodies as a patch does (`docs/engine.md`, "Contact
//! points as small patches"): a spin row bounded by the patch's Coulomb torque and a rolling
//! pair bounded by the normal force at the patch's rim. The sweeps go slab by slab of bodies,
//! on one thread or several, with the same answer for any number of them (`slabs`, `sweep`).

use crate::body::Body;
use crate::geometry::contact::Contact;
use crate::math::{Mat3, Real, Vec3};
use crate::team::Team;

mod passes;
mod patch;
mod slabs;
mod sweep;
pub use passes::{collision_passes, Touching};
use patch::PatchBlock;

/// A block's update smaller than this fraction of the tolerance (m/s of relative velocity) is
/// not applied, so that round-off does not keep its bodies "moving" for the skip test.
const QUIET_FRACTION: Real = 1e-2;

/// What a contact's normal row asks of the relative normal velocity after the step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NormalTarget {
    /// u_n⁺ ≥ `min_speed`, m/s (negative: the gap may close by up to −min_speed·h).
    pub min_speed: Real,
    /// Coulomb coefficient of the contact.
    pub mu: Real,
    /// Radius of the patch the contact point stands for, m (0: a point that turns freely).
    pub patch: Real,
    /// The patch resists rolling as well as spin (between two spheres it resists spin only).
    pub rolls: bool,
}

/// Where a solve starts from: a contact's impulses of the last step (N·s).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct WarmStart {
    /// Normal impulse.
    pub normal: Real,
    /// Friction impulse on body A, world frame.
    pub friction: Vec3,
    /// Angular impulse of a patch on body A, world frame, N·m·s.
    pub torque: Vec3,
}

/// One contact's rows, with their M⁻¹Jᵀ blocks (B's with its sign applied).
#[derive(Debug, Clone)]
struct Block {
    /// The bodies, as indices of the velocities the block is solved on (the solve's, then its
    /// task's: `sweep`).
    a: usize,
    /// usize::MAX for a wall.
    b: usize,
    /// Normal, then the two tangents.
    dir: [Vec3; 3],
    /// The contact point relative to A's and B's centres (B's zero for a wall).
    lever_a: Vec3,
    lever_b: Vec3,
    /// I_A⁻¹(r_A × d), −I_B⁻¹(r_B × d).
    w_a: [Vec3; 3],
    w_b: [Vec3; 3],
    inv_ma: Real,
    inv_mb: Real,
    /// 1 / K_nn.
    inv_knn: Real,
    /// K_nn.
    knn: Real,
    /// Inverse of the tangential 2×2 block.
    kt_inv: [[Real; 2]; 2],
    /// Largest eigenvalue bound of the tangential block (its trace), for the stop test.
    kt_trace: Real,
    /// K_1n, K_2n: how the tangential relative velocities change per unit normal impulse.
    kt_n: [Real; 2],

    target: Real,
    mu: Real,
}

/// The result of one solve.
#[derive(Debug, Clone, Default)]
pub struct ImpulseSolution {
    /// Normal impulse per contact, N·s (≥ 0).
    pub normal: Vec<Real>,
    /// Friction impulse on body A per contact, world frame, N·s.
    pub friction: Vec<Vec3>,
    /// Angular impulse of each contact's patch on body A, world frame, N·m·s.
    pub torque: Vec<Vec3>,
    /// Relative velocity per contact before the impulses (the free velocity), m/s.
    pub relative_before: Vec<Vec3>,
    /// Relative velocity per contact after the step, m/s.
    pub relative_after: Vec<Vec3>,
    /// Sweeps run.
    pub sweeps: usize,
    /// Largest change of a relative velocity in the last sweep, m/s.
    pub residual: Real,
    /// The stop test was met within the sweep cap.
    pub converged: bool,
}

/// Velocities of the bodies as flat arrays, M⁻¹ alongside.
pub struct VelocityState {
    /// Linear velocities, m/s.
    pub v: Vec<Vec3>,
    /// Angular velocities, rad/s.
    pub w: Vec<Vec3>,
    inv_mass: Vec<Real>,
    inv_inertia: Vec<Mat3>,
    /// Heights of the bodies' centres, m: where the solve cuts its slabs (`slabs`).
    height: Vec<Real>,
}

/// Bodies' velocities by index, wherever they are kept: the solve's flat arrays, or the two
/// slabs a task of the sweep works on.
trait Velocities {
    fn v(&mut self, i: usize) -> &mut Vec3;
    fn w(&mut self, i: usize) -> &mut Vec3;
}

impl Velocities for VelocityState {
    #[inline]
    fn v(&mut self, i: usize) -> &mut Vec3 {
        &mut self.v[i]
    }
    #[inline]
    fn w(&mut self, i: usize) -> &mut Vec3 {
        &mut self.w[i]
    }
}

impl VelocityState {
    /// The velocities of `bodies` after gravity's increment over `h` (the free velocities).
    pub fn free(bodies: &[Body], gravity: &Vec3, h: Real) -> Self {
        Self {
            v: bodies.iter().map(|b| b.velocity() + gravity * h).collect(),
            w: bodies.iter().map(Body::angular_velocity).collect(),
            inv_mass: bodies.iter().map(Body::inv_mass).collect(),
            inv_inertia: bodies.iter().map(Body::inv_inertia_world).collect(),
            height: bodies.iter().map(|b| b.position.z).collect(),
        }
    }

    fn relative(&self, c: &Contact) -> Vec3 {
        let ua = self.v[c.a] + self.w[c.a].cross(&c.lever_a);
        match c.b_body() {
            Some(j) => ua - (self.v[j] + self.w[j].cross(&c.lever_b)),
            None => ua,
        }
    }
}

/// Two unit tangents completing `n` to a right-handed frame (a fixed choice: the answer does
/// not depend on it, the friction disk being round).
pub fn tangents(n: &Vec3) -> (Vec3, Vec3) {
    let seed = if n.x.abs() < 0.57 {
        Vec3::x()
    } else if n.y.abs() < 0.57 {
        Vec3::y()
    } else {
        Vec3::z()
    };
    let t1 = (seed - n * n.dot(&seed)).normalize();
    (t1, n.cross(&t1))
}

impl Block {
    fn new(c: &Contact, st: &VelocityState, target: &NormalTarget) -> Self {
        let n = c.normal;
        let (t1, t2) = tangents(&n);
        let dir = [n, t1, t2];
        let a = c.a;
        let b = c.b_body();
        let inv_ma = st.inv_mass[a];
        let ia = &st.inv_inertia[a];
        let ang_a = dir.map(|d| c.lever_a.cross(&d));
        let w_a = ang_a.map(|g| ia * g);
        let (inv_mb, ang_b, w_b) = match b {
            Some(j) => {
                let ib = &st.inv_inertia[j];
                let ang_b = dir.map(|d| c.lever_b.cross(&d));
                (st.inv_mass[j], ang_b, ang_b.map(|g| -(ib * g)))
            }
            None => (0.0, [Vec3::zeros(); 3], [Vec3::zeros(); 3]),
        };
        // K_ij = d_i·d_j (1/m_A + 1/m_B) + (r_A×d_i)·I_A⁻¹(r_A×d_j) + (r_B×d_i)·I_B⁻¹(r_B×d_j).
        let k = |i: usize, j: usize| {
            dir[i].dot(&dir[j]) * (inv_ma + inv_mb) + ang_a[i].dot(&w_a[j]) - ang_b[i].dot(&w_b[j])
        };
        let knn = k(0, 0);
        let (k11, k12, k22) = (k(1, 1), k(1, 2), k(2, 2));
        let det = k11 * k22 - k12 * k12;
        Self {
            a,
            b: b.unwrap_or(usize::MAX),
            dir,
            lever_a: c.lever_a,
            lever_b: if b.is_some() { c.lever_b } else { Vec3::zeros() },
            w_a,
            w_b,
            inv_ma,
            inv_mb,
            inv_knn: 1.0 / knn,
            knn,
            kt_inv: [[k22 / det, -k12 / det], [-k12 / det, k11 / det]],
            kt_trace: k11 + k22,
            kt_n: [k(1, 0), k(2, 0)],
            target: target.min_speed,
            mu: target.mu,
        }
    }

    /// Relative velocity of the contact along its normal and two tangents, from one relative
    /// velocity vector.
    #[inline]
    fn speeds(&self, st: &mut impl Velocities) -> [Real; 3] {
        let mut u = *st.v(self.a) + st.w(self.a).cross(&self.lever_a);
        if self.b != usize::MAX {
            u -= *st.v(self.b) + st.w(self.b).cross(&self.lever_b);
        }
        [self.dir[0].dot(&u), self.dir[1].dot(&u), self.dir[2].dot(&u)]
    }

    /// Applies the impulse changes `dl` (normal, then the two tangents) to both bodies at once.
    #[inline]
    fn apply_all(&self, st: &mut impl Velocities, dl: [Real; 3]) {
        let j = self.dir[0] * dl[0] + self.dir[1] * dl[1] + self.dir[2] * dl[2];
        *st.v(self.a) += j * self.inv_ma;
        *st.w(self.a) += self.w_a[0] * dl[0] + self.w_a[1] * dl[1] + self.w_a[2] * dl[2];
        if self.b != usize::MAX {
            *st.v(self.b) -= j * self.inv_mb;
            *st.w(self.b) += self.w_b[0] * dl[0] + self.w_b[1] * dl[1] + self.w_b[2] * dl[2];
        }
    }

    #[inline]
    fn apply(&self, st: &mut impl Velocities, i: usize, dl: Real) {
        *st.v(self.a) += self.dir[i] * (self.inv_ma * dl);
        *st.w(self.a) += self.w_a[i] * dl;
        if self.b != usize::MAX {
            *st.v(self.b) -= self.dir[i] * (self.inv_mb * dl);
            *st.w(self.b) += self.w_b[i] * dl;
        }
    }
}

/// `t` projected onto the disk of radius `bound` (radially: the answer's direction is `t`'s).
#[inline]
fn onto_disk(t: [Real; 2], bound: Real) -> [Real; 2] {
    let norm = (t[0] * t[0] + t[1] * t[1]).sqrt();
    if norm > bound {
        let s = if norm > 0.0 { bound / norm } else { 0.0 };
        [t[0] * s, t[1] * s]
    } else {
        t
    }
}

/// Solves the step's contact problem from the free velocities in `st` (changed in place to
/// the velocities after the step), starting from `warm` impulses. Stops once a sweep changes
/// no relative velocity by more than `tolerance` (m/s), or after `max_sweeps`. The sweeps run
/// on `team`'s threads; the answer does not depend on how many (`slabs`).
pub fn solve_impulses(
    contacts: &[Contact],
    targets: &[NormalTarget],
    warm: &[WarmStart],
    st: &mut VelocityState,
    tolerance: Real,
    max_sweeps: usize,
    team: &Team,
) -> ImpulseSolution {
    let relative_before: Vec<Vec3> = contacts.iter().map(|c| st.relative(c)).collect();
    let layout = slabs::Layout::new(contacts, &st.height);
    let solve = sweep::Solve::new(&layout, st);
    let problem = sweep::Problem { contacts, targets, warm, st };
    let mut sol = solve.run(&problem, QUIET_FRACTION * tolerance, tolerance, max_sweeps, team);
    solve.finish(contacts.len(), st, &mut sol);
    sol.relative_after = contacts.iter().map(|c| st.relative(c)).collect();
    sol.relative_before = relative_before;
    sol
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::TypeId;
    use crate::container::WallId;
    use crate::geometry::contact::{ContactKey, Counterpart, GapKinematics};
    use crate::math::Quat;

    fn sphere(z: Real, v: Vec3) -> Body {
        let (m, i) = (1e-3, 1e-8);
        Body {
            type_id: TypeId(0),
            position: Vec3::new(0.0, 0.0, z),
            orientation: Quat::identity(),
            linear_momentum: v * m,
            angular_momentum: Vec3::zeros(),
            mass: m,
            inertia_body: Mat3::identity() * i,
            inv_inertia_body: Mat3::identity() / i,
            bounding_radius: 5e-3,
        }
    }

    fn floor(a: usize, r: Real) -> Contact {
        Contact {
            a,
            b: Counterpart::Wall(WallId::Floor),
            point: Vec3::zeros(),
            lever_a: Vec3::new(0.0, 0.0, -r),
            lever_b: Vec3::zeros(),
            normal: Vec3::z(),
            gap: 0.0,
            kinematics: GapKinematics::SpherePlane,
            key: ContactKey { a: a as u32, b: Counterpart::Wall(WallId::Floor), feature: 0 },
        }
    }

    /// A sphere sliding on the floor at 1 m/s with μ = 0.3: one step of h takes μ g h off its
    /// slip (the disk's bound), and the normal impulse is m g h.
    #[test]
    fn sliding_takes_mu_g_h_off_the_slip() {
        let b = sphere(5e-3, Vec3::new(1.0, 0.0, 0.0));
        let h = 1e-3;
        let g = Vec3::new(0.0, 0.0, -9.81);
        let mut st = VelocityState::free(std::slice::from_ref(&b), &g, h);
        let c = floor(0, 5e-3);
        let sol = solve_impulses(
            &[c],
            &[NormalTarget { min_speed: 0.0, mu: 0.3, patch: 0.0, rolls: true }],
            &[WarmStart::default()],
            &mut st,
            1e-12,
            50,
            &Team::default(),
        );
        assert!((sol.normal[0] - 1e-3 * 9.81 * h).abs() < 1e-15);
        assert!(st.v[0].z.abs() < 1e-12);
        // Slip = v_x − r ω_y... the friction impulse −μ λ_n along x, so Δv_x = −μ g h.
        assert!((st.v[0].x - (1.0 - 0.3 * 9.81 * h)).abs() < 1e-12, "{}", st.v[0].x);
        assert!((sol.friction[0].norm() - 0.3 * sol.normal[0]).abs() < 1e-15);
    }

    /// A restitution target is met exactly, and a warm start at the answer needs one sweep.
    #[test]
    fn restitution_and_warm_start() {
        let b = sphere(5e-3, Vec3::new(0.0, 0.0, -1.0));
        let g = Vec3::zeros();
        let c = floor(0, 5e-3);
        let t = [NormalTarget { min_speed: 0.5, mu: 0.0, patch: 0.0, rolls: true }];
        let mut st = VelocityState::free(std::slice::from_ref(&b), &g, 1e-3);
        let sol =
            solve_impulses(std::slice::from_ref(&c), &t, &[WarmStart::default()], &mut st, 1e-12, 50, &Team::default());
        assert!((st.v[0].z - 0.5).abs() < 1e-12);
        let mut st = VelocityState::free(std::slice::from_ref(&b), &g, 1e-3);
        let warm = WarmStart { normal: sol.normal[0], ..WarmStart::default() };
        let again = solve_impulses(&[c], &t, &[warm], &mut st, 1e-12, 50, &Team::default());
        assert_eq!(again.sweeps, 1);
        assert!((st.v[0].z - 0.5).abs() < 1e-12);
    }

    /// A ball spinning fast about the floor's normal on a patch of radius a: one step of h
    /// takes Hertz's full-slip torque (3π/16) μ a λ_n off its spin, λ_n = m g h.
    #[test]
    fn a_patch_slows_a_spin_by_its_coulomb_torque() {
        let mut b = sphere(5e-3, Vec3::zeros());
        b.angular_momentum = Vec3::new(0.0, 0.0, 1e-8 * 50.0);
        let (h, a, mu) = (1e-3, 1e-5, 0.3);
        let g = Vec3::new(0.0, 0.0, -9.81);
        let mut st = VelocityState::free(std::slice::from_ref(&b), &g, h);
        let t = [NormalTarget { min_speed: 0.0, mu, patch: a, rolls: true }];
        let sol = solve_impulses(&[floor(0, 5e-3)], &t, &[WarmStart::default()], &mut st, 1e-12, 50, &Team::default());
        let want = 50.0 - patch::SPIN_FACTOR * mu * a * 1e-3 * 9.81 * h / 1e-8;
        assert!((st.w[0].z - want).abs() < 1e-12, "{} against {want}", st.w[0].z);
        assert!(sol.converged);
    }

    /// A ball rolling on the floor (μ large enough to hold it): the patch's rolling torque
    /// a λ_n, with friction keeping the contact from slipping, takes a λ_n / (I + m r²) off
    /// its rolling speed in a step.
    #[test]
    fn a_patch_slows_rolling_by_its_rim_torque() {
        let (r, w0) = (5e-3, 1.0);
        let mut b = sphere(r, Vec3::new(0.0, -w0 * r, 0.0));
        b.angular_momentum = Vec3::new(1e-8 * w0, 0.0, 0.0);
        let (h, a) = (1e-3, 1e-5);
        let g = Vec3::new(0.0, 0.0, -9.81);
        let mut st = VelocityState::free(std::slice::from_ref(&b), &g, h);
        let t = [NormalTarget { min_speed: 0.0, mu: 0.5, patch: a, rolls: true }];
        let sol = solve_impulses(&[floor(0, r)], &t, &[WarmStart::default()], &mut st, 1e-14, 200, &Team::default());
        let want = w0 - a * 1e-3 * 9.81 * h / (1e-8 + 1e-3 * r * r);
        assert!(sol.converged);
        assert!((st.w[0].x - want).abs() < 1e-9, "{} against {want}", st.w[0].x);
        assert!((st.v[0].y + st.w[0].x * r).abs() < 1e-9, "the contact slips");
        assert!((sol.torque[0].x + a * sol.normal[0]).abs() < 1e-18);
    }

    /// A pile of spheres on a lattice, touching, falling on the floor with scattered
    /// velocities and spins: enough contacts for the solve to take several threads.
    pub(super) fn pile() -> (Vec<Body>, Vec<Contact>, Vec<NormalTarget>) {
        let (r, n) = (5e-3, 7usize);
        let mut bodies = Vec::new();
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut noise = || {
            seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
            (seed >> 11) as Real / (1u64 << 53) as Real - 0.5
        };
        for k in 0..n * n * n {
            let (i, j, l) = (k % n, k / n % n, k / (n * n));
            let at = Vec3::new(i as Real, j as Real, l as Real) * 2.0 * r + Vec3::new(0.0, 0.0, r);
            let mut b = sphere(at.z, Vec3::new(noise(), noise(), noise() - 1.0) * 0.1);
            b.position = at;
            b.angular_momentum = Vec3::new(noise(), noise(), noise()) * 1e-8 * 20.0;
            bodies.push(b);
        }
        let mut contacts = Vec::new();
        for (a, ba) in bodies.iter().enumerate() {
            if ba.position.z < 1.5 * r {
                contacts.push(floor(a, r));
            }
            for (b, bb) in bodies.iter().enumerate().skip(a + 1) {
                let d = bb.position - ba.position;
                if d.norm() < 2.0 * r + 1e-9 {
                    let normal = -d.normalize();
                    contacts.push(Contact {
                        a,
                        b: Counterpart::Body(b),
                        point: ba.position - normal * r,
                        lever_a: -normal * r,
                        lever_b: normal * r,
                        normal,
                        gap: 0.0,
                        kinematics: GapKinematics::SphereSphere { distance: d.norm() },
                        key: ContactKey { a: a as u32, b: Counterpart::Body(b), feature: 0 },
                    });
                }
            }
        }
        let targets = contacts
            .iter()
            .enumerate()
            .map(|(k, _)| NormalTarget {
                min_speed: if k % 7 == 0 { 0.05 } else { 0.0 },
                mu: 0.4,
                patch: 1e-5,
                rolls: k % 3 != 0,
            })
            .collect();
        (bodies, contacts, targets)
    }

    /// The answer does not depend on the threads: every impulse and velocity bit for bit, for
    /// 1, 2 and 3 threads, converged (to 0.1 mm/s: the lattice's friction is statically
    /// indeterminate, and Gauss–Seidel creeps there) or stopped at the sweep cap.
    #[test]
    fn any_thread_count_gives_the_same_answer() {
        let (bodies, contacts, targets) = pile();
        assert!(contacts.len() > 4 * sweep::MIN_PARALLEL_CONTACTS, "{} contacts", contacts.len());
        let warm: Vec<WarmStart> = (0..contacts.len())
            .map(|k| WarmStart { normal: if k % 2 == 0 { 1e-7 } else { 0.0 }, ..WarmStart::default() })
            .collect();
        for sweeps in [3, 10_000] {
            let solve = |threads: usize| {
                let mut st = VelocityState::free(&bodies, &Vec3::new(0.0, 0.0, -9.81), 1e-3);
                let sol = solve_impulses(&contacts, &targets, &warm, &mut st, 1e-4, sweeps, &Team::new(threads));
                let bits = |v: &[Vec3]| v.iter().flat_map(|x| x.iter().map(|c| c.to_bits())).collect::<Vec<u64>>();
                let normal: Vec<u64> = sol.normal.iter().map(|x| x.to_bits()).collect();
                (normal, bits(&sol.friction), bits(&sol.torque), bits(&st.v), bits(&st.w), sol.sweeps, sol.converged)
            };
            let one = solve(1);
            assert!(one.0.iter().any(|&x| x != 0), "no impulse");
            assert_eq!(one.6, sweeps > 3, "{} sweeps", one.5);
            for threads in [2, 3] {
                assert!(solve(threads) == one, "{threads} threads, cap {sweeps}");
            }
        }
    }

    #[test]
    fn tangents_are_orthonormal() {
        for n in [Vec3::z(), Vec3::x(), -Vec3::y(), Vec3::new(0.3, -0.5, 0.8).normalize()] {
            let (t1, t2) = tangents(&n);
            for (a, b) in [(n, t1), (n, t2), (t1, t2)] {
                assert!(a.dot(&b).abs() < 1e-15);
            }
            assert!((t1.norm() - 1.0).abs() < 1e-15 && (t2.norm() - 1.0).abs() < 1e-15);
        }
    }
}
