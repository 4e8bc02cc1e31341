//! T3 (two spheres), T4 (oblique ball–floor impact with friction), T9 (Newton's cradle).

mod common;
use common::*;
use pellet_sim::{AccelerationParams, Container, EngineParams, FrictionClamp, Pipeline, Stepper, Vec3};

fn head_on(e: f64, stepper: Stepper) {
    let (r1, r2) = (0.005, 0.007);
    let params = EngineParams { stepper, ..zero_gravity() };
    let (mut w, t1) = sphere_world(Container::tube(0.3).unwrap(), r1, material(e, 0.0), wall(e, 0.0), params);
    let t2 = w.register_type(pellet_sim::BodyType::solid_sphere(r2).unwrap()).unwrap();
    let (v1, v2) = (1.0, -0.5);
    let a = add(&mut w, t1, Vec3::new(-0.02, 0.0, 0.1), Vec3::new(v1, 0.0, 0.0), Vec3::zeros());
    let b = add(&mut w, t2, Vec3::new(0.02, 0.0, 0.1), Vec3::new(v2, 0.0, 0.0), Vec3::zeros());
    let (m1, m2) = (w.body(a).unwrap().mass, w.body(b).unwrap().mass);
    let p0 = m1 * v1 + m2 * v2;
    let ke0 = w.kinetic_energy();
    let mut p = Pipeline::new();
    let pen = run(&mut w, &mut p, 0.005, 10);
    let w1 = ((m1 - e * m2) * v1 + (1.0 + e) * m2 * v2) / (m1 + m2);
    let w2 = ((m2 - e * m1) * v2 + (1.0 + e) * m1 * v1) / (m1 + m2);
    let (u1, u2) = (vel(&w, a), vel(&w, b));
    eprintln!("T3 e={e}: v1' {:.15} (want {w1:.15}), v2' {:.15} (want {w2:.15})", u1.x, u2.x);
    assert!((u1.x - w1).abs() <= 1e-12 * v1.abs(), "v1' {} vs {w1}", u1.x);
    assert!((u2.x - w2).abs() <= 1e-12 * v1.abs(), "v2' {} vs {w2}", u2.x);
    assert!(rel(m1 * u1.x + m2 * u2.x, p0) <= 1e-12);
    if e == 1.0 {
        assert!(rel(w.kinetic_energy(), ke0) <= 1e-12);
    }
    assert_eq!(omega(&w, a), Vec3::zeros());
    assert_eq!(omega(&w, b), Vec3::zeros());
    assert!(pen < 0.01 * 2.0 * r2, "penetration {pen}");
}

#[test]
fn t3_head_on_elastic() {
    head_on(1.0, Stepper::Acceleration);
}

#[test]
fn t3_head_on_elastic_velocity_stepper() {
    head_on(1.0, Stepper::Velocity);
}

#[test]
fn t3_head_on_inelastic_velocity_stepper() {
    head_on(0.7, Stepper::Velocity);
}

#[test]
fn t3_head_on_inelastic() {
    head_on(0.7, Stepper::Acceleration);
}

#[test]
fn t3_oblique_equal_masses_leave_perpendicular() {
    let r = 0.005;
    let (mut w, t) = sphere_world(Container::tube(0.3).unwrap(), r, material(1.0, 0.0), wall(1.0, 0.0), zero_gravity());
    let a = add(&mut w, t, Vec3::new(-0.03, 0.004, 0.1), Vec3::new(1.0, 0.0, 0.0), Vec3::zeros());
    let b = add(&mut w, t, Vec3::new(0.0, 0.0, 0.1), Vec3::zeros(), Vec3::zeros());
    let mut p = Pipeline::new();
    run(&mut w, &mut p, 0.01, 5);
    let (u1, u2) = (vel(&w, a), vel(&w, b));
    assert!(u2.norm() > 0.1, "target did not move");
    let angle = u1.angle(&u2);
    eprintln!("T3 oblique: angle {:.12} rad", angle);
    assert!((angle - std::f64::consts::FRAC_PI_2).abs() <= 1e-9);
    // Unchanged to round-off (the lever arm is parallel to n up to the last bit).
    assert!(omega(&w, a).norm() <= 1e-12 && omega(&w, b).norm() <= 1e-12);
}

