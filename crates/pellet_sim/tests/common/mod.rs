//! Shared helpers for the validation tests.
#![allow(dead_code)]

use pellet_sim::{
    AccelerationParams, BodyId, BodyType, Container, EngineParams, Material, Pipeline, Quat, Real, TypeId, Vec3,
    WallMaterial, World,
};

/// Density used by the tests, kg/m³.
pub const DENSITY: Real = 2000.0;

pub fn material(cor: Real, friction: Real) -> Material {
    Material { density: DENSITY, cor, friction }
}

pub fn wall(cor: Real, friction: Real) -> WallMaterial {
    WallMaterial { cor, friction }
}

pub fn zero_gravity() -> EngineParams {
    EngineParams { gravity: Vec3::zeros(), ..EngineParams::paper() }
}

/// World with one sphere type of radius `r` in a tube of diameter `tube_d`.
pub fn sphere_world(
    container: Container,
    r: Real,
    mat: Material,
    wall_mat: WallMaterial,
    params: EngineParams,
) -> (World, TypeId) {
    let mut w = World::new(container, mat, wall_mat, params).unwrap();
    let t = w.register_type(BodyType::solid_sphere(r).unwrap()).unwrap();
    (w, t)
}

pub fn add(w: &mut World, t: TypeId, x: Vec3, v: Vec3, omega: Vec3) -> BodyId {
    w.add_body(t, x, Quat::identity(), v, omega).unwrap()
}

/// Steps `n` times by `dt`, returning the worst penetration seen.
pub fn run(w: &mut World, p: &mut Pipeline, dt: Real, n: usize) -> Real {
    let mut pen: Real = 0.0;
    for _ in 0..n {
        let r = w.step(dt, p).unwrap();
        pen = pen.max(r.max_penetration);
    }
    pen
}

pub fn rel(a: Real, b: Real) -> Real {
    (a - b).abs() / b.abs().max(1e-300)
}

pub fn vel(w: &World, id: BodyId) -> Vec3 {
    w.body(id).unwrap().velocity()
}

pub fn omega(w: &World, id: BodyId) -> Vec3 {
    w.body(id).unwrap().angular_velocity()
}

pub fn pos(w: &World, id: BodyId) -> Vec3 {
    w.body(id).unwrap().position
}

/// World with one pellet type `ty`.
pub fn shape_world(
    container: Container,
    ty: BodyType,
    mat: Material,
    wall_mat: WallMaterial,
    params: EngineParams,
) -> (World, TypeId) {
    let mut w = World::new(container, mat, wall_mat, params).unwrap();
    let t = w.register_type(ty).unwrap();
    (w, t)
}

pub fn add_q(w: &mut World, t: TypeId, x: Vec3, q: Quat, v: Vec3, omega: Vec3) -> BodyId {
    w.add_body(t, x, q, v, omega).unwrap()
}

/// Sum of resting normal forces on the contacts of the last substep that satisfy `pick`.
pub fn force_sum(p: &Pipeline, pick: impl Fn(&pellet_sim::Contact) -> bool) -> Real {
    p.last_contacts().iter().filter(|r| pick(&r.contact)).map(|r| r.normal_force).sum()
}

/// `n` equilateral 10 mm cylinders stacked on the floor of a 12 mm tube, caps touching, at rest
/// (the stack proof and its diagnostic).
pub fn cylinder_stack(n: usize, params: EngineParams) -> (World, Vec<BodyId>) {
    let ty = BodyType::solid_cylinder(0.005, 0.005).unwrap();
    let (mut w, t) = shape_world(Container::tube(0.012).unwrap(), ty, material(0.5, 0.3), wall(0.5, 0.3), params);
    let ids = (0..n)
        .map(|k| {
            let x = Vec3::new(0.0, 0.0, 0.005 + 0.01 * k as f64);
            add_q(&mut w, t, x, Quat::identity(), Vec3::zeros(), Vec3::zeros())
        })
        .collect();
    (w, ids)
}

/// The paper's formulation ([`EngineParams::paper`]) with the recommended contact model: static
/// friction, stick clamp, velocity bias.
pub fn recommended() -> EngineParams {
    let paper = EngineParams::paper();
    let acceleration = AccelerationParams {
        static_friction: true,
        friction_clamp: pellet_sim::FrictionClamp::Stick,
        velocity_bias: true,
        ..paper.acceleration
    };
    EngineParams { acceleration, ..paper }
}

/// Recommended-mode switch used by "bias on" variants.
pub fn with_bias(params: EngineParams) -> EngineParams {
    EngineParams { acceleration: AccelerationParams { velocity_bias: true, ..params.acceleration }, ..params }
}

/// A mixed pour in a 40 mm tube, paper mode: `n` pellets alternating equilateral 10 mm
/// cylinders and 10/6/10 mm Raschig rings, four per layer 15 mm apart, each turned by a random
/// rotation of up to 3·½√3 rad (ChaCha8 from `seed`), at rest. Used by the pour proofs and the
/// ledger diagnostic so they start from the same bed.
pub fn mixed_pour(n: usize, seed: u64) -> World {
    use rand::{RngExt, SeedableRng};
    let mut w =
        World::new(Container::tube(0.04).unwrap(), material(0.5, 0.3), wall(0.5, 0.3), EngineParams::paper()).unwrap();
    let cyl = w.register_type(BodyType::solid_cylinder(0.005, 0.005).unwrap()).unwrap();
    let ring = w.register_type(BodyType::hollow_cylinder(0.003, 0.005, 0.005).unwrap()).unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    for k in 0..n {
        let (layer, slot) = (k / 4, k % 4);
        let (sx, sy) = [(1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0)][slot];
        let x = Vec3::new(0.0075 * sx, 0.0075 * sy, 0.01 + 0.015 * layer as f64);
        let axis = Vec3::new(rng.random::<f64>() - 0.5, rng.random::<f64>() - 0.5, rng.random::<f64>() - 0.5);
        let t = if k % 2 == 0 { cyl } else { ring };
        add_q(&mut w, t, x, Quat::from_scaled_axis(axis * 3.0), Vec3::zeros(), Vec3::zeros());
    }
    w
}
