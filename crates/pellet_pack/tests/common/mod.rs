//! Shared by the pack-level tests: pack's configuration for a tube, and a world restarted from a
//! bed's poses with every pellet at rest. Each test binary uses part of it.
#![allow(dead_code)]

use pellet_geom::Pellet;
use pellet_pack::driver::new_world;
use pellet_pack::{PackConfig, PackOptions};
use pellet_sim::{EngineParams, Quat, Vec3, World};

/// Pack's configuration for a tube of `tube_mm` (defaults otherwise), with `edit` applied to
/// the options first.
pub fn pack_config(tube_mm: f64, count: u32, edit: impl FnOnce(&mut PackOptions)) -> PackConfig {
    let mut options = PackOptions {
        pellet: Some("restart.pellet".into()),
        tube_diameter: Some(tube_mm),
        count: Some(count),
        ..Default::default()
    };
    edit(&mut options);
    PackConfig::resolve(&options).expect("a valid pack configuration")
}

/// A world of `pellet`s at `poses` ((x, y, z) in m, (w, x, y, z) body → world), at rest, set up
/// as pack sets it up for `config`, then with `params` (pack's are [`pellet_pack::engine_params`]). A resting
/// pellet may sit a few µm into the floor or the wall, which `add_body` refuses: such a pellet
/// is moved 10 µm up and 10 µm towards the axis.
pub fn restart_world(
    config: &PackConfig,
    params: EngineParams,
    pellet: &Pellet,
    poses: &[([f64; 3], [f64; 4])],
) -> World {
    let (mut world, ty) = new_world(config, pellet).expect("pack's world for this configuration");
    world.set_params(params).expect("valid engine parameters");
    for (p, q) in poses {
        let q = Quat::new_normalize(nalgebra::Quaternion::new(q[0], q[1], q[2], q[3]));
        let p = Vec3::from(*p);
        if world.add_body(ty, p, q, Vec3::zeros(), Vec3::zeros()).is_err() {
            let r = p.x.hypot(p.y).max(1e-9);
            let nudged = Vec3::new(p.x * (1.0 - 1e-5 / r), p.y * (1.0 - 1e-5 / r), p.z + 1e-5);
            world.add_body(ty, nudged, q, Vec3::zeros(), Vec3::zeros()).expect("the pellet inside the tube");
        }
    }
    world
}