/// Returns (v_n⁺, v_t⁺, ω⁺R, KE⁺/KE⁻).
fn oblique_floor(mu: f64, clamp: FrictionClamp) -> (f64, f64, f64, f64) {
    let r = 0.005;
    let params = EngineParams {
        acceleration: AccelerationParams { friction_clamp: clamp, ..AccelerationParams::paper() },
        ..zero_gravity()
    };
    let (mut w, t) = sphere_world(Container::tube(0.3).unwrap(), r, material(0.5, mu), wall(0.5, mu), params);
    let id = add(&mut w, t, Vec3::new(0.0, 0.0, r + 0.002), Vec3::new(1.0, 0.0, -1.0), Vec3::zeros());
    let ke0 = w.kinetic_energy();
    let mut p = Pipeline::new();
    run(&mut w, &mut p, 0.001, 10);
    let (v, om) = (vel(&w, id), omega(&w, id));
    // Rolling in +x needs ω_y > 0 (contact point velocity v_x − R ω_y).
    (v.z, v.x, om.y * r, w.kinetic_energy() / ke0)
}

#[test]
fn t4_oblique_impact_with_friction() {
    let cases = [
        (0.3, FrictionClamp::Stick, 5.0 / 7.0, 5.0 / 7.0),
        (0.3, FrictionClamp::Zero, 1.0, 0.0),
        (0.1, FrictionClamp::Stick, 0.85, 0.375),
        (0.1, FrictionClamp::Zero, 0.85, 0.375),
    ];
    for (mu, clamp, vt, wr) in cases {
        let (vn, got_vt, got_wr, ke) = oblique_floor(mu, clamp);
        eprintln!("T4 mu={mu} {clamp:?}: vn {vn:.12} vt {got_vt:.12} wR {got_wr:.12} KE ratio {ke:.6}");
        assert!((vn - 0.5).abs() <= 1e-9, "vn {vn}");
        assert!((got_vt - vt).abs() <= 1e-9, "mu {mu} {clamp:?}: vt {got_vt} want {vt}");
        assert!((got_wr - wr).abs() <= 1e-9, "mu {mu} {clamp:?}: wR {got_wr} want {wr}");
        assert!(ke <= 1.0);
    }
}

/// Five touching spheres on the x axis; returns final velocities and impulses applied.
fn cradle(e: f64, v_in: [f64; 5], eps_p: f64) -> ([f64; 5], u64, f64, f64) {
    let r = 0.005;
    let params = EngineParams { eps_p, ..zero_gravity() };
    let (mut w, t) = sphere_world(Container::tube(0.3).unwrap(), r, material(e, 0.0), wall(e, 0.0), params);
    let ids: Vec<_> = (0..5)
        .map(|i| {
            add(&mut w, t, Vec3::new(-0.02 + 2.0 * r * i as f64, 0.0, 0.1), Vec3::new(v_in[i], 0.0, 0.0), Vec3::zeros())
        })
        .collect();
    let ke0 = w.kinetic_energy();
    let mut p = Pipeline::new();
    let rep = w.step(1e-6, &mut p).unwrap();
    let mut out = [0.0; 5];
    for (i, id) in ids.iter().enumerate() {
        out[i] = vel(&w, *id).x;
    }
    let mom: f64 = out.iter().sum();
    (out, rep.impulses, mom, w.kinetic_energy() / ke0)
}

