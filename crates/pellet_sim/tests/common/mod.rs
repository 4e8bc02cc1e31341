//! Shared helpers for the validation tests.
#![allow(dead_code)]

use pellet_sim::{
    BodyId, BodyType, Container, EngineParams, Material, Pipeline, Quat, Real, TypeId, Vec3, WallMaterial, World,
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
    EngineParams { gravity: Vec3::zeros(), ..EngineParams::default() }
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

/// Recommended-mode switch used by "bias on" variants.
pub fn with_bias(params: EngineParams) -> EngineParams {
    EngineParams { velocity_bias: true, ..params }
}
