//! The sampled narrow phase through its cache of candidate samples gives the full sweep's
//! contacts exactly, while two pellets in contact jiggle, roll apart and come back: cylinders,
//! rings and a cylinder against a ring, with the gap limit changing as in a pour.

use pellet_sim::geometry::narrow_phase::{collide_pair, collide_pair_cached, Pellet};
use pellet_sim::geometry::sample_cache::SampleCache;
use pellet_sim::geometry::samples::TypeGeometry;
use pellet_sim::{BodyType, Container, EngineParams, Material, Quat, Vec3, WallMaterial, World};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn pair_world(a: BodyType, b: BodyType) -> (World, [TypeGeometry; 2]) {
    let mat = Material { density: 2000.0, cor: 0.5, friction: 0.3 };
    let wall = WallMaterial { cor: 0.5, friction: 0.3 };
    let mut w = World::new(Container::tube(0.2).unwrap(), mat, wall, EngineParams::paper()).unwrap();
    let geoms = [TypeGeometry::new(&a), TypeGeometry::new(&b)];
    let ta = w.register_type(a).unwrap();
    let tb = w.register_type(b).unwrap();
    w.add_body(ta, Vec3::new(0.0, 0.0, 0.05), Quat::identity(), Vec3::zeros(), Vec3::zeros()).unwrap();
    w.add_body(tb, Vec3::new(0.0, 0.0, 0.0599), Quat::identity(), Vec3::zeros(), Vec3::zeros()).unwrap();
    (w, geoms)
}

#[test]
fn cached_contacts_equal_the_full_sweep() {
    let cylinder = || BodyType::solid_cylinder(0.005, 0.005).unwrap();
    let ring = || BodyType::hollow_cylinder(0.003, 0.005, 0.005).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    for (name, a, b) in
        [("cylinders", cylinder(), cylinder()), ("rings", ring(), ring()), ("mixed", cylinder(), ring())]
    {
        let (mut w, geoms) = pair_world(a, b);
        let shapes = [w.types()[0].shape.clone(), w.types()[1].shape.clone()];
        let mut cache = SampleCache::default();
        let (mut touching, mut steps) = (0, 0);
        for step in 0..600 {
            // Mostly tiny motions (a bed at rest), now and then a jump; B tilts as it goes.
            let big = step % 97 == 0;
            let scale = if big { 2e-3 } else { 2e-6 };
            let b = w.body_mut(pellet_sim::BodyId(1)).unwrap();
            let d = Vec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
            b.position += d * scale;
            // Keep B on A's top, within a few mm of touching.
            b.position.z = b.position.z.clamp(0.0592, 0.0601);
            b.position.x = b.position.x.clamp(-0.004, 0.004);
            b.position.y = b.position.y.clamp(-0.004, 0.004);
            let axis =
                nalgebra::Unit::new_normalize(Vec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), 0.3));
            b.orientation = nalgebra::UnitQuaternion::from_axis_angle(&axis, 100.0 * scale) * b.orientation;
            if b.orientation.angle() > 0.2 {
                b.orientation = Quat::identity();
            }
            let max_gap = if step % 5 == 0 { 3e-4 } else { 1e-5 };
            let bodies = w.bodies();
            let pa = Pellet { index: 0, body: &bodies[0], shape: &shapes[0], geom: &geoms[0] };
            let pb = Pellet { index: 1, body: &bodies[1], shape: &shapes[1], geom: &geoms[1] };
            let (mut fresh, mut cached) = (Vec::new(), Vec::new());
            collide_pair(pa, pb, max_gap, &mut fresh).unwrap();
            cache.next_round();
            collide_pair_cached(pa, pb, max_gap, &mut cache, &mut cached).unwrap();
            assert_eq!(cached, fresh, "{name}, step {step}");
            touching += usize::from(!fresh.is_empty());
            steps += 1;
        }
        let (builds, lookups) = cache.counts();
        println!("{name}: {touching} of {steps} steps touching, {builds} full sweeps for {lookups} lookups");
        assert!(touching > 300, "{name}: the pair must touch most of the time ({touching})");
        assert_eq!(lookups, 600);
        assert!(builds < 200 && builds > 10, "{name}: {builds} full sweeps");
    }
}
