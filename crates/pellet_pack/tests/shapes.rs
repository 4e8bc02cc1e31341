//! Non-spherical pellets through the pack driver: a few cylinders end to end, and the mesh
//! (parry grid) path of the engine against the closed form on the same samples.

mod common;

use pellet_geom::{Pellet, Resolution, ShapeSpec};
use pellet_io::{EnergyRecord, Frame};
use pellet_pack::driver::mesh_shape;
use pellet_pack::{run_pack, Ending, RunSink};
use pellet_sim::geometry::narrow_phase::{collide_pair, Pellet as SimPellet};
use pellet_sim::geometry::samples::TypeGeometry;
use pellet_sim::{BodyType, Container, EngineParams, Material, Quat, ShapeDesc, Vec3, WallMaterial, World};
use rand::{RngExt, SeedableRng};

#[derive(Default)]
struct Frames(Vec<Frame>);

impl RunSink for Frames {
    fn frame(&mut self, frame: &Frame) -> Result<(), String> {
        self.0.push(frame.clone());
        Ok(())
    }
    fn energy(&mut self, _: &EnergyRecord) -> Result<(), String> {
        Ok(())
    }
}

/// `count` equilateral 10 mm cylinders packed by pack's defaults in a tube of `tube_mm`, run
/// for at most `max_time_s`.
fn pack_cylinders(tube_mm: f64, count: u32, max_time_s: f64) -> (pellet_pack::RunSummary, Frames) {
    let pellet =
        Pellet::build(ShapeSpec::Cylinder { diameter_mm: 10.0, height_mm: 10.0 }, Resolution::default()).unwrap();
    let config = common::pack_config(tube_mm, count, |o| o.max_time = Some(max_time_s));
    let mut sink = Frames::default();
    let summary = run_pack(&config, &pellet, &mut sink).unwrap();
    (summary, sink)
}

#[test]
fn packs_a_few_cylinders_end_to_end() {
    let (summary, sink) = pack_cylinders(30.0, 3, 1.5);
    println!("{summary:?}");
    assert_eq!(summary.pellets, 3);
    assert!(summary.max_penetration_m < 1e-2 * 0.01, "penetration {}", summary.max_penetration_m);
    let last = sink.0.last().expect("frames were recorded");
    assert_eq!(last.positions.len(), 3);
    for (p, q) in last.positions.iter().zip(&last.orientations) {
        let q = Quat::new_normalize(nalgebra::Quaternion::new(q[0], q[1], q[2], q[3]));
        // Every rim point inside the tube (radius 15 mm) and above the floor, 1e-4 m slack.
        for z in [-0.005, 0.005] {
            for k in 0..32 {
                let t = std::f64::consts::TAU * k as f64 / 32.0;
                let x = Vec3::from(*p) + q * Vec3::new(0.005 * t.cos(), 0.005 * t.sin(), z);
                assert!(x.x.hypot(x.y) < 0.015 + 1e-4 && x.z > -1e-4, "rim point outside: {x:?}");
            }
        }
        assert!(p[2] < 0.03, "the cylinders must have fallen to the floor: {p:?}");
    }
}

