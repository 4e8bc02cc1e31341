//! Bad input is an error, never a panic; the state is serialisable.

mod common;
use common::*;
use pellet_sim::{BodyType, Container, EngineParams, Mat3, Quat, ShapeDesc, SimError, Vec3, World};

fn world(d: f64) -> World {
    World::new(Container::tube(d).unwrap(), material(0.5, 0.3), wall(0.5, 0.3), EngineParams::default()).unwrap()
}

#[test]
fn bad_radius_is_an_error() {
    assert!(matches!(BodyType::solid_sphere(0.0), Err(SimError::InvalidParameter { .. })));
    assert!(matches!(BodyType::solid_sphere(-1.0), Err(SimError::InvalidParameter { .. })));
    assert!(matches!(BodyType::solid_sphere(f64::NAN), Err(SimError::InvalidParameter { .. })));
    assert!(Container::tube(0.0).is_err());
}

#[test]
fn tube_narrower_than_pellet_is_an_error() {
    let mut w = world(0.008);
    let err = w.register_type(BodyType::solid_sphere(0.005).unwrap());
    assert!(matches!(err, Err(SimError::ContainerTooSmall { .. })));
}

#[test]
fn unsupported_shapes_are_errors_not_panics() {
    let mut w = world(0.1);
    let shapes = [
        ShapeDesc::Cylinder { radius: 0.005, half_height: 0.005 },
        ShapeDesc::HollowCylinder { inner_radius: 0.003, outer_radius: 0.005, half_height: 0.005 },
        ShapeDesc::Mesh { name: "trilobe".into() },
    ];
    for shape in shapes {
        let ty = BodyType {
            shape,
            volume_m3: 1e-7,
            inertia_per_density_m5: Mat3::identity() * 1e-12,
            bounding_radius_m: 0.008,
        };
        assert!(matches!(w.register_type(ty), Err(SimError::UnsupportedShape(_))));
    }
}

#[test]
fn bad_inertia_and_materials_are_errors() {
    let mut w = world(0.1);
    let mut ty = BodyType::solid_sphere(0.005).unwrap();
    ty.inertia_per_density_m5 = Mat3::from_diagonal(&Vec3::new(1.0, -1.0, 1.0));
    assert!(w.register_type(ty).is_err());
    let bad = World::new(Container::tube(0.1).unwrap(), material(1.5, 0.3), wall(0.5, 0.3), EngineParams::default());
    assert!(bad.is_err());
    let bad = World::new(Container::tube(0.1).unwrap(), material(0.5, 0.3), wall(0.5, -0.1), EngineParams::default());
    assert!(bad.is_err());
    let params = EngineParams { eps_p: 0.0, ..EngineParams::default() };
    assert!(World::new(Container::tube(0.1).unwrap(), material(0.5, 0.3), wall(0.5, 0.3), params).is_err());
}

#[test]
fn bodies_outside_the_container_are_rejected() {
    let mut w = world(0.05);
    let t = w.register_type(BodyType::solid_sphere(0.005).unwrap()).unwrap();
    let q = Quat::identity();
    let z = Vec3::zeros();
    assert!(matches!(w.add_body(t, Vec3::new(0.0, 0.0, 0.001), q, z, z), Err(SimError::OutsideContainer { .. })));
    assert!(matches!(w.add_body(t, Vec3::new(0.023, 0.0, 0.1), q, z, z), Err(SimError::OutsideContainer { .. })));
    assert!(w.add_body(t, Vec3::new(0.0, 0.0, f64::NAN), q, z, z).is_err());
    assert!(matches!(
        w.add_body(pellet_sim::TypeId(7), Vec3::new(0.0, 0.0, 0.1), q, z, z),
        Err(SimError::UnknownBodyType(7))
    ));
    assert!(w.add_body(t, Vec3::new(0.0, 0.0, 0.1), q, z, z).is_ok());
    let mut p = pellet_sim::Pipeline::new();
    assert!(w.step(-1.0, &mut p).is_err());
    assert!(w.step(f64::NAN, &mut p).is_err());
}

#[test]
fn world_is_serialisable() {
    fn assert_serde<T: serde::Serialize + for<'de> serde::Deserialize<'de>>() {}
    assert_serde::<World>();
    assert_serde::<pellet_sim::EnergyLedger>();
}
