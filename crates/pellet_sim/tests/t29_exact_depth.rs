//! Pairs placed at a known interpenetration: the narrow phase's deepest contact is the
//! analytic depth to 1 µm, wherever the contact falls between the pellets' surface samples,
//! under both steppers' rules: `collide_pair` (the force-level stepper's, whose
//! `collide_pair_cached` gives the same contacts) and `collide_pair_kept` (the velocity-level
//! stepper's, with edge–edge normals at cylinder rims).

use pellet_sim::geometry::narrow_phase::{collide_pair, collide_pair_kept, collide_wall, Pellet};
use pellet_sim::geometry::sample_cache::SampleCache;
use pellet_sim::geometry::samples::TypeGeometry;
use pellet_sim::{Body, BodyType, Container, Quat, Real, SdfGrid, ShapeDesc, TypeId, Vec3, WallId};
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI, TAU};

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

/// The rules a pair is collided under.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Rules {
    /// `collide_pair`: the force-level stepper's.
    Force,
    /// `collide_pair_kept`: the velocity-level stepper's.
    Velocity,
}

/// The deepest gap the narrow phase finds between `ta` at (xa, qa) and `tb` at (xb, qb).
fn deepest(rules: Rules, ta: &BodyType, xa: Vec3, qa: Quat, tb: &BodyType, xb: Vec3, qb: Quat) -> Real {
    let (ga, gb) = (TypeGeometry::new(ta), TypeGeometry::new(tb));
    let (ba, bb) = (body(ta, xa, qa), body(tb, xb, qb));
    let (sa, sb): (&ShapeDesc, &ShapeDesc) = (&ta.shape, &tb.shape);
    let pa = Pellet { index: 0, body: &ba, shape: sa, geom: &ga };
    let pb = Pellet { index: 1, body: &bb, shape: sb, geom: &gb };
    let mut out = Vec::new();
    match rules {
        Rules::Force => collide_pair(pa, pb, 1e-4, &mut out).unwrap(),
        Rules::Velocity => collide_pair_kept(pa, pb, 1e-4, &mut SampleCache::default(), &[], &mut out).unwrap(),
    }
    if std::env::var_os("T29_CONTACTS").is_some() {
        for c in &out {
            println!("  {rules:?}: gap {:.4e} normal {:.4?} feature {:#x}", c.gap, c.normal, c.key.feature);
        }
    }
    out.iter().map(|c| c.gap).fold(Real::INFINITY, Real::min)
}

/// [`check`] of the pair under both steppers' rules.
fn check_pair(name: &str, ta: &BodyType, a: (Vec3, Quat), tb: &BodyType, b: (Vec3, Quat), want: Real) {
    for rules in [Rules::Force, Rules::Velocity] {
        check(&format!("{name}, {rules:?} rules"), deepest(rules, ta, a.0, a.1, tb, b.0, b.1), want);
    }
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
        check_pair(&format!("sides crossed at {angle:.2} rad"), &c, (xa, qa), &c, (xb, qb), -DEPTH);
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
        let name = format!("parallel sides, shifted {shift:.4} m");
        check_pair(&name, &c, (xa, q), &c, (xb, lying(0.4, -roll)), -DEPTH);
    }
}

/// Two upright cylinders side by side on one level, as on a floor: their caps are flush (or
/// within a fraction of a micrometre of it), so at a rim point inside the other pellet its cap
/// is the shallower face, flat along the rim, and the side's overlap is the depth. A bed of
/// 2000 cylinders ended with such a pair 7.5 µm deep where the narrow phase saw 0.3 µm.
#[test]
fn upright_sides_on_one_level() {
    let c = cylinder();
    for (depth, azimuth, roll, lift) in
        [(DEPTH, 0.3_f64, 0.0, 0.0), (6e-6, 1.87, 0.41, 2.4e-7), (6e-6, -2.6, 1.3, -1.1e-7), (2e-6, 0.05, 2.2, 0.0)]
    {
        let qa = Quat::from_axis_angle(&Vec3::z_axis(), roll);
        let qb = Quat::from_axis_angle(&Vec3::z_axis(), -0.7 * roll);
        let xa = Vec3::new(0.0, 0.0, H);
        let xb = Vec3::new(azimuth.cos(), azimuth.sin(), 0.0) * (2.0 * R - depth) + Vec3::new(0.0, 0.0, H + lift);
        let name = format!("upright sides on one level, {depth:.1e} m deep at azimuth {azimuth}");
        check_pair(&name, &c, (xa, qa), &c, (xb, qb), -depth);
    }
}