/// Two 10 mm cylinders at random poses overlapping by 0.1 mm (closed form): the closed-form SDF path and the mesh
/// path (parry signed-distance grid of a sharp 256-segment cylinder mesh) on the same samples
/// must find the same deepest contact: depth within 0.1 mm (≈ cell 0.18 mm / 2) and point
/// within half the spacing of the side's sample rings (1 mm): where the sides cross, the
/// closed form's point is exact (`contact_lateral`), the mesh path's the nearest sample.
#[test]
fn closed_form_and_mesh_paths_agree() {
    let spec = ShapeSpec::Cylinder { diameter_mm: 10.0, height_mm: 10.0 };
    let sharp = Pellet::build(spec, Resolution { level: 0, faces: Some(1024) }).unwrap();
    let closed = BodyType::solid_cylinder(0.005, 0.005).unwrap();
    let ShapeDesc::Mesh { grid, .. } = mesh_shape(&sharp).unwrap() else { panic!("mesh expected") };
    // Same samples as the closed form: only the signed-distance source differs.
    let geo_c = TypeGeometry::new(&closed);
    let mesh = BodyType {
        shape: ShapeDesc::Mesh { name: "cyl".into(), samples: geo_c.samples.clone(), grid },
        ..closed.clone()
    };
    let geo_m = TypeGeometry::new(&mesh);
    let mut w = World::new(
        Container::tube(0.2).unwrap(),
        Material { density: 2000.0, cor: 0.5, friction: 0.3 },
        WallMaterial { cor: 0.5, friction: 0.3 },
        EngineParams::default(),
    )
    .unwrap();
    let t = w.register_type(closed.clone()).unwrap();
    let xa = Vec3::new(0.0, 0.0, 0.05);
    let ida = w.add_body(t, xa, Quat::identity(), Vec3::zeros(), Vec3::zeros()).unwrap();
    let idb = w.add_body(t, xa + Vec3::x() * 0.02, Quat::identity(), Vec3::zeros(), Vec3::zeros()).unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    let (mut worst_depth, mut worst_point) = (0.0f64, 0.0f64);
    let n = 40;
    for _ in 0..n {
        let mut rv = || Vec3::new(rng.random::<f64>() - 0.5, rng.random::<f64>() - 0.5, rng.random::<f64>() - 0.5);
        let (qa, qb, dir) = (Quat::from_scaled_axis(rv() * 6.0), Quat::from_scaled_axis(rv() * 6.0), rv().normalize());
        w.body_mut(ida).unwrap().orientation = qa;
        w.body_mut(idb).unwrap().orientation = qb;
        let deepest = |w: &World, shape: &ShapeDesc, geom: &TypeGeometry| {
            let pa = SimPellet { index: 0, body: w.body(ida).unwrap(), shape, geom };
            let pb = SimPellet { index: 1, body: w.body(idb).unwrap(), shape, geom };
            let mut out = Vec::new();
            collide_pair(pa, pb, 1e-3, &mut out).unwrap();
            out.into_iter().min_by(|x, y| x.gap.total_cmp(&y.gap))
        };
        // Bisect the centre distance until the closed form's deepest penetration is 0.1 mm.
        let (mut lo, mut hi) = (0.0, 0.02);
        for _ in 0..30 {
            let mid = 0.5 * (lo + hi);
            w.body_mut(idb).unwrap().position = xa + dir * mid;
            match deepest(&w, &closed.shape, &geo_c) {
                Some(c) if c.gap < -1e-4 => lo = mid,
                _ => hi = mid,
            }
        }
        w.body_mut(idb).unwrap().position = xa + dir * hi;
        let c = deepest(&w, &closed.shape, &geo_c).expect("touching");
        let m = deepest(&w, &mesh.shape, &geo_m).expect("the mesh path missed the contact");
        worst_depth = worst_depth.max((c.gap - m.gap).abs());
        worst_point = worst_point.max((c.lever_a - m.lever_a).norm());
    }
    println!("closed form vs mesh grid, {n} overlapping poses: depth difference ≤ {worst_depth:.2e} m, point ≤ {worst_point:.2e} m");
    assert!(worst_depth < 1e-4, "depth {worst_depth}");
    // Side sample rings 2h/5 = 2 mm apart.
    assert!(worst_point < 1e-3, "point {worst_point}");
}

/// A small cylinder bed comes to rest in pack's model. Before the exact fallback
/// (`EXACT_FALLBACK_MAX_ROWS`) islands the iterative solver left unconverged made cylinder
/// beds creep for ever (pellets turning by degrees per second), so pack ran to its time limit:
/// this bed was still moving after 8 s (max speed 1.9e-3 m/s); with it, it settles at 2.19 s.
#[test]
fn a_cylinder_bed_settles() {
    let (summary, _) = pack_cylinders(40.0, 20, 4.0);
    println!("{summary:?}");
    assert_eq!(summary.pellets, 20);
    assert_eq!(summary.ending, Ending::Settled, "not settled: {:?}", summary.settle);
    assert!(summary.max_penetration_m < 1e-2 * 0.01, "penetration {}", summary.max_penetration_m);
}

/// The first 1.1 s of the paper's ring bed (D = 40.45 mm, seed 1, one column, filled to 120
/// mm): on a 41-row island at t = 1.048 s the friction fixed point of the exact fallback grew
/// ×12 per round (normal forces from 0.07 N to 1e20 N) and flung the bed out of the tube.
/// Every recorded pellet must stay inside the tube and above the floor, and no pellet may move
/// faster than a pellet dropped from the feed height could (≈ 2 m/s; bound 5 m/s).
#[test]
fn the_paper_ring_bed_is_not_flung_out() {
    let pellet = Pellet::build(
        ShapeSpec::Ring { outer_diameter_mm: 10.0, inner_diameter_mm: 6.0, height_mm: 10.0 },
        Resolution::default(),
    )
    .unwrap();
    let config = common::pack_config(40.45, 1, |o| {
        o.count = None;
        o.fill_height = Some(120.0);
        o.seed = Some(1);
        o.max_time = Some(1.1);
    });
    let mut sink = Frames::default();
    let summary = run_pack(&config, &pellet, &mut sink).expect("no engine error");
    println!("{summary:?}");
    assert!(summary.pellets >= 15, "pellets released by 1.1 s: {}", summary.pellets);
    let radius = 0.5 * 40.45e-3;
    let mut fastest: f64 = 0.0;
    for pair in sink.0.windows(2) {
        let (a, b) = (&pair[0], &pair[1]);
        for (i, p) in b.positions.iter().enumerate() {
            assert!(p[0].hypot(p[1]) < radius && p[2] > 0.0, "pellet {i} outside at t = {}: {p:?}", b.time_s);
            if let Some(q) = a.positions.get(i) {
                let d = ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt();
                fastest = fastest.max(d / (b.time_s - a.time_s));
            }
        }
    }
    println!("fastest pellet between frames: {fastest:.2} m/s");
    assert!(fastest < 5.0, "a pellet moved at {fastest:.1} m/s");
}
