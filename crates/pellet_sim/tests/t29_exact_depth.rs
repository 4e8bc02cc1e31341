//! Pairs placed at a known interpenetration: the narrow phase's deepest contact is the
//! analytic depth to 1 µm, wherever the contact falls between the pellets' surface samples.

use pellet_sim::geometry::narrow_phase::{collide_pair, collide_wall, Pellet};
use pellet_sim::geometry::samples::TypeGeometry;
use pellet_sim::{Body, BodyType, Container, Quat, Real, ShapeDesc, TypeId, Vec3, WallId};
use std::f64::consts::FRAC_PI_2;

/// 10 × 10 mm cylinders.
const R: Real = 0.005;
const H: Real = 0.005;
/// The interpenetration every case is placed at, m.
const DEPTH: Real = 2e-5;

fn body(ty: &BodyType, x: Vec3, q: Quat) -> Body {
    Body {
        type_id: TypeId(0),
        position: x,
        orientation: q,
        linear_momentum: Vec3::zeros(),
        angular_momentum: Vec3::zeros(),
        mass: 1.0,
        inertia_body: pellet_sim::Mat3::identity(),
        inv_inertia_body: pellet_sim::Mat3::identity(),
        bounding_radius: ty.bounding_radius_m,
    }
}

/// The deepest gap the narrow phase finds between `ta` at (xa, qa) and `tb` at (xb, qb).
fn deepest(ta: &BodyType, xa: Vec3, qa: Quat, tb: &BodyType, xb: Vec3, qb: Quat) -> Real {
    let (ga, gb) = (TypeGeometry::new(ta), TypeGeometry::new(tb));
    let (ba, bb) = (body(ta, xa, qa), body(tb, xb, qb));
    let (sa, sb): (&ShapeDesc, &ShapeDesc) = (&ta.shape, &tb.shape);
    let pa = Pellet { index: 0, body: &ba, shape: sa, geom: &ga };
    let pb = Pellet { index: 1, body: &bb, shape: sb, geom: &gb };
    let mut out = Vec::new();
    collide_pair(pa, pb, 1e-4, &mut out).unwrap();
    out.iter().map(|c| c.gap).fold(Real::INFINITY, Real::min)
}

fn check(name: &str, got: Real, want: Real) {
    println!("{name}: gap {got:.4e} m, analytic {want:.4e} m, error {:.2e} m", got - want);
    assert!((got - want).abs() <= 1e-6, "{name}: gap {got} against {want}");
}

fn cylinder() -> BodyType {
    BodyType::solid_cylinder(R, H).unwrap()
}

/// Axis along `dir` (unit, in the xy plane), turned about it by `roll`.
fn lying(angle: Real, roll: Real) -> Quat {
    Quat::from_axis_angle(&Vec3::z_axis(), angle)
        * Quat::from_axis_angle(&Vec3::y_axis(), FRAC_PI_2)
        * Quat::from_axis_angle(&Vec3::z_axis(), roll)
}

/// Two cylinders lying on their sides, one on the other, crossed at `angle`: their sides
/// touch at one point, anywhere along either axis (not at the surface samples' stations).
#[test]
fn crossed_sides() {
    let c = cylinder();
    for (angle, sa, sb, roll) in
        [(FRAC_PI_2, 0.0007, -0.0013, 0.1), (0.5, -0.0021, 0.0017, 0.7), (1.2, 0.0031, 0.0004, 2.0)]
    {
        let qa = lying(0.0, roll);
        let qb = lying(angle, -roll);
        let ua = qa * Vec3::z();
        let ub = qb * Vec3::z();
        // The axes' common perpendicular is z: A's point at s_a along its axis lies under B's at s_b.
        let xa = Vec3::new(0.0, 0.0, R) - ua * sa;
        let xb = Vec3::new(0.0, 0.0, 3.0 * R - DEPTH) - ub * sb;
        let got = deepest(&c, xa, qa, &c, xb, qb);
        check(&format!("sides crossed at {angle:.2} rad"), got, -DEPTH);
    }
}

