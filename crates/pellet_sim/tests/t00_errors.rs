//! Bad input is an error, never a panic; the state is serialisable.

mod common;
use common::*;
use pellet_sim::{BodyType, Container, EngineParams, Mat3, Quat, ShapeDesc, SimError, Vec3, World};

fn world(d: f64) -> World {
    World::new(Container::tube(d).unwrap(), material(0.5, 0.3), wall(0.5, 0.3), EngineParams::paper()).unwrap()
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
fn bad_shapes_are_errors_not_panics() {
    let mut w = world(0.1);
    let grid =
        pellet_sim::SdfGrid { origin: Vec3::zeros(), cell: 1e-3, dims: [2, 2, 2], values: vec![0.0; 7], margin: 1e-3 };
    let shapes = [
        ShapeDesc::Cylinder { radius: 0.0, half_height: 0.005 },
        ShapeDesc::Cylinder { radius: 0.005, half_height: f64::NAN },
        ShapeDesc::HollowCylinder { inner_radius: 0.005, outer_radius: 0.003, half_height: 0.005 },
        ShapeDesc::Mesh { name: "no samples".into(), samples: vec![], grid: grid.clone() },
        ShapeDesc::Mesh { name: "short grid".into(), samples: vec![Vec3::x() * 1e-3], grid },
    ];
    for shape in shapes {
        let ty = BodyType {
            shape,
            volume_m3: 1e-7,
            inertia_per_density_m5: Mat3::identity() * 1e-12,
            bounding_radius_m: 0.008,
        };
        assert!(w.register_type(ty).is_err());
    }
    // A bounding radius that does not hold the cylinder is refused (the culling trusts it).
    let mut ty = BodyType::solid_cylinder(0.005, 0.005).unwrap();
    ty.bounding_radius_m = 0.006;
    assert!(w.register_type(ty).is_err());
    // A cylinder fits a tube just wider than its diameter (axis along the tube).
    let mut narrow = world(0.0101);
    assert!(narrow.register_type(BodyType::solid_cylinder(0.005, 0.005).unwrap()).is_ok());
    let mut too_narrow = world(0.0099);
    assert!(matches!(
        too_narrow.register_type(BodyType::solid_cylinder(0.005, 0.005).unwrap()),
        Err(SimError::ContainerTooSmall { .. })
    ));
}

#[test]
fn cylinder_placement_uses_the_exact_shape() {
    let mut w = world(0.05);
    let t = w.register_type(BodyType::solid_cylinder(0.005, 0.005).unwrap()).unwrap();
    let (q, z) = (Quat::identity(), Vec3::zeros());
    // Standing on the floor: inside, although the bounding sphere (7.07 mm) pokes through.
    assert!(w.add_body(t, Vec3::new(0.0, 0.0, 0.005), q, z, z).is_ok());
    assert!(w.add_body(t, Vec3::new(0.0, 0.0, 0.0049), q, z, z).is_err());
    // Tilted 45°: the lowest rim point is 7.07 mm below the centre.
    let tilt = Quat::from_axis_angle(&Vec3::x_axis(), std::f64::consts::FRAC_PI_4);
    assert!(w.add_body(t, Vec3::new(0.0, 0.0, 0.0070), tilt, z, z).is_err());
    assert!(w.add_body(t, Vec3::new(0.0, 0.0, 0.0071), tilt, z, z).is_ok());
    // Against the tube wall (radius 25 mm): the rim reaches 5 mm out.
    assert!(w.add_body(t, Vec3::new(0.0199, 0.0, 0.05), q, z, z).is_ok());
    assert!(w.add_body(t, Vec3::new(0.0201, 0.0, 0.05), q, z, z).is_err());
}

#[test]
fn bad_inertia_and_materials_are_errors() {
    let mut w = world(0.1);
    let mut ty = BodyType::solid_sphere(0.005).unwrap();
    ty.inertia_per_density_m5 = Mat3::from_diagonal(&Vec3::new(1.0, -1.0, 1.0));
    assert!(w.register_type(ty).is_err());
    let bad = World::new(Container::tube(0.1).unwrap(), material(1.5, 0.3), wall(0.5, 0.3), EngineParams::paper());
    assert!(bad.is_err());
    let bad = World::new(Container::tube(0.1).unwrap(), material(0.5, 0.3), wall(0.5, -0.1), EngineParams::paper());
    assert!(bad.is_err());
    let params = EngineParams { eps_p: 0.0, ..EngineParams::paper() };
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
