//! How a pack run sets up the engine: the pellet as an engine body type (closed forms, or a
//! mesh's samples and signed-distance grid), the tube and materials, and the engine parameters
//! of the chosen contact model.

use pellet_geom::{ClosedForm, Pellet};
use pellet_sim::{
    BodyType, Container, EngineParams, FrictionClamp, IterativeSolver, Material, ShapeDesc, VelocityParams,
    WallMaterial, World,
};

use crate::config::{ClampRule, ContactModel, PackConfig};
use crate::driver::PackError;

/// Nodes of the signed-distance grid along the pellet's bounding diameter for mesh shapes:
/// cell ≈ d/80 (0.125 mm for a 10 mm pellet) keeps the interpolation error near the surface
/// at a few µm on flat parts and ~cell/2 at sharp edges.
pub const SDF_GRID_NODES_PER_DIAMETER: f64 = 80.0;

/// At most this many mesh vertices are used as contact samples (a finer mesh is thinned on a
/// grid of spacing ≈ d/60, so the per-pair cost stays bounded).
pub const MAX_MESH_SAMPLES: usize = 3000;

/// The engine's description of a pellet type: closed forms for sphere, cylinder and ring;
/// every other shape (lobed, multi-hole, user meshes) as mesh vertices plus a signed-distance
/// grid of its triangle mesh (parry3d, via `pellet_geom::parry_boundary`).
pub fn body_type(pellet: &Pellet) -> Result<BodyType, PackError> {
    let shape = match pellet.closed_form {
        Some(ClosedForm::Sphere { radius }) => ShapeDesc::Sphere { radius },
        Some(ClosedForm::Cylinder { radius, half_height }) => ShapeDesc::Cylinder { radius, half_height },
        Some(ClosedForm::HollowCylinder { inner_radius, outer_radius, half_height }) => {
            ShapeDesc::HollowCylinder { inner_radius, outer_radius, half_height }
        }
        None => mesh_shape(pellet)?,
    };
    // A sphere's contacts are those of the exact sphere, so is its inertia: the faceted mesh's
    // tensor is isotropic but for ~1e-3 of its trace, and an exactly isotropic one lets the
    // engine skip R I Rᵀ (`Body::inv_inertia_world`).
    let inertia = match shape {
        ShapeDesc::Sphere { .. } => {
            let mean = pellet.properties.inertia.trace() / 3.0;
            pellet_sim::Mat3::identity() * mean
        }
        _ => pellet.properties.inertia,
    };
    Ok(BodyType {
        shape,
        volume_m3: pellet.properties.volume,
        inertia_per_density_m5: inertia,
        bounding_radius_m: pellet.bounding_radius,
    })
}

/// The engine's mesh shape of a pellet: thinned vertices and the signed-distance grid.
pub fn mesh_shape(pellet: &Pellet) -> Result<ShapeDesc, PackError> {
    let d = 2.0 * pellet.bounding_radius;
    let cell = d / SDF_GRID_NODES_PER_DIAMETER;
    let margin = 0.1 * d;
    let (origin, dims, values) = pellet_geom::parry_boundary::signed_distance_grid(&pellet.mesh, cell, margin)
        .map_err(|e| PackError::Setup(e.to_string()))?;
    let grid = pellet_sim::SdfGrid { origin: origin.coords, cell, dims, values, margin };
    Ok(ShapeDesc::Mesh { name: pellet.shape.kind().to_string(), samples: thin(&pellet.mesh.vertices, d), grid })
}

/// Keeps one vertex per cell of a grid fine enough to leave at most MAX_MESH_SAMPLES
/// (first vertex in index order wins: deterministic).
fn thin(vertices: &[pellet_geom::math::Point], d: f64) -> Vec<pellet_sim::Vec3> {
    let all: Vec<pellet_sim::Vec3> = vertices.iter().map(|v| v.coords).collect();
    if all.len() <= MAX_MESH_SAMPLES {
        return all;
    }
    let mut spacing = d / 60.0;
    loop {
        let mut seen = std::collections::BTreeSet::new();
        let kept: Vec<_> = all
            .iter()
            .filter(|p| {
                seen.insert((
                    (p.x / spacing).floor() as i64,
                    (p.y / spacing).floor() as i64,
                    (p.z / spacing).floor() as i64,
                ))
            })
            .copied()
            .collect();
        if kept.len() <= MAX_MESH_SAMPLES {
            return kept;
        }
        spacing *= 1.25;
    }
}