/// A cylinder lying on the cap of an upright one.
#[test]
fn side_on_cap() {
    let c = cylinder();
    for (angle, roll, x, y) in [(0.3, 0.2, 0.0011, -0.0007), (1.9, 1.3, -0.0023, 0.0009)] {
        let a = (Vec3::new(0.0, 0.0, H), Quat::identity());
        let b = (Vec3::new(x, y, 2.0 * H + R - DEPTH), lying(angle, roll));
        check_pair(&format!("side on cap, axis at {angle:.2} rad"), &c, a, &c, b, -DEPTH);
    }
}

/// A upright with its centre at (0, 0, H), turned by `roll_a` about its axis, and B with its
/// bottom rim crossing A's top rim at E = (R, 0, 2H), `DEPTH` deep along
/// n = (cos α, 0, sin α): −n splits B's two face normals there (its cap's −a and its side's u)
/// at `phi` from −a, and B's rim tangent there is t = m cos β + y sin β with m = n × y; B is
/// turned by `roll_b` about its axis. Returns B's pose.
///
/// Depth: at DEPTH = 0 the plane through E normal to n separates the pellets (n lies in A's
/// normal cone at its rim, between x and z, and −n in B's), and they touch at E alone because
/// the rims' tangents y and t are not parallel (cos β ≠ 0). Moved by −DEPTH n they overlap by
/// DEPTH along n; any other direction n' separates them only by more: the sum of the two
/// pellets' support functions grows from its zero at n as the rims' curvature (1/R) times the
/// squared angle, because every direction at right angles to n has a part along y or along t,
/// and that beats the DEPTH (1 − n·n') that moving along n' saves while the angle is
/// ≫ DEPTH / R. So the depth is DEPTH, to O(DEPTH²/R) = 0.1 µm.
fn rim_crossing(alpha: Real, phi: Real, beta: Real, roll_b: Real) -> (Vec3, Quat) {
    let n = Vec3::new(alpha.cos(), 0.0, alpha.sin());
    let m = n.cross(&Vec3::y());
    let t = m * beta.cos() + Vec3::y() * beta.sin();
    let w = n.cross(&t);
    // B's axis a and the outward radial direction u of its rim point, both at right angles to
    // t; −n = cos φ (−a) + sin φ u.
    let a = n * phi.cos() + w * phi.sin();
    let u = -n * phi.sin() + w * phi.cos();
    let frame = nalgebra::Rotation3::from_matrix_unchecked(nalgebra::Matrix3::from_columns(&[u, a.cross(&u), a]));
    let q = Quat::from_rotation_matrix(&frame) * Quat::from_axis_angle(&Vec3::z_axis(), roll_b);
    // B's rim point (R, 0, −H) in the frame, at E − DEPTH n.
    let rim_point = Quat::from_axis_angle(&Vec3::z_axis(), -roll_b) * Vec3::new(R, 0.0, -H);
    (Vec3::new(R, 0.0, 2.0 * H) - n * DEPTH - q * rim_point, q)
}

/// Two cylinders or two rings (`ty`) whose outer rims cross (`rim_crossing`; a ring is a
/// cylinder less its bore, so nothing else of them meets), at four pairs of face splits and
/// crossing angles.
fn rim_on_rim(rules: Rules, ty: BodyType) {
    let c = ty;
    for (alpha, phi, beta, roll_a, roll_b) in [
        (FRAC_PI_4, FRAC_PI_4, 0.0, 0.0, 0.0),
        (0.5, 1.0, 0.6, 0.013, 0.4),
        (1.1, 0.4, -0.9, 2.1, 1.7),
        (0.8, 0.7, 1.2, -0.9, 3.3),
    ] {
        let a = (Vec3::new(0.0, 0.0, H), Quat::from_axis_angle(&Vec3::z_axis(), roll_a));
        let b = rim_crossing(alpha, phi, beta, roll_b);
        let got = deepest(rules, &c, a.0, a.1, &c, b.0, b.1);
        check(&format!("rims crossed, α {alpha:.2}, φ {phi:.2}, β {beta:.2}, {rules:?} rules"), got, -DEPTH);
    }
}

#[test]
fn cylinder_rims_under_the_velocity_rules() {
    rim_on_rim(Rules::Velocity, cylinder());
}

/// The force-level stepper takes a cylinder rim's contact from the faces' signed distance (on
/// purpose: `contact_sampled`, `OneWay::edge_edge`), the depth to the nearer face at the rim's
/// deepest point, DEPTH / (cos α' + sin α') for the corner's split α' of the crossing's normal.
#[test]
#[ignore = "force-level rules: a cylinder rim crossing a rim reads the nearer face, 4.8-5.9 µm shallow"]
fn cylinder_rims_under_the_force_rules() {
    rim_on_rim(Rules::Force, cylinder());
}

