//! T1 (free fall) and T2 (torque-free rotation), plus rotation sub-stepping in
//! free flight.

mod common;
use common::*;
use pellet_sim::dynamics::integrator::midpoint_step;
use pellet_sim::{Body, BodyType, Container, EngineParams, Mat3, Pipeline, Quat, ShapeDesc, TypeId, Vec3};

#[test]
fn t1_free_fall_is_exact() {
    free_fall(EngineParams::paper());
}

#[test]
fn t1_free_fall_is_exact_velocity_stepper() {
    free_fall(EngineParams { stepper: pellet_sim::Stepper::Velocity, ..EngineParams::paper() });
}

fn free_fall(params: EngineParams) {
    let (mut w, t) = sphere_world(Container::tube(1.0).unwrap(), 0.005, material(0.5, 0.3), wall(0.5, 0.3), params);
    let x0 = Vec3::new(0.01, -0.02, 10.0);
    let v0 = Vec3::new(0.3, -0.2, 1.0);
    let id = add(&mut w, t, x0, v0, Vec3::zeros());
    let mut p = Pipeline::new();
    for _ in 0..40 {
        w.step(1.0 / 40.0, &mut p).unwrap();
    }
    let tt = w.time();
    assert!((tt - 1.0).abs() < 1e-12);
    let g = Vec3::new(0.0, 0.0, -9.81);
    let want = x0 + v0 * tt + g * (0.5 * tt * tt);
    let got = pos(&w, id);
    for k in 0..3 {
        assert!(rel(got[k], want[k]) < 1e-12, "axis {k}: {} vs {}", got[k], want[k]);
    }
    let vw = v0 + g * tt;
    assert!((vel(&w, id) - vw).norm() < 1e-12 * vw.norm());
    assert_eq!(w.body(id).unwrap().orientation, Quat::identity());
}

fn asym_body(ib: Mat3, omega0: Vec3) -> Body {
    Body {
        type_id: TypeId(0),
        position: Vec3::zeros(),
        orientation: Quat::identity(),
        linear_momentum: Vec3::zeros(),
        angular_momentum: ib * omega0,
        mass: 1.0,
        inertia_body: ib,
        inv_inertia_body: ib.try_inverse().unwrap(),
        bounding_radius: 1.0,
    }
}

/// Runs torque-free for `t_end` at `dt`; returns (max |ΔE/E|, max |ΔL|/|L|, body).
fn spin(ib: Mat3, omega0: Vec3, dt: f64, t_end: f64) -> (f64, f64, Body) {
    let mut b = asym_body(ib, omega0);
    let e0 = b.kinetic_rotational();
    let l0 = b.angular_momentum;
    let n = (t_end / dt).round() as usize;
    let (mut de, mut dl) = (0.0f64, 0.0f64);
    for _ in 0..n {
        midpoint_step(&mut b, &Vec3::zeros(), &Vec3::zeros(), dt);
        de = de.max(((b.kinetic_rotational() - e0) / e0).abs());
        dl = dl.max((b.angular_momentum - l0).norm() / l0.norm());
    }
    (de, dl, b)
}

#[test]
fn t2a_asymmetric_body_energy_drift_scales_as_dt_cubed() {
    let ib = Mat3::from_diagonal(&Vec3::new(1.0, 2.0, 3.0));
    let w0 = Vec3::new(3.0, 4.0, 5.0);
    let (de3, dl3, _) = spin(ib, w0, 1e-3, 10.0);
    let (de2, _, _) = spin(ib, w0, 1e-2, 10.0);
    eprintln!("T2a: dE/E {de3:.2e} at dt 1e-3, {de2:.2e} at dt 1e-2, ratio {:.0}, L drift {dl3:.1e}", de2 / de3);
    assert!(dl3 <= 1e-12, "L drift {dl3}");
    assert!(de3 <= 2e-6, "dE/E at 1e-3: {de3}");
    assert!(de3 > 1e-7, "drift unexpectedly small: {de3}");
    assert!(de2 > 5e-4 && de2 < 3e-3, "dE/E at 1e-2: {de2}");
    let ratio = de2 / de3;
    assert!(ratio > 500.0 && ratio < 2000.0, "ratio {ratio}");
}

