//! Shared by the pack-level engine tests: a world restarted from a bed's poses, every pellet at
//! rest, with pack's engine parameters.

use pellet_geom::Pellet;
use pellet_pack::driver::body_type;
use pellet_pack::{engine_params, PackConfig, PackOptions};
use pellet_sim::{Container, EngineParams, Material, Quat, Vec3, WallMaterial, World};

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

/// A world of `pellet`s at `poses` ((x, y, z) in m, (w, x, y, z) body → world), at rest, in the
/// tube of `config`, with `params` (pack's are [`engine_params`]). A resting pellet may sit a
/// few µm into the floor or the wall, which `add_body` refuses: such a pellet is moved 10 µm up
/// and 10 µm towards the axis.
pub fn restart_world(
    config: &PackConfig,
    params: EngineParams,
    pellet: &Pellet,
    poses: &[([f64; 3], [f64; 4])],
) -> World {
    let material = Material { density: config.density_kg_m3, cor: config.cor, friction: config.friction };
    let wall = WallMaterial { cor: config.wall_cor, friction: config.wall_friction };
    let container = Container::tube(config.tube_diameter_m).expect("a valid tube");
    let mut world = World::new(container, material, wall, params).expect("valid parameters");
    let ty = world.register_type(body_type(pellet).expect("an engine shape")).expect("the pellet fits");
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

/// Pack's engine parameters for `config`.
pub fn pack_params(config: &PackConfig) -> EngineParams {
    engine_params(config)
}
