//! T5: bounce sequence of a sphere dropped on the floor.

mod common;
use common::*;
use pellet_sim::{AccelerationParams, Container, EngineParams, Pipeline, Stepper, Vec3};

#[test]
fn t5_bounce_heights_and_count() {
    bounce(Stepper::Acceleration);
}

/// The velocity-level stepper, its steps no longer than the force-level stepper's cap here.
#[test]
fn t5_bounce_heights_and_count_velocity_stepper() {
    bounce(Stepper::Velocity);
}

fn bounce(stepper: Stepper) {
    let r = 0.005;
    let e: f64 = 0.8;
    let h0 = 0.1;
    let dt = 1e-4;
    let params = EngineParams {
        stepper,
        acceleration: AccelerationParams { dt_cap: dt, ..AccelerationParams::paper() },
        ..EngineParams::paper()
    };
    let eps_p = params.eps_p;
    let (mut w, t) = sphere_world(Container::tube(0.05).unwrap(), r, material(e, 0.0), wall(e, 0.0), params);
    let id = add(&mut w, t, Vec3::new(0.0, 0.0, r + h0), Vec3::zeros(), Vec3::zeros());
    let mut p = Pipeline::new();
    let g = 9.81;
    let v0 = (2.0 * g * h0).sqrt();
    assert!((v0 - 1.40071).abs() < 1e-5);
    let mut apexes = Vec::new();
    let mut impacts = 0u64;
    let mut last_impact_time = 0.0;
    let mut prev_vz = 0.0;
    let mut max_pen: f64 = 0.0;
    while w.time() < 2.0 {
        let rep = w.step(dt, &mut p).unwrap();
        max_pen = max_pen.max(rep.max_penetration);
        if rep.impulses > 0 {
            impacts += rep.impulses;
            last_impact_time = w.time();
        }
        let b = w.body(id).unwrap();
        let vz = b.velocity().z;
        if prev_vz > 0.0 && vz <= 0.0 {
            // Parabolic apex from the current state: z + vz²/(2g) is exact in free flight.
            apexes.push(b.position.z - r + vz * vz / (2.0 * g));
        }
        prev_vz = vz;
    }
    let delta_c = 1e-3 * 2.0 * r;
    for n in 1..=5 {
        let want = e.powi(2 * n as i32) * h0;
        let vn = e.powi(n as i32) * v0;
        let tol = 2.0 * g * dt / vn + 2.0 * delta_c / want + 1e-3;
        let got = apexes[n - 1];
        eprintln!("T5 h_{n}: {got:.6} m (want {want:.6}, rel err {:.2e}, tol {tol:.2e})", rel(got, want));
        assert!(rel(got, want) <= tol);
    }
    let n_star = ((eps_p / v0).ln() / e.ln()).ceil() as u64;
    assert_eq!(n_star, 26);
    let t0 = (2.0 * h0 / g).sqrt();
    // Time of the n*-th impact: t0 + 2 t0 Σ_{k=1}^{n*-1} e^k.
    let t_last = t0 + 2.0 * t0 * e * (1.0 - e.powi(n_star as i32 - 1)) / (1.0 - e);
    eprintln!(
        "T5 impacts {impacts} (n* = {n_star}); last impact at {last_impact_time:.5} s (want {t_last:.5}); Zeno limit {:.5}; max pen {max_pen:.2e} m",
        t0 * (1.0 + e) / (1.0 - e)
    );
    assert!(impacts.abs_diff(n_star) <= 1, "impacts {impacts}");
    assert!(rel(last_impact_time, t_last) < 5e-3);
    // At rest on the floor afterwards.
    let b = w.body(id).unwrap();
    assert!(b.velocity().norm() <= eps_p);
    assert!((b.position.z - r).abs() <= 1e-2 * 2.0 * r);
    assert!(max_pen < 1e-2 * 2.0 * r);
}