#[test]
fn t2b_intermediate_axis_flips_with_small_energy_error() {
    let ib = Mat3::from_diagonal(&Vec3::new(1.0, 2.0, 3.0));
    let mut b = asym_body(ib, Vec3::new(0.01, 10.0, 0.01));
    let e0 = b.kinetic_rotational();
    let mut de = 0.0f64;
    let mut flipped = false;
    for _ in 0..10_000 {
        midpoint_step(&mut b, &Vec3::zeros(), &Vec3::zeros(), 1e-3);
        de = de.max(((b.kinetic_rotational() - e0) / e0).abs());
        // Body-frame ω_y changes sign when the body flips (Dzhanibekov effect).
        let wb = b.orientation.inverse() * b.angular_velocity();
        flipped |= wb.y < -5.0;
    }
    eprintln!("T2b: dE/E {de:.2e}, flipped {flipped}");
    assert!(de <= 1e-6, "dE/E {de}");
    assert!(flipped, "no flip observed");
}

#[test]
fn t2c_symmetric_top_precesses_at_the_analytic_rate() {
    let ib = Mat3::from_diagonal(&Vec3::new(1.0, 1.0, 2.0));
    let (_, _, b) = spin(ib, Vec3::new(1.0, 0.0, 10.0), 1e-3, 10.0);
    let l = Vec3::new(1.0, 0.0, 20.0);
    let big_omega = l.norm() / 1.0;
    assert!((big_omega - 20.025).abs() < 1e-3);
    let want = nalgebra::UnitQuaternion::from_scaled_axis(l.normalize() * big_omega * 10.0) * Vec3::z();
    let axis = b.orientation * Vec3::z();
    let err_deg = axis.angle(&want).to_degrees();
    assert!(err_deg <= 0.02, "axis error {err_deg}°");
    let cone = axis.angle(&l).to_degrees();
    let cone0 = (20.0 / l.norm()).acos().to_degrees();
    assert!((cone0 - 2.8624).abs() < 1e-4);
    eprintln!("T2c: axis error {err_deg:.4}°, cone {cone:.6}° (analytic {cone0:.6}°)");
    assert!((cone - cone0).abs() <= 2e-4, "cone drift {}", cone - cone0);
}

#[test]
fn free_flight_substeps_rotation() {
    // A sphere-shaped body with an asymmetric inertia tumbling at ~70 rad/s: a single midpoint
    // step per 1/40 s would wreck it; the rotation sub-steps keep |ΔE/E| tiny.
    let mut w =
        pellet_sim::World::new(Container::tube(1.0).unwrap(), material(0.5, 0.3), wall(0.5, 0.3), zero_gravity())
            .unwrap();
    let t = w
        .register_type(BodyType {
            shape: ShapeDesc::Sphere { radius: 0.01 },
            volume_m3: 1e-6,
            inertia_per_density_m5: Mat3::from_diagonal(&Vec3::new(1.0, 2.0, 3.0)) * 1e-11,
            bounding_radius_m: 0.01,
        })
        .unwrap();
    let id = add(&mut w, t, Vec3::new(0.0, 0.0, 0.5), Vec3::zeros(), Vec3::new(30.0, 40.0, 50.0));
    let e0 = w.kinetic_energy();
    let l0 = w.body(id).unwrap().angular_momentum;
    let mut p = Pipeline::new();
    let mut rot = 0;
    for _ in 0..40 {
        rot += w.step(1.0 / 40.0, &mut p).unwrap().rotation_substeps;
    }
    let de = ((w.kinetic_energy() - e0) / e0).abs();
    eprintln!("free-flight rotation: {rot} rotation substeps in 1 s, dE/E {de:.2e}");
    assert!(rot >= 40 * 175, "rotation substeps {rot}");
    assert!(de < 1e-5, "dE/E {de}");
    assert!((w.body(id).unwrap().angular_momentum - l0).norm() <= 1e-12 * l0.norm());
}