#[test]
fn ring_rims_under_both_steppers_rules() {
    rim_on_rim(Rules::Force, ring());
    rim_on_rim(Rules::Velocity, ring());
}

/// Raschig ring: 10 mm outside, 6 mm bore, 10 mm high.
const RI: Real = 0.003;

fn ring() -> BodyType {
    BodyType::hollow_cylinder(RI, R, H).unwrap()
}

/// The whole pair turned off the axes (the ring's axis is not z).
fn tilted() -> Quat {
    Quat::from_axis_angle(&nalgebra::Unit::new_normalize(Vec3::new(0.3, -0.8, 0.5)), 0.7)
}

/// A pin (a thin cylinder, parallel to the ring's axis) inside the ring's bore, pressed against
/// the bore wall: short pins whose ends lie inside the bore, and a long one through it whose
/// contact line ends at the bore's edges.
///
/// Depth: in the ring's frame the pin's axis is at distance RI − r + DEPTH from the ring's, so
/// its side reaches radius RI + DEPTH, DEPTH into the wall along the radius, all along the
/// line where both lie; the pin's cross-section must move by at least DEPTH to fit in the
/// bore's disc again (its centre within RI − r of the ring's axis), so the depth is DEPTH.
#[test]
fn pin_in_ring_bore() {
    let ring = ring();
    let q = tilted();
    let x0 = Vec3::new(0.01, -0.02, 0.03);
    for (r, h, psi, z, roll_a, roll_b) in [
        (0.001, 0.003, 0.3, 0.0011, 0.0, 0.0),
        (0.0015, 0.002, 4.0, -0.0025, 0.7, 1.9),
        (0.001, 0.008, 2.2, 0.0, 1.3, 0.2),
        (0.0008, 0.0065, 5.1, 0.0004, 2.6, 0.9),
    ] {
        let pin = BodyType::solid_cylinder(r, h).unwrap();
        let centre = Vec3::new(Real::cos(psi), Real::sin(psi), 0.0) * (RI - r + DEPTH) + Vec3::new(0.0, 0.0, z);
        let a = (x0, q * Quat::from_axis_angle(&Vec3::z_axis(), roll_a));
        let b = (x0 + q * centre, q * Quat::from_axis_angle(&Vec3::z_axis(), roll_b));
        let name = format!("pin r {r} h {h} in the bore at {psi:.1} rad");
        check_pair(&name, &ring, a, &pin, b, -DEPTH);
        check_pair(&format!("{name}, swapped"), &pin, b, &ring, a, -DEPTH);
    }
}

/// A 4 mm sphere in the ring's bore against the wall: its centre at RI − r + DEPTH from the
/// axis, so its surface reaches radius RI + DEPTH.
#[test]
fn sphere_in_ring_bore() {
    let ring = ring();
    let r = 0.002;
    let ball = BodyType::solid_sphere(r).unwrap();
    let q = tilted();
    for (psi, z) in [(0.4, 0.0), (3.0, 0.0021), (5.5, -0.0029)] {
        let centre = Vec3::new(Real::cos(psi), Real::sin(psi), 0.0) * (RI - r + DEPTH) + Vec3::new(0.0, 0.0, z);
        let b = (q * centre, Quat::identity());
        check_pair(&format!("sphere in the bore at {psi:.1} rad"), &ring, (Vec3::zeros(), q), &ball, b, -DEPTH);
    }
}

/// Lobe diameter, size (circle around the lobes) and height of the trilobe, mm.
const TRILOBE_MM: (Real, Real, Real) = (1.6, 2.9, 5.0);

/// `mkpellet trilobe --lobe-diameter 1.6 --size 2.9 --height 5` as a pack run hands it to the
/// engine (`pellet_pack::setup::mesh_shape`): the mesh's vertices as samples (fewer than its
/// sample limit: none thinned) and a signed-distance grid of cell d/80 and margin d/10.
fn trilobe() -> BodyType {
    let (lobe, size, height) = TRILOBE_MM;
    let spec = pellet_geom::ShapeSpec::Lobed { lobes: 3, lobe_diameter_mm: lobe, size_mm: size, height_mm: height };
    let pellet = pellet_geom::Pellet::build(spec, pellet_geom::Resolution::default()).unwrap();
    let d = 2.0 * pellet.bounding_radius;
    let (cell, margin) = (d / 80.0, 0.1 * d);
    let (origin, dims, values) = pellet_geom::parry_boundary::signed_distance_grid(&pellet.mesh, cell, margin).unwrap();
    let samples: Vec<Vec3> = pellet.mesh.vertices.iter().map(|v| v.coords).collect();
    assert!(samples.len() <= 3000, "{} vertices: the pack run would thin them", samples.len());
    let grid = SdfGrid { origin: origin.coords, cell, dims, values, margin };
    BodyType {
        shape: ShapeDesc::Mesh { name: "trilobe".into(), samples, grid },
        volume_m3: pellet.properties.volume,
        inertia_per_density_m5: pellet.properties.inertia,
        bounding_radius_m: pellet.bounding_radius,
    }
}

