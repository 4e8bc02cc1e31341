//! Cylinders in motion: T6, a cylinder sliding down a 30° incline, and T11, a cylinder tipping
//! over a rim.

mod common;
use common::*;
use pellet_sim::{BodyType, Container, EngineParams, Quat, Stepper, Vec3};

const G: f64 = 9.81;

/// T6: a 10 mm cylinder on its face on a 30° incline; returns its acceleration down the slope
/// between 0.05 s and 0.25 s after release from rest, and its speed at 1 s.
fn incline(params: EngineParams, mu: f64) -> (f64, f64) {
    let th = 30f64.to_radians();
    let n = Vec3::new(th.sin(), 0.0, th.cos());
    let p0 = Vec3::new(0.0, 0.0, 0.2);
    let container = Container::tube(0.6).unwrap().with_plane(n, n.dot(&p0)).unwrap();
    let ty = BodyType::solid_cylinder(0.005, 0.005).unwrap();
    let (mut w, t) = shape_world(container, ty, material(0.5, mu), wall(0.5, mu), params);
    // On the plane 0.1 m uphill of p0, axis along the plane normal.
    let down = Vec3::new(th.cos(), 0.0, -th.sin());
    let x = p0 - down * 0.1 + n * 0.005;
    let q = Quat::rotation_between(&Vec3::z(), &n).unwrap();
    let id = add_q(&mut w, t, x, q, Vec3::zeros(), Vec3::zeros());
    let mut p = pellet_sim::Pipeline::new();
    let mut pen = 0.0f64;
    let mut v_at = |w: &mut pellet_sim::World, steps: usize| {
        pen = pen.max(run(w, &mut p, 1.0 / 40.0, steps));
        vel(w, id).dot(&down)
    };
    let v1 = v_at(&mut w, 2);
    let v2 = v_at(&mut w, 8);
    let v3 = v_at(&mut w, 30);
    let a = (v2 - v1) / 0.2;
    let off_plane = vel(&w, id).dot(&n);
    println!(
        "T6 mu={mu} static={}: a {a:.5} m/s², |v(1 s)| {v3:.3e}, v_n {off_plane:.1e}, max pen {pen:.2e} m",
        w.params().acceleration.static_friction
    );
    assert!(pen < 1e-4, "penetration {pen}");
    (a, v3.abs())
}

#[test]
fn t6_block_on_an_incline() {
    let th = 30f64.to_radians();
    let sliding = G * (th.sin() - 0.3 * th.cos());
    // Frictionless: g sinθ.
    let (a, _) = incline(EngineParams::paper(), 0.0);
    assert!(rel(a, G * th.sin()) <= 1e-2, "frictionless a {a}");
    // Paper mode: dynamic friction at the sliding resting contacts.
    let (a, _) = incline(EngineParams::paper(), 0.3);
    assert!(rel(a, sliding) <= 1e-2, "paper mu 0.3 a {a} (expected {sliding})");
    // Static friction switch: same sliding value, and no motion for μ = 0.7 > tan 30°.
    let (a, _) = incline(recommended(), 0.3);
    assert!(rel(a, sliding) <= 1e-2, "static-friction mode mu 0.3 a {a}");
    let (_, v) = incline(recommended(), 0.7);
    assert!(v < 1e-6, "mu 0.7 must stick: v {v}");
}

/// T6 with the velocity-level stepper, whose friction is the cone (static and sliding):
/// frictionless sliding and sticking at μ = 0.7 > tan 30°. Sliding at μ = 0.3 is not checked
/// here: this stepper gives 2.42 m/s² against 2.356 (2.6 % fast; `docs/engine.md`, "Known
/// gaps of the velocity-level stepper").
#[test]
fn t6_block_on_an_incline_velocity_stepper() {
    let th = 30f64.to_radians();
    let velocity = EngineParams { stepper: Stepper::Velocity, ..EngineParams::paper() };
    let (a, _) = incline(velocity.clone(), 0.0);
    assert!(rel(a, G * th.sin()) <= 1e-2, "frictionless a {a}");
    let (_, v) = incline(velocity, 0.7);
    assert!(v < 1e-6, "mu 0.7 must stick: v {v}");
}

/// T11, frictionless pivot (paper mode, μ = 0): released from rest at tilt β₀ on one rim point.
/// Returns (time to land, ω there, CoM vertical speed there, max |x_CoM|) or None if it fell back.
fn tip(beta0_deg: f64) -> Option<(f64, f64, f64, f64)> {
    let (r, h) = (0.005, 0.005);
    let ty = BodyType::solid_cylinder(r, h).unwrap();
    let (mut w, t) =
        shape_world(Container::tube(0.1).unwrap(), ty, material(0.5, 0.0), wall(0.5, 0.0), EngineParams::paper());
    let b0 = beta0_deg.to_radians();
    let z0 = h * b0.cos() + r * b0.sin();
    let q = Quat::from_axis_angle(&Vec3::y_axis(), b0);
    let id = add_q(&mut w, t, Vec3::new(0.0, 0.0, z0), q, Vec3::zeros(), Vec3::zeros());
    let mut p = pellet_sim::Pipeline::new();
    let dt = 2e-4;
    let mut prev: Option<(f64, f64, f64, f64)> = None;
    let mut xmax = 0.0f64;
    let mut beta_max = 0.0f64;
    for _ in 0..2500 {
        w.step(dt, &mut p).unwrap();
        let b = w.body(id).unwrap();
        let axis = b.orientation * Vec3::z();
        let beta = axis.z.clamp(-1.0, 1.0).acos();
        let (om, vz) = (b.angular_velocity().y, b.velocity().z);
        xmax = xmax.max(b.position.x.abs());
        beta_max = beta_max.max(beta);
        let now = (w.time(), beta, om, vz);
        if beta >= 89f64.to_radians() {
            // Extrapolate to β = 90° with the last two samples.
            let (t0, _, om0, vz0) = prev.unwrap();
            let s = (std::f64::consts::FRAC_PI_2 - beta) / om;
            let alpha = (om - om0) / (now.0 - t0);
            let az = (vz - vz0) / (now.0 - t0);
            return Some((now.0 + s, om + alpha * s, vz + az * s, xmax));
        }
        prev = Some(now);
    }
    println!("T11 β₀ = {beta0_deg}°: fell back, largest tilt {:.3}°", beta_max.to_degrees());
    assert!(beta_max < (beta0_deg + 0.5).to_radians());
    None
}

#[test]
fn t11_cylinder_tipping_over_a_rim_frictionless() {
    // Reference values for a frictionless pivot: (β₀, time, ω, CoM vertical speed).
    for (b0, time, om, vz) in
        [(46.0, 71.41e-3, 32.03, 0.1602), (50.0, 48.24e-3, 31.83, 0.1592), (60.0, 32.65e-3, 30.12, 0.1506)]
    {
        let (t, w, v, x) = tip(b0).expect("must tip over");
        println!("T11 β₀ = {b0}°: time {:.2} ms (doc {:.2}), ω {w:.3} rad/s (doc {om}), CoM v_z {:.4} m/s (doc {vz}), |x_CoM| {x:.1e}", t * 1e3, time * 1e3, -v);
        assert!(rel(t, time) <= 1e-2, "time {t}");
        assert!(rel(w, om) <= 1e-2, "omega {w}");
        assert!(rel(-v, vz) <= 1e-2, "CoM speed {v}");
        // No friction: no horizontal force, the centre of mass falls vertically.
        assert!(x <= 1e-9, "CoM moved sideways by {x}");
    }
    assert!(tip(44.0).is_none(), "released at 44° it must fall back onto its face");
}
