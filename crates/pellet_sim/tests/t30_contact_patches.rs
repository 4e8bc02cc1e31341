//! A contact point stands for a small patch under the velocity-level stepper: a cylinder lying
//! across another, or a sphere on a sphere, spinning about their one contact's normal, slows at
//! the rate of the patch's Coulomb torque and comes to rest. With contact points that turn
//! freely, the spin is the rigid model's undamped mode and never ends (`docs/engine.md`,
//! "Contact points as small patches").

mod common;
use common::*;
use pellet_sim::{BodyType, Container, EngineParams, Quat, Stepper, Vec3, VelocityParams};
use std::f64::consts::{FRAC_PI_2, PI};

const R: f64 = 0.005;
const H: f64 = 0.005;
const MU: f64 = 0.3;
const SPIN: f64 = 0.5;

fn velocity_stepper(patch_radius: f64) -> EngineParams {
    EngineParams {
        stepper: Stepper::Velocity,
        velocity: VelocityParams { patch_radius, ..VelocityParams::default() },
        ..EngineParams::paper()
    }
}

/// Steps `w` to each of `times` (s) and returns `body`'s spin about the vertical there (rad/s).
fn spins_at(w: &mut pellet_sim::World, body: pellet_sim::BodyId, times: &[f64]) -> Vec<f64> {
    let mut p = pellet_sim::Pipeline::new();
    let mut spins = Vec::new();
    for &until in times {
        while w.time() < until - 1e-9 {
            w.step(1.0 / 200.0, &mut p).unwrap();
        }
        spins.push(omega(w, body).z);
    }
    spins
}

/// The upper cylinder's spin (rad/s) after each of `times` (s), and the two cylinders' relative
/// angular velocity (rad/s) at the end.
fn crossed(patch_radius: f64, times: &[f64]) -> (Vec<f64>, f64) {
    let params = velocity_stepper(patch_radius);
    let ty = BodyType::solid_cylinder(R, H).unwrap();
    let (mut w, t) = shape_world(Container::tube(0.05).unwrap(), ty, material(0.5, MU), wall(0.5, MU), params);
    // The lower one lies along x on the floor, the upper along y across its middle: one point.
    let along_x = Quat::from_axis_angle(&Vec3::y_axis(), FRAC_PI_2);
    let along_y = Quat::from_axis_angle(&Vec3::x_axis(), FRAC_PI_2);
    add_q(&mut w, t, Vec3::new(0.0, 0.0, R), along_x, Vec3::zeros(), Vec3::zeros());
    let top = add_q(&mut w, t, Vec3::new(0.0, 0.0, 3.0 * R), along_y, Vec3::zeros(), Vec3::new(0.0, 0.0, SPIN));
    let spins = spins_at(&mut w, top, times);
    let b = w.bodies();
    (spins, (b[1].angular_velocity() - b[0].angular_velocity()).norm())
}

/// Spin slows by α = (3π/16) μ a g / (I/m), I the upper cylinder's moment about the vertical
/// (a transverse axis: m(3r² + (2h)²)/12), a the patch radius (1e-3 of the 10 mm diameter):
/// 1.19 rad/s², so the 0.5 rad/s spin ends at 0.42 s. The lower cylinder's floor contact is a
/// line of two points, whose friction holds the reaction. At 1 s the two turn as one (a
/// speed of their pair rolling on that line, a free mode of a cylinder on a floor, may remain).
#[test]
fn a_spin_on_a_contact_point_ends_at_the_patch_torque_rate() {
    let a = VelocityParams::default().patch_radius * 2.0 * R;
    let i_over_m = (3.0 * R * R + 4.0 * H * H) / 12.0;
    let alpha = 3.0 * PI / 16.0 * MU * a * 9.81 / i_over_m;
    let (spins, turn) = crossed(VelocityParams::default().patch_radius, &[0.1, 0.3, 1.0]);
    println!(
        "spin at 0.1, 0.3, 1 s: {spins:?} rad/s (α = {alpha:.4} rad/s²); relative turning at 1 s {turn:.2e} rad/s"
    );
    for (t, got) in [(0.1, spins[0]), (0.3, spins[1])] {
        let want = SPIN - alpha * t;
        assert!((got - want).abs() <= 0.01 * alpha * t, "spin at {t} s: {got} rad/s against {want}");
    }
    assert!(turn <= 1e-6, "the contact still turns at 1 s: {turn} rad/s");
}

/// Without the patch the spin is the rigid model's free mode: nothing slows it.
#[test]
fn a_spin_on_a_free_contact_point_never_ends() {
    let (spins, _) = crossed(0.0, &[1.0]);
    println!("spin at 1 s without patches: {} rad/s", spins[0]);
    assert!((spins[0] - SPIN).abs() <= 1e-4 * SPIN, "spin at 1 s: {}", spins[0]);
}

/// The top sphere's spin (rad/s) after each of `times` (s), and the bottom sphere's angular
/// speed (rad/s) at the end, for two spheres stacked on the tube's axis, the top one spinning
/// about the vertical: their one contact lies on the spin axis, so friction alone never slows it.
fn stacked_spheres(patch_radius: f64, times: &[f64]) -> (Vec<f64>, f64) {
    let params = velocity_stepper(patch_radius);
    let (mut w, t) = sphere_world(Container::tube(0.05).unwrap(), R, material(0.5, MU), wall(0.5, MU), params);
    let bottom = add(&mut w, t, Vec3::new(0.0, 0.0, R), Vec3::zeros(), Vec3::zeros());
    let top = add(&mut w, t, Vec3::new(0.0, 0.0, 3.0 * R), Vec3::zeros(), Vec3::new(0.0, 0.0, SPIN));
    let spins = spins_at(&mut w, top, times);
    (spins, omega(&w, bottom).norm())
}

/// Between two spheres the patch resists spin (not rolling): a sphere held on a point of its
/// spin axis slows at α = (3π/16) μ a g / (2r²/5) = 1.73 rad/s², its 0.5 rad/s spin ending at
/// 0.29 s, while the floor's patch under twice the load holds the lower sphere still.
#[test]
fn a_sphere_spinning_on_a_sphere_stops_at_the_patch_torque_rate() {
    let a = VelocityParams::default().patch_radius * 2.0 * R;
    let alpha = 3.0 * PI / 16.0 * MU * a * 9.81 / (0.4 * R * R);
    let (spins, bottom) = stacked_spheres(VelocityParams::default().patch_radius, &[0.1, 0.2, 0.5]);
    println!("top spin at 0.1, 0.2, 0.5 s: {spins:?} rad/s (α = {alpha:.4} rad/s²); bottom {bottom:.2e} rad/s");
    for (t, got) in [(0.1, spins[0]), (0.2, spins[1])] {
        let want = SPIN - alpha * t;
        assert!((got - want).abs() <= 0.01 * alpha * t, "spin at {t} s: {got} rad/s against {want}");
    }
    assert!(spins[2].abs() <= 1e-6, "the top sphere still spins at 0.5 s: {} rad/s", spins[2]);
    assert!(bottom <= 1e-6, "the bottom sphere turns: {bottom} rad/s");
}

/// Without the patch nothing slows that spin.
#[test]
fn a_sphere_spinning_on_a_free_contact_point_never_stops() {
    let (spins, _) = stacked_spheres(0.0, &[0.5]);
    assert!((spins[0] - SPIN).abs() <= 1e-4 * SPIN, "spin at 0.5 s: {}", spins[0]);
}