#[test]
fn t9_newtons_cradle() {
    let (v, n, ..) = cradle(1.0, [1.0, 0.0, 0.0, 0.0, 0.0], 5e-3);
    eprintln!("T9 one ball: {v:?}, {n} impulses");
    let want = [0.0, 0.0, 0.0, 0.0, 1.0];
    for i in 0..5 {
        assert!((v[i] - want[i]).abs() <= 1e-12, "{v:?}");
    }
    assert_eq!(n, 4);
    let (v, n, ..) = cradle(1.0, [1.0, 1.0, 0.0, 0.0, 0.0], 5e-3);
    eprintln!("T9 two balls: {v:?}, {n} impulses");
    let want = [0.0, 0.0, 0.0, 1.0, 1.0];
    for i in 0..5 {
        assert!((v[i] - want[i]).abs() <= 1e-12, "{v:?}");
    }
}

/// The velocity-level stepper resolves the cradle ball by ball as well: its collision passes
/// come before the step's one solve (`docs/engine.md`, "Collisions before the step's solve").
/// Resolved in that one solve, all five balls moved.
#[test]
fn t9_newtons_cradle_velocity_stepper() {
    for (v_in, want) in
        [([1.0, 0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0, 1.0]), ([1.0, 1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0, 1.0])]
    {
        let r = 0.005;
        let params = EngineParams { stepper: Stepper::Velocity, ..zero_gravity() };
        let (mut w, t) = sphere_world(Container::tube(0.3).unwrap(), r, material(1.0, 0.0), wall(1.0, 0.0), params);
        // Touching, or overlapping by a rounding error: each contact collides at once.
        let ids: Vec<_> = (0..5)
            .map(|i| {
                add(
                    &mut w,
                    t,
                    Vec3::new(0.02 * i as f64 / 2.0 - 1e-12 * i as f64, 0.0, 0.1),
                    Vec3::new(v_in[i], 0.0, 0.0),
                    Vec3::zeros(),
                )
            })
            .collect();
        let ke0 = w.kinetic_energy();
        let mut p = Pipeline::new();
        run(&mut w, &mut p, 1e-5, 3);
        let v: Vec<f64> = ids.iter().map(|id| vel(&w, *id).x).collect();
        eprintln!("T9 velocity stepper {v_in:?}: {v:?}");
        for i in 0..5 {
            assert!((v[i] - want[i]).abs() <= 1e-12, "{v:?}");
        }
        assert!(rel(w.kinetic_energy(), ke0) <= 1e-12);
    }
}

#[test]
fn t9_cradle_inelastic_regression() {
    let (v, n, mom, ke) = cradle(0.9, [1.0, 0.0, 0.0, 0.0, 0.0], 1e-9);
    eprintln!("T9 e=0.9: {v:?}, {n} impulses, momentum {mom}, KE ratio {ke}");
    let want = [0.043525, 0.045373, 0.047297, 0.049299, 0.814506];
    for i in 0..5 {
        assert!((v[i] - want[i]).abs() <= 1e-6, "{v:?}");
    }
    assert!((mom - 1.0).abs() <= 1e-12);
    assert!((ke - 0.67204).abs() <= 1e-5, "KE ratio {ke}");
    assert_eq!(n, 10);
}

#[test]
fn no_tunnelling_in_big_steps() {
    // 5 m/s moves 125 mm per 1/40 s big step, far more than the 10 mm sphere: the swept broad
    // phase must still find the floor and the other sphere.
    let r = 0.005;
    let (mut w, t) = sphere_world(Container::tube(0.3).unwrap(), r, material(0.5, 0.0), wall(0.5, 0.0), zero_gravity());
    let a = add(&mut w, t, Vec3::new(0.0, 0.0, 0.2), Vec3::new(0.0, 0.0, -5.0), Vec3::zeros());
    let b = add(&mut w, t, Vec3::new(-0.12, 0.05, 0.1), Vec3::new(5.0, 0.0, 0.0), Vec3::zeros());
    let c = add(&mut w, t, Vec3::new(0.12, 0.05, 0.1), Vec3::new(-5.0, 0.0, 0.0), Vec3::zeros());
    let mut p = Pipeline::new();
    // After two big steps: the pair met at t ≈ 0.023 s, the falling sphere hit the floor at
    // t ≈ 0.039 s, and nobody has reached the tube wall yet.
    let pen = run(&mut w, &mut p, 1.0 / 40.0, 2);
    assert!(vel(&w, a).z > 0.0, "sphere went through the floor");
    assert!(pos(&w, a).z > r * 0.99);
    assert!(vel(&w, b).x < 0.0 && vel(&w, c).x > 0.0, "spheres passed through each other");
    // Zero gravity, head-on impacts with e = 0.5: the exact outgoing speeds are 2.5 m/s.
    assert!((vel(&w, a).z - 2.5).abs() <= 1e-9);
    assert!((vel(&w, b).x + 2.5).abs() <= 1e-9 && (vel(&w, c).x - 2.5).abs() <= 1e-9);
    assert!(pen < 0.01 * 2.0 * r, "penetration {pen}");
}

