//! T7 (rolling versus slipping) and a sphere on an incline, in paper mode and with static
//! friction on.

mod common;
use common::*;
use pellet_sim::{AccelerationParams, Container, EngineParams, FrictionClamp, Pipeline, Stepper, Vec3};

struct Rolling {
    t_r: f64,
    v_final: f64,
    slip_distance: f64,
    ke_loss: f64,
    max_pen: f64,
}

fn roll(params: EngineParams) -> Rolling {
    let r = 0.005;
    let mu = 0.3;
    let eps_f = params.acceleration.eps_f;
    let (mut w, t) = sphere_world(Container::tube(0.6).unwrap(), r, material(0.5, mu), wall(0.5, mu), params);
    let id = add(&mut w, t, Vec3::new(-0.1, 0.0, r), Vec3::new(1.0, 0.0, 0.0), Vec3::zeros());
    let ke0 = w.kinetic_energy();
    let mut p = Pipeline::new();
    let dt = 1e-4;
    let mut t_r = None;
    let mut slip_distance = 0.0;
    let x0 = pos(&w, id).x;
    let mut max_pen: f64 = 0.0;
    let slip = |w: &pellet_sim::World| vel(w, id).x - r * omega(w, id).y;
    let mut s_prev = slip(&w);
    while w.time() < 0.2 {
        max_pen = max_pen.max(w.step(dt, &mut p).unwrap().max_penetration);
        let s = slip(&w);
        if t_r.is_none() && s <= eps_f {
            // Interpolate the crossing of the εf floor within the last step.
            let frac = (s_prev - eps_f) / (s_prev - s);
            t_r = Some(w.time() - dt + frac * dt);
            // Distance the centre travelled while slipping.
            slip_distance = pos(&w, id).x - x0 - (1.0 - frac) * dt * vel(&w, id).x;
        }
        s_prev = s;
    }
    Rolling {
        t_r: t_r.expect("slipping never ended"),
        v_final: vel(&w, id).x,
        slip_distance,
        ke_loss: 1.0 - w.kinetic_energy() / ke0,
        max_pen,
    }
}

fn check_rolling(label: &str, params: EngineParams) {
    let g = 9.81;
    let (v0, mu) = (1.0, 0.3);
    let eps_f = params.acceleration.eps_f;
    let got = roll(params);
    // Slipping stops when the slip reaches εf (paper mode has no friction below it).
    let t_r = 2.0 * v0 / (7.0 * mu * g);
    let t_eps = (v0 - eps_f) / (3.5 * mu * g);
    eprintln!(
        "T7 {label}: t_r {:.6} s (analytic {t_r:.6}, at slip εf {t_eps:.6}), v_final {:.6} (5/7 = {:.6}), slip distance {:.6} m (analytic {:.6}), KE loss {:.5} (2/7 = {:.5}), max pen {:.2e}",
        got.t_r, got.v_final, 5.0 / 7.0, got.slip_distance, 12.0 * v0 * v0 / (49.0 * mu * g), got.ke_loss, 2.0 / 7.0, got.max_pen
    );
    assert!(rel(got.t_r, t_r) <= 0.01);
    assert!(rel(got.v_final, 5.0 / 7.0) <= 0.01);
    assert!(rel(got.slip_distance, 12.0 * v0 * v0 / (49.0 * mu * g)) <= 0.01);
    assert!(rel(got.ke_loss, 2.0 / 7.0) <= 0.01);
    assert!(got.max_pen < 1e-2 * 0.01);
}

#[test]
fn t7_rolling_paper_mode() {
    check_rolling("paper", EngineParams::paper());
}

#[test]
fn t7_rolling_paper_mode_stick_clamp() {
    check_rolling(
        "paper+stick",
        EngineParams {
            acceleration: AccelerationParams { friction_clamp: FrictionClamp::Stick, ..AccelerationParams::paper() },
            ..EngineParams::paper()
        },
    );
}

/// The velocity-level stepper: Coulomb's cone in the impulse solve, so the slip ends at zero,
/// not at εf; the checks are the same (εf's share of t_r is 0.3 %).
#[test]
fn t7_rolling_velocity_stepper() {
    check_rolling("velocity", EngineParams { stepper: Stepper::Velocity, ..EngineParams::paper() });
}

#[test]
fn t7_rolling_static_friction() {
    check_rolling("static", recommended());
}

/// Sphere released from rest on a 30° incline; returns (acceleration along the slope over
/// 0.2 s, final slip speed, max penetration).
fn incline(params: EngineParams, mu: f64) -> (f64, f64, f64) {
    let r = 0.005;
    let th = 30f64.to_radians();
    let n = Vec3::new(th.sin(), 0.0, th.cos());
    let p0 = Vec3::new(-0.05, 0.0, 0.1);
    let c = Container::tube(0.4).unwrap().with_plane(n, n.dot(&p0)).unwrap();
    let (mut w, t) = sphere_world(c, r, material(0.5, mu), wall(0.5, mu), params);
    let id = add(&mut w, t, p0 + n * r, Vec3::zeros(), Vec3::zeros());
    let down = Vec3::new(th.cos(), 0.0, -th.sin());
    let x0 = pos(&w, id);
    let mut p = Pipeline::new();
    let pen = run(&mut w, &mut p, 1e-3, 200);
    let s = (pos(&w, id) - x0).dot(&down);
    let a = 2.0 * s / (w.time() * w.time());
    let cp = pos(&w, id) - n * r;
    let slip = (w.body(id).unwrap().point_velocity(&cp)).norm();
    (a, slip, pen)
}

#[test]
fn incline_sphere_rolls_or_slides() {
    let g = 9.81;
    let th = 30f64.to_radians();
    let (a_rough, slip_rough, pen1) = incline(recommended(), 0.3);
    let (a_paper, slip_paper, pen2) = incline(EngineParams::paper(), 0.3);
    let (a_smooth, slip_smooth, pen3) = incline(EngineParams::paper(), 0.0);
    eprintln!(
        "incline: static friction a {a_rough:.5} slip {slip_rough:.2e}; paper a {a_paper:.5} slip {slip_paper:.2e}; frictionless a {a_smooth:.5} slip {slip_smooth:.3}; (5/7 g sin = {:.5}, g sin = {:.5})",
        5.0 / 7.0 * g * th.sin(),
        g * th.sin()
    );
    // Static friction: rolling without slipping.
    assert!(rel(a_rough, 5.0 / 7.0 * g * th.sin()) <= 0.01);
    assert!(slip_rough <= 1e-6);
    // Paper mode: frictionless below εf, Coulomb above: the slip hovers near εf, so the ball
    // nearly rolls.
    assert!(rel(a_paper, 5.0 / 7.0 * g * th.sin()) <= 0.01);
    assert!(slip_paper <= 2.0 * 5e-3);
    // No friction at all: slides at g sin θ.
    assert!(rel(a_smooth, g * th.sin()) <= 1e-3);
    assert!(pen1.max(pen2).max(pen3) < 1e-2 * 0.01);
}
