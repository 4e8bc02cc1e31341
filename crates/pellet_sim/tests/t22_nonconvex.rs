//! Nonconvex contact is real: linked rings, a pin through a ring's hole (zero gravity).

mod common;
use common::*;
use pellet_sim::{BodyType, Container, Quat, Vec3, World};

fn world() -> World {
    World::new(Container::tube(0.1).unwrap(), material(0.0, 0.0), wall(0.0, 0.0), zero_gravity()).unwrap()
}

/// Two thin rings (10/8/2 mm) linked like chain links: B lies flat at the origin, A stands in
/// the xz-plane with B's wall inside A's hole. A is pulled away at 0.1 m/s; its hole's inner
/// wall must catch B's wall 3.5 mm later and drag B along (e = 0: both end at 0.05 m/s).
/// A convex (hull) model would see the two bodies overlapping from the start.
#[test]
fn linked_rings_hook_each_other() {
    let mut w = world();
    let t = w.register_type(BodyType::hollow_cylinder(0.004, 0.005, 0.001).unwrap()).unwrap();
    let z0 = 0.05;
    let b = add_q(&mut w, t, Vec3::new(0.0, 0.0, z0), Quat::identity(), Vec3::zeros(), Vec3::zeros());
    let stand = Quat::from_axis_angle(&Vec3::x_axis(), std::f64::consts::FRAC_PI_2);
    let a = add_q(&mut w, t, Vec3::new(0.0045, 0.0, z0), stand, Vec3::new(0.1, 0.0, 0.0), Vec3::zeros());
    let mut p = pellet_sim::Pipeline::new();
    // 20 ms: A has moved 2 mm inside the gap; nothing touches yet.
    let pen0 = run(&mut w, &mut p, 1e-3, 20);
    assert_eq!(vel(&w, b), Vec3::zeros(), "B moved before the hook engaged");
    assert!(pen0 == 0.0);
    let pen = run(&mut w, &mut p, 1e-3, 60);
    let (va, vb) = (vel(&w, a), vel(&w, b));
    println!(
        "hook: v_A {:?}, v_B {:?}, max pen {pen:.2e} m, gap A-B x {:.3e}",
        va.as_slice(),
        vb.as_slice(),
        pos(&w, a).x - pos(&w, b).x
    );
    assert!((vb.x - 0.05).abs() < 2.5e-3, "B must be dragged along: {}", vb.x);
    assert!((va.x + vb.x - 0.1).abs() < 1e-12, "momentum");
    assert!(pen < 1e-2 * 0.01, "penetration {pen}");
}

/// A pin (4 mm diameter, 12 mm long) falls through a 10/6/10 ring's 6 mm hole untouched; moved
/// 4 mm sideways it hits the ring's wall (e = 0) and is stopped and turned.
#[test]
fn pin_passes_through_the_hole() {
    for (offset, passes) in [(0.0, true), (0.0005, true), (0.004, false)] {
        let mut w = world();
        let ring = w.register_type(BodyType::hollow_cylinder(0.003, 0.005, 0.005).unwrap()).unwrap();
        let pin = w.register_type(BodyType::solid_cylinder(0.002, 0.006).unwrap()).unwrap();
        let r = add_q(&mut w, ring, Vec3::new(0.0, 0.0, 0.05), Quat::identity(), Vec3::zeros(), Vec3::zeros());
        let v0 = Vec3::new(0.0, 0.0, -0.2);
        let pid = add_q(&mut w, pin, Vec3::new(offset, 0.0, 0.0625), Quat::identity(), v0, Vec3::zeros());
        let mut p = pellet_sim::Pipeline::new();
        // 0.2 s at 0.2 m/s: 40 mm, the pin's whole length plus the ring's height and more.
        let mut touched = false;
        for _ in 0..200 {
            w.step(1e-3, &mut p).unwrap();
            touched |= !p.last_contacts().is_empty();
        }
        let (vp, vr) = (vel(&w, pid), vel(&w, r));
        println!("pin offset {offset}: v_pin {:?}, v_ring {:?}, touched {touched}", vp.as_slice(), vr.as_slice());
        if passes {
            assert!(!touched, "the pin touched the ring");
            assert_eq!(vp, v0);
            assert_eq!(vr, Vec3::zeros());
            assert!(pos(&w, pid).z < 0.05 - 0.005 - 0.006, "the pin is through");
        } else {
            // An eccentric hit on the wall: the pin is slowed and turned, momentum is kept.
            assert!(touched);
            assert!(vp.z > -0.1, "the pin must be stopped by the wall: {:?}", vp);
            let (mp, mr) = (w.body(pid).unwrap().mass, w.body(r).unwrap().mass);
            assert!((mp * vp + mr * vr - mp * v0).norm() < 1e-12 * mp * 0.2, "momentum");
        }
    }
}