#[test]
fn final_e0_solve_after_the_pass_cap() {
    // With one pass allowed, the cradle's momentum cannot travel ball by ball: the final e = 0
    // solve makes balls 2..5 leave together, conserving momentum, and nothing approaches after.
    let r = 0.005;
    let params = EngineParams {
        acceleration: AccelerationParams { collision_pass_cap: 1, ..AccelerationParams::paper() },
        ..zero_gravity()
    };
    let (mut w, t) = sphere_world(Container::tube(0.3).unwrap(), r, material(1.0, 0.0), wall(1.0, 0.0), params);
    let ids: Vec<_> = (0..5)
        .map(|i| {
            let v = if i == 0 { 1.0 } else { 0.0 };
            add(&mut w, t, Vec3::new(-0.02 + 2.0 * r * i as f64, 0.0, 0.1), Vec3::new(v, 0.0, 0.0), Vec3::zeros())
        })
        .collect();
    let mut p = Pipeline::new();
    let rep = w.step(1e-6, &mut p).unwrap();
    let v: Vec<f64> = ids.iter().map(|id| vel(&w, *id).x).collect();
    eprintln!("final e=0 solve: {v:?}, final solves {}", rep.final_solves);
    assert_eq!(rep.final_solves, 1);
    let want = [0.0, 0.25, 0.25, 0.25, 0.25];
    for i in 0..5 {
        assert!((v[i] - want[i]).abs() <= 1e-12, "{v:?}");
    }
}

#[test]
fn rewind_and_halve_keeps_penetration_below_the_bound() {
    // Impacts are resolved before touching, so to provoke a rewind we make a pair approach
    // inside a (deliberately wide) resting band: nothing stops it, and a full substep would push
    // it 1e-4 m deep. Rewind-and-halve must keep the penetration under pen_max = 1e-3 d.
    let r = 0.005;
    let params = EngineParams {
        eps_p: 0.1,
        max_penetration_factor: 1e-3,
        acceleration: AccelerationParams { dt_cap: 1e-2, ..AccelerationParams::paper() },
        ..zero_gravity()
    };
    let (mut w, t) = sphere_world(Container::tube(0.3).unwrap(), r, material(1.0, 0.0), wall(1.0, 0.0), params);
    let a = add(&mut w, t, Vec3::new(-2.0 * r, 0.0, 0.1), Vec3::new(0.08, 0.0, 0.0), Vec3::zeros());
    add(&mut w, t, Vec3::new(0.0, 0.0, 0.1), Vec3::zeros(), Vec3::zeros());
    let mut p = Pipeline::new();
    let (mut rewinds, mut pen) = (0, 0.0f64);
    for _ in 0..20 {
        let rep = w.step(1e-3, &mut p).unwrap();
        rewinds += rep.rewinds;
        pen = pen.max(rep.max_penetration);
    }
    eprintln!("rewind test: {rewinds} rewinds, max penetration {pen:.2e} m (bound {:.1e})", 1e-3 * 2.0 * r);
    assert!(rewinds > 0);
    assert!(pen <= 1e-3 * 2.0 * r);
    // Resting contact with b ≥ 0: no force, the velocity is untouched.
    assert_eq!(vel(&w, a).x, 0.08);
}