/// Side by side, parallel, offset along the axis: a line contact whose ends are rims.
#[test]
fn parallel_sides() {
    let c = cylinder();
    for (shift, roll) in [(0.0, 0.3), (0.0031, 1.1), (-0.0047, 2.9)] {
        let q = lying(0.4, roll);
        let u = q * Vec3::z();
        let xa = Vec3::new(0.0, 0.0, R);
        let xb = Vec3::new(0.0, 0.0, 3.0 * R - DEPTH) + u * shift;
        let got = deepest(&c, xa, q, &c, xb, lying(0.4, -roll));
        check(&format!("parallel sides, shifted {shift:.4} m"), got, -DEPTH);
    }
}

/// A cylinder lying on the cap of an upright one.
#[test]
fn side_on_cap() {
    let c = cylinder();
    for (angle, roll, x, y) in [(0.3, 0.2, 0.0011, -0.0007), (1.9, 1.3, -0.0023, 0.0009)] {
        let got = deepest(
            &c,
            Vec3::new(0.0, 0.0, H),
            Quat::identity(),
            &c,
            Vec3::new(x, y, 2.0 * H + R - DEPTH),
            lying(angle, roll),
        );
        check(&format!("side on cap, axis at {angle:.2} rad"), got, -DEPTH);
    }
}

/// The tube wall's contacts of `c` at (x, q), as (gap, world point).
fn tube_contacts(c: &BodyType, tube: &Container, x: Vec3, q: Quat) -> Vec<(Real, Vec3)> {
    let g = TypeGeometry::new(c);
    let b = body(c, x, q);
    let p = Pellet { index: 0, body: &b, shape: &c.shape, geom: &g };
    let mut out = Vec::new();
    collide_wall(tube, WallId::Tube, p, 1e-4, &mut out).unwrap();
    out.iter().map(|k| (k.gap, k.point)).collect()
}

/// The local minima of the tube gap along each rim of `c` at (x, q), sampled every 1e-5 rad
/// (an independent, brute-force answer), within 1e-4 m.
fn rim_minima(tube_radius: Real, x: Vec3, q: Quat) -> Vec<Real> {
    let n = 628_319;
    let mut minima = Vec::new();
    for z in [-H, H] {
        let gap = |k: usize| {
            let t = std::f64::consts::TAU * k as Real / n as Real;
            let p = x + q * Vec3::new(R * t.cos(), R * t.sin(), z);
            tube_radius - (p.x * p.x + p.y * p.y).sqrt()
        };
        for k in 0..n {
            let (g0, gp, gn) = (gap(k), gap((k + n - 1) % n), gap((k + 1) % n));
            if g0 < gp && g0 <= gn && g0 <= 1e-4 {
                minima.push(g0);
            }
        }
    }
    minima.sort_by(Real::total_cmp);
    minima
}

/// A cylinder with its cap facing the tube wall touches it at two rim points, left and right
/// of the cap's centre (the wall does not curve along its axis): both are contacts, each at its
/// depth, square to the wall and turned and tilted a little.
#[test]
fn cap_facing_the_tube_wall() {
    let c = cylinder();
    let d = 0.04;
    let tube = Container::tube(d).unwrap();
    let rt = 0.5 * d;
    // Axis radial along x: the rim points (±R along y) lie at ρ² = (c + H)² + R².
    let centre = ((rt + DEPTH).powi(2) - R * R).sqrt() - H;
    for (turn, tilt) in [(0.0, 0.0), (0.02, 0.0), (0.01, 0.3)] {
        let q = Quat::from_axis_angle(&Vec3::z_axis(), turn)
            * Quat::from_axis_angle(&Vec3::y_axis(), FRAC_PI_2)
            * Quat::from_axis_angle(&Vec3::z_axis(), tilt);
        let x = Vec3::new(centre, 0.0, 0.03);
        let mut got: Vec<Real> = tube_contacts(&c, &tube, x, q).iter().map(|k| k.0).collect();
        got.sort_by(Real::total_cmp);
        let want = rim_minima(rt, x, q);
        println!("turn {turn}, tilt {tilt}: contacts {got:?}, sampled minima {want:?}");
        assert_eq!(got.len(), want.len(), "turn {turn}: one contact per point nearest the wall");
        assert_eq!(got.len(), 2, "turn {turn}: the cap's two rim points");
        for (g, w) in got.iter().zip(&want) {
            check(&format!("cap facing the tube, turned {turn} rad"), *g, *w);
        }
        if turn == 0.0 {
            check("cap facing the tube, square", got[0], -DEPTH);
            check("cap facing the tube, square", got[1], -DEPTH);
        }
    }
}
