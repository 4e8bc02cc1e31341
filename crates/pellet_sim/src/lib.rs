//! `pellet_sim`: the hard-contact rigid-body engine of packbed.
//!
//! It follows Mohammadzadeh Moghaddam et al. (2018) as designed in `docs/engine.md`: state
//! (x, q, P, L) integrated by the midpoint rule with quaternion renormalisation; a swept broad
//! phase and the paper's substep rule δt = 0.2λ/v_max with a cap; contacts classified by the
//! relative normal velocity against εp; colliding contacts resolved by passes of simultaneous
//! impulses with restitution and Coulomb friction; resting contacts by a linear complementarity
//! problem per island (Baraff's pivoting method for small islands, APGD/PGS for large ones);
//! drift removed by position projection that leaves velocities alone. No damping, no sleeping.
//!
//! Everything is SI (m, kg, s); gravity is (0, 0, −9.81) m/s² by default. Runs are
//! deterministic: same input, same bits.
//!
//! ```
//! use pellet_sim::{BodyType, Container, EngineParams, Material, Pipeline, Quat, Vec3, WallMaterial, World};
//! let mut world = World::new(
//!     Container::tube(0.05).unwrap(),
//!     Material { density: 2000.0, cor: 0.5, friction: 0.3 },
//!     WallMaterial { cor: 0.5, friction: 0.3 },
//!     EngineParams::default(),
//! ).unwrap();
//! let sphere = world.register_type(BodyType::solid_sphere(0.005).unwrap()).unwrap();
//! world.add_body(sphere, Vec3::new(0.0, 0.0, 0.05), Quat::identity(), Vec3::zeros(), Vec3::zeros()).unwrap();
//! let mut pipeline = Pipeline::new();
//! let report = world.step(1.0 / 40.0, &mut pipeline).unwrap();
//! assert!(report.free_flights >= 1);
//! ```
#![deny(missing_docs)]

mod body;
mod container;
pub mod dynamics;
mod error;
pub mod geometry;
mod math;
mod params;
mod pipeline;
mod shape;
mod team;

pub use body::{Body, BodyId, TypeId};
pub use container::{Container, PlaneWall, WallId};
pub use error::SimError;
pub use geometry::contact::{Contact, ContactKey, Counterpart};
pub use geometry::manifold::Manifold;
pub use geometry::sdf::SdfGrid;
pub use math::{Mat3, Quat, Real, Vec3};
pub use params::{
    AccelerationParams, ApproachBound, EngineParams, FrictionClamp, IterativeSolver, Material, Stepper, VelocityParams,
    WallMaterial, EXACT_FALLBACK_MAX_ROWS, EXACT_SOLVER_MAX_ROWS,
};
pub use pipeline::{ContactRecord, EnergyLedger, Pipeline, StepReport, WarmForce, WarmImpulse, World, WorldState};
pub use shape::{BodyType, ShapeDesc};
