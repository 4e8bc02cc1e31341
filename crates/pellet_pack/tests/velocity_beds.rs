//! Small cylinder and ring beds come to rest under the velocity-level stepper: 40 pellets of
//! 10 × 10 mm in a 40 mm tube, batch loading, seeds 1–6, each within 8 s simulated, with the
//! contact solve, over the last 0.1 s, warm starting (nearly) every loaded contact and
//! converging in (nearly) every step.

mod common;

use pellet_geom::{Pellet, Resolution, ShapeSpec};
use pellet_io::{EnergyRecord, Frame};
use pellet_pack::{run_pack, Ending, LoadingScheme, RunSink, Stepper};

struct Discard;

impl RunSink for Discard {
    fn frame(&mut self, _: &Frame) -> Result<(), String> {
        Ok(())
    }
    fn energy(&mut self, _: &EnergyRecord) -> Result<(), String> {
        Ok(())
    }
}

fn settles(shape: ShapeSpec, name: &str) {
    let pellet = Pellet::build(shape, Resolution::default()).unwrap();
    let mut unsettled = Vec::new();
    for seed in 1..=6 {
        let config = common::pack_config(40.0, 40, |o| {
            o.scheme = Some(LoadingScheme::Batch);
            o.seed = Some(seed);
            o.max_time = Some(8.0);
            o.stepper = Some(Stepper::Velocity);
        });
        let s = run_pack(&config, &pellet, &mut Discard).unwrap();
        println!(
            "{name} seed {seed}: {:?} at {:.3} s, {:.2} points a pair, {:.1} % of loaded contacts warm started, {:.1} % of steps converged",
            s.ending,
            s.time_s,
            s.solver.contacts_per_pair(),
            100.0 * s.solver.warm_start_rate(),
            100.0 * s.solver.converged_rate()
        );
        if s.ending != Ending::Settled {
            unsettled.push(seed);
        } else {
            // A bed at rest: its loaded contacts keep their keys, and its solves converge.
            assert!(s.solver.warm_start_rate() >= 0.99, "{name} seed {seed}: {:?}", s.solver);
            assert!(s.solver.converged_rate() >= 0.99, "{name} seed {seed}: {:?}", s.solver);
        }
        assert!(s.max_penetration_m < 1e-2 * 0.01, "{name} seed {seed}: penetration {}", s.max_penetration_m);
    }
    assert!(unsettled.is_empty(), "{name}: seeds {unsettled:?} did not settle within 8 s");
}

#[test]
fn forty_cylinders_settle() {
    settles(ShapeSpec::Cylinder { diameter_mm: 10.0, height_mm: 10.0 }, "40 cylinders");
}

#[test]
fn forty_rings_settle() {
    settles(ShapeSpec::Ring { outer_diameter_mm: 10.0, inner_diameter_mm: 6.0, height_mm: 10.0 }, "40 rings");
}
