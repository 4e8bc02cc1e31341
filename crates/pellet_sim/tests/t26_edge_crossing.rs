//! A rim of one ring crossing an edge of another keeps a continuous contact normal while the
//! pellets jiggle by micrometres, as in a bed at rest. The rim's refined point (the deepest
//! along the rim) lies where the two face depths of the edge are equal, so the shallower face's
//! normal, which the Euclidean SDF gives, flipped by 90° with round-off from substep to substep,
//! and wide ring beds never settled. The edge–edge normal is continuous there, and its gap is
//! the crossing's depth. Cylinders get it under the velocity-level stepper's rules
//! (`collide_pair_kept`), rings under both steppers'.

use pellet_sim::geometry::narrow_phase::{collide_pair, collide_pair_kept, Pellet};
use pellet_sim::geometry::sample_cache::SampleCache;
use pellet_sim::geometry::samples::TypeGeometry;
use pellet_sim::{BodyId, BodyType, Contact, Container, EngineParams, Material, Quat, Real, Vec3, WallMaterial, World};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Inner and outer radius, half height of the rings, m (the cylinders': the same outer radius
/// and half height).
const RING: (Real, Real, Real) = (0.003, 0.005, 0.005);
/// How deep B's rim point is placed inside A's edge, m.
const DEPTH: Real = 3e-6;
/// Height of A's centre (inside the container), m.
const BASE: Real = 0.05;

/// Ring B placed with a point of its bottom outer rim `depth` inside A's top outer edge at
/// E = (R, 0, BASE + H), the two edges crossing: `beta` turns B's rim tangent out of the plane
/// at right angles to A's edge (0: at right angles). Both bodies' surfaces allow the separating
/// direction n (A's corner diagonal), so the pellets touch only at the crossing.
fn crossing(beta: Real, depth: Real) -> (Vec3, Quat) {
    let (_, ro, h) = RING;
    let s = std::f64::consts::FRAC_1_SQRT_2;
    let n = Vec3::new(s, 0.0, s);
    let m = Vec3::new(-s, 0.0, s);
    let tangent = m * beta.cos() + Vec3::y() * beta.sin();
    let w = n.cross(&tangent);
    // B's axis a and the outward radial direction u of its rim point: −n bisects B's two faces
    // there (the bottom cap, normal −a, and the lateral face, normal u).
    let a = ((n - w) * s).normalize();
    let u = (-(n + w) * s).normalize();
    let rot = nalgebra::Rotation3::from_matrix_unchecked(nalgebra::Matrix3::from_columns(&[u, a.cross(&u), a]));
    let q = Quat::from_rotation_matrix(&rot);
    let e = Vec3::new(ro, 0.0, BASE + h);
    (e - n * depth - q * Vec3::new(ro, 0.0, -h), q)
}

fn contacts(w: &World, geoms: &[TypeGeometry; 2], lean: bool, cache: &mut SampleCache) -> Vec<Contact> {
    let shapes = [w.types()[0].shape.clone(), w.types()[1].shape.clone()];
    let b = w.bodies();
    let pa = Pellet { index: 0, body: &b[0], shape: &shapes[0], geom: &geoms[0] };
    let pb = Pellet { index: 1, body: &b[1], shape: &shapes[1], geom: &geoms[1] };
    let mut out = Vec::new();
    if lean {
        cache.next_round();
        collide_pair_kept(pa, pb, 1e-5, cache, &[], &mut out).unwrap();
    } else {
        collide_pair(pa, pb, 1e-5, &mut out).unwrap();
    }
    out
}

/// B's rim crossing A's edge for each of three crossing angles, B jiggled 200 times: every
/// contact that persists keeps its normal to within 2.6°, and the deepest gap is the placed
/// depth to within the jiggle's 0.5 µm plus 1 µm.
fn keeps_its_normal(shape: impl Fn() -> BodyType, lean: bool) {
    let mat = Material { density: 2000.0, cor: 0.5, friction: 0.3 };
    let wall = WallMaterial { cor: 0.5, friction: 0.3 };
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let (mut compared, mut worst, mut depth_error) = (0, 1.0 as Real, 0.0 as Real);
    for beta in [0.0, 0.4, -0.7] {
        let mut w = World::new(Container::tube(0.2).unwrap(), mat, wall, EngineParams::paper()).unwrap();
        let geoms = [TypeGeometry::new(&shape()), TypeGeometry::new(&shape())];
        let ta = w.register_type(shape()).unwrap();
        let tb = w.register_type(shape()).unwrap();
        w.add_body(ta, Vec3::new(0.0, 0.0, BASE), Quat::identity(), Vec3::zeros(), Vec3::zeros()).unwrap();
        let (x0, q0) = crossing(beta, DEPTH);
        w.add_body(tb, x0, q0, Vec3::zeros(), Vec3::zeros()).unwrap();
        let mut cache = SampleCache::default();
        let mut prev: Vec<Contact> = Vec::new();
        for step in 0..200 {
            // A bed at rest: B jiggles by up to 0.5 µm and 1e-5 rad about its placed pose.
            let d = Vec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
            let r = Vec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
            let b = w.body_mut(BodyId(1)).unwrap();
            b.position = x0 + d * 0.5e-6;
            b.orientation = Quat::from_scaled_axis(r * 1e-5) * q0;
            let now = contacts(&w, &geoms, lean, &mut cache);
            assert!(!now.is_empty(), "beta {beta}, step {step}: the pellets must touch");
            let deepest = now.iter().map(|c| c.gap).fold(Real::INFINITY, Real::min);
            depth_error = depth_error.max((deepest + DEPTH).abs());
            for c in &now {
                assert!(c.gap > -2e-5, "beta {beta}: only the crossing touches (gap {:.2e} m)", c.gap);
                if let Some(p) = prev.iter().find(|p| p.key == c.key) {
                    let cos = p.normal.dot(&c.normal);
                    worst = worst.min(cos);
                    compared += 1;
                    assert!(
                        cos > 0.999,
                        "beta {beta}, step {step}, feature {:#x}: the normal turned by {:.1}°",
                        c.key.feature,
                        cos.clamp(-1.0, 1.0).acos().to_degrees()
                    );
                }
            }
            prev = now;
        }
    }
    println!(
        "{compared} persistent contacts compared, smallest cosine {worst:.6}, largest depth error {depth_error:.2e} m"
    );
    assert!(compared > 300, "{compared}");
    assert!(depth_error <= 1.5e-6, "the deepest gap missed the crossing's depth by {depth_error:.2e} m");
}

fn ring() -> BodyType {
    let (ri, ro, h) = RING;
    BodyType::hollow_cylinder(ri, ro, h).unwrap()
}

fn cylinder() -> BodyType {
    let (_, ro, h) = RING;
    BodyType::solid_cylinder(ro, h).unwrap()
}

#[test]
fn a_rim_crossing_an_edge_keeps_its_normal() {
    keeps_its_normal(ring, false);
}

#[test]
fn a_ring_rim_crossing_an_edge_keeps_its_normal_under_the_velocity_rules() {
    keeps_its_normal(ring, true);
}

#[test]
fn a_cylinder_rim_crossing_an_edge_keeps_its_normal_under_the_velocity_rules() {
    keeps_its_normal(cylinder, true);
}
