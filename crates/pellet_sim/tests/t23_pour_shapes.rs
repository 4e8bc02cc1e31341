//! 20 cylinders and 20 Raschig rings (10 mm, rings 10/6/10) poured into a 40 mm tube, paper
//! mode: max penetration < 1 % of d = 10 mm at every step, no pellet outside the tube.

mod common;
use common::*;
use pellet_sim::{Vec3, World};

/// Largest excursion of any rim point beyond the tube wall or below the floor, m.
fn outside(w: &World, tube_r: f64) -> f64 {
    let mut worst = f64::NEG_INFINITY;
    for b in w.bodies() {
        for z in [-0.005, 0.005] {
            for k in 0..64 {
                let t = std::f64::consts::TAU * k as f64 / 64.0;
                let p = b.position + b.orientation * Vec3::new(0.005 * t.cos(), 0.005 * t.sin(), z);
                worst = worst.max(p.x.hypot(p.y) - tube_r).max(-p.z);
            }
        }
    }
    worst
}

/// Pours the 40 pellets for `seconds`; returns (max penetration, worst excursion, KE at end).
pub fn pour(seconds: f64, seed: u64) -> (f64, f64, f64, World) {
    let tube_d = 0.04;
    let mut w = mixed_pour(40, seed);
    let mut p = pellet_sim::Pipeline::new();
    let (mut pen, mut out) = (0.0f64, f64::NEG_INFINITY);
    for _ in 0..(seconds * 40.0) as usize {
        let r = w.step(1.0 / 40.0, &mut p).unwrap();
        pen = pen.max(r.max_penetration);
        out = out.max(outside(&w, 0.5 * tube_d));
    }
    let ke = w.kinetic_energy();
    (pen, out, ke, w)
}

/// The acceptance test of the non-spherical engine: 20 cylinders and 20 rings poured, seed 7,
/// 1.5 s, must settle with penetration below 1 % of d. The worst penetrations are made in the
/// narrow phase, not by missed sampling: an edge-face switch that measures a rim's depth along
/// the deeper lateral face (1.06e-4 m read, 3.7e-6 m true; see `FACE_SWITCH` in
/// `geometry/contact_sampled.rs`) and a patch reduction that drops a touching refined rim point
/// (it then sinks 8.3e-5 m in one substep; see `geometry/patch.rs`); with those two, the pour
/// reaches 1.09e-4 m (1.09 % of d). Measured: max penetration 2.88e-5 m, worst excursion
/// 2.17e-5 m, KE 8.8e-7 J, top centre 0.0469 m, 187 s wall in release with three other jobs on
/// the two cores.
/// Alone: `cargo test -p pellet_sim --release --test t23_pour_shapes -- --nocapture`.
#[test]
fn twenty_cylinders_and_twenty_rings_settle() {
    let t0 = std::time::Instant::now();
    let (pen, out, ke, w) = pour(1.5, 7);
    let zmax = w.bodies().iter().map(|b| b.position.z).fold(0.0, f64::max);
    println!("pour 40: max pen {pen:.2e} m ({:.2e} of 10 mm), worst excursion {out:.2e} m, KE {ke:.2e} J, top centre {zmax:.4} m, wall {:?}", pen / 0.01, t0.elapsed());
    assert!(pen < 1e-2 * 0.01, "penetration {pen}");
    assert!(out < 1e-2 * 0.01, "a pellet is outside the tube by {out}");
    assert!(zmax < 0.08, "the bed did not settle: top at {zmax}");
}