/// Two trilobes side by side, axes parallel, lobe k of A pressing on lobe k + 1 of B: B turned
/// about A's lobe's axis to ten angles ψ (the contact falls elsewhere among the mesh's vertices
/// and the grid's nodes) and shifted along the axes by `z`.
///
/// Depth: A's lobe k has its axis at c e_k, c = (size − d)/2, e_k at angle 2πk/3; B's lobe
/// k + 1 has its axis at c e_k + (d − DEPTH) e, e = e_k turned by ψ, and points along −e (B's
/// centre at its lobe's axis plus c e). The two lobe cylinders (radius d/2) overlap by DEPTH
/// along e; for |ψ| ≤ 40° their contact lies on both lobes' outer arcs (which span ±104.7°)
/// and the other lobes stay over 0.3 mm apart, so the depth is DEPTH.
#[test]
#[ignore = "grid SDF of the Loop-subdivided mesh: measured 0.5-3.5 µm shallow"]
fn trilobe_lobe_on_lobe() {
    let t = trilobe();
    let (lobe, size, _) = TRILOBE_MM;
    let (c, d) = (0.5e-3 * (size - lobe), 1e-3 * lobe);
    let turn = |angle: Real| Quat::from_axis_angle(&Vec3::z_axis(), angle);
    let dir = |angle: Real| Vec3::new(angle.cos(), angle.sin(), 0.0);
    let mut worst: Real = 0.0;
    for j in 0..10 {
        let k = j % 3;
        let psi = (-40.0 + 80.0 * j as Real / 9.0).to_radians();
        let z = 1e-3 * [0.0, 0.37, -0.81][k];
        let ek = TAU * k as Real / 3.0;
        let e = ek + psi;
        let lobe_b = c * dir(ek) + (d - DEPTH) * dir(e);
        // B's lobe k + 1 sits at B's angle 2π(k + 1)/3 and must point along −e.
        let b = (lobe_b + c * dir(e) + Vec3::new(0.0, 0.0, z), turn(e + PI - TAU * (k + 1) as Real / 3.0));
        let a = (Vec3::zeros(), Quat::identity());
        for rules in [Rules::Force, Rules::Velocity] {
            let got = deepest(rules, &t, a.0, a.1, &t, b.0, b.1);
            worst = worst.max((got + DEPTH).abs());
            let name = format!("trilobes, lobe {k} at ψ {:.1}°, {rules:?} rules", psi.to_degrees());
            println!("{name}: gap {got:.4e} m, error {:.2e} m", got + DEPTH);
        }
    }
    println!("trilobes: largest error {worst:.2e} m");
    assert!(worst <= 1e-6, "trilobes: largest error {worst:.2e} m");
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

/// Two cylinders of the 620-cylinder bed (seed 1, pellets 167 and 300 at rest, poses in mm
/// from `settle-check --csv`): B's cap lies almost flat against A's side next to A's rim, the
/// overlap a strip ~0.44 mm wide cut off by the two rims, between the surface samples.
/// `pellet_analysis::deepest_overlap` (exact surfaces, independent of the engine) finds them
/// 4.809 µm deep, ~10 µm below A's rim on its side; the best rim point is 3.7 µm deep, so the
/// refined rim points must be followed into their faces (`rim_refine`).
#[test]
fn rims_crossing_in_the_620_cylinder_bed() {
    let c = cylinder();
    let pose = |x: [Real; 3], q: [Real; 4]| {
        (Vec3::from(x) * 1e-3, Quat::from_quaternion(nalgebra::Quaternion::new(q[0], q[1], q[2], q[3])))
    };
    let a = pose(
        [1.5869645570539042, 10.99020707741654, 40.99446766306336],
        [0.06433852496152628, 0.5159320742981977, 0.06392277404326252, -0.8518148436572048],
    );
    let b = pose(
        [4.181959783670155, 1.4197079758673194, 42.25843704806751],
        [0.03937309251986795, 0.15216782939144274, -0.7345431847658551, -0.6601068254439987],
    );
    check_pair("rims crossing in the 620-cylinder bed", &c, a, &c, b, -4.809027e-6);
}