/// Radius of the narrowest tube the pellet can enter: the smallest, over
/// its principal axes, of the largest distance of a mesh vertex from that axis.
pub fn narrowest_tube_radius(pellet: &Pellet) -> f64 {
    let axes = pellet.properties.principal_axes;
    (0..3)
        .map(|k| {
            let a = axes.column(k).into_owned();
            pellet.mesh.vertices.iter().map(|v| (v.coords - a * a.dot(&v.coords)).norm()).fold(0.0, f64::max)
        })
        .fold(f64::INFINITY, f64::min)
}

/// Checks that the run can start (the tube fits the pellet, the engine
/// accepts the shape and materials) without running it, so that a tool
/// can refuse before it creates any output.
pub fn check_setup(config: &PackConfig, pellet: &Pellet) -> Result<(), PackError> {
    new_world(config, pellet).map(|_| ())
}

/// The empty world of a pack run: the tube, materials and engine parameters of `config`, and
/// `pellet` registered as its one type (refused if the tube is too narrow for it). Beds of
/// spheres solve their large islands with MPRGP, others with APGD: measured, MPRGP took 38 %
/// less CPU on the paper's 690-sphere bed, but a 3.55 N cylinder bed of the paper study that
/// APGD settles at 3.4 s in 97 s of CPU still crept at 20 s with MPRGP (a top pellet rocking,
/// KE ~2e-10 J flickering).
pub fn new_world(config: &PackConfig, pellet: &Pellet) -> Result<(World, pellet_sim::TypeId), PackError> {
    let tube_radius = 0.5 * config.tube_diameter_m;
    let min_radius = narrowest_tube_radius(pellet);
    if tube_radius <= min_radius {
        return Err(PackError::Setup(format!(
            "--tube-diameter {:.3} mm is too narrow for this pellet: it needs more than {:.3} mm",
            config.tube_diameter_m * 1e3,
            2.0 * min_radius * 1e3
        )));
    }
    let setup = |e: pellet_sim::SimError| PackError::Setup(e.to_string());
    let material = Material { density: config.density_kg_m3, cor: config.cor, friction: config.friction };
    let wall = WallMaterial { cor: config.wall_cor, friction: config.wall_friction };
    let mut params = engine_params(config);
    if pellet.is_sphere() {
        params.acceleration.iterative_solver = IterativeSolver::Mprgp;
    }
    let mut world =
        World::new(Container::tube(config.tube_diameter_m).map_err(setup)?, material, wall, params).map_err(setup)?;
    let type_id = world.register_type(body_type(pellet)?).map_err(setup)?;
    Ok((world, type_id))
}

/// The engine parameters of a pack run: [`EngineParams::default`] with the run's resting band
/// ([`EngineParams::with_resting_band`]), contact model and clamp rule, substep scale, stepper
/// and velocity-level step and patch. With no engine flags they are the default itself.
pub fn engine_params(config: &PackConfig) -> EngineParams {
    let base = EngineParams::default().with_resting_band(config.resting_band_m_s);
    let mut acceleration = match config.contact_model {
        ContactModel::Paper => base.acceleration.with_paper_contact_model(),
        ContactModel::Recommended => base.acceleration,
    };
    match config.friction_clamp {
        Some(ClampRule::Stick) => acceleration.friction_clamp = FrictionClamp::Stick,
        Some(ClampRule::Zero) => acceleration.friction_clamp = FrictionClamp::Zero,
        None => {}
    }
    acceleration.dt_cap *= config.substep_scale;
    acceleration.slip_fraction *= config.substep_scale;
    EngineParams {
        stepper: config.stepper,
        acceleration,
        velocity: VelocityParams {
            patch_radius: config.contact_patch_dp,
            travel: config.step_travel_dp,
            max_step: config.max_step_s,
            ..base.velocity
        },
        ..base
    }
}
