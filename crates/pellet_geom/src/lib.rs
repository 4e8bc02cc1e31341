//! Pellet shapes for packbed: Loop-subdivided meshes with exact mass
//! properties, closed-form signed distances and convex collision pieces.
//!
//! Every pellet is a closed, outward-oriented triangle mesh made by Loop
//! subdivision of a coarse control mesh, with every new vertex projected
//! back onto the exact surface (flat caps stay flat, rims stay sharp).
//! Lengths are in metres inside; shape parameters are in millimetres as
//! users type them.
//!
//! ```
//! use pellet_geom::{Pellet, Resolution, ShapeSpec};
//! let cyl = Pellet::build(ShapeSpec::Cylinder { diameter_mm: 10.0, height_mm: 10.0 }, Resolution::default()).unwrap();
//! let exact = std::f64::consts::PI * 0.005f64.powi(2) * 0.010;
//! assert!((cyl.properties.volume / exact - 1.0).abs() < 0.005);
//! assert_eq!(cyl.topology().unwrap().euler_characteristic, 2);
//! ```
#![deny(missing_docs)]

pub mod bed;
pub mod catalogue;
pub mod extrude;
pub mod mass;
pub mod math;
pub mod mesh;
pub mod parry_boundary;
pub mod pellet;
pub mod pieces;
pub mod sdf;
pub mod shape_spec;
pub mod sphere;
pub mod subdivision;
pub mod surface;

pub use bed::{Bed, PlacedPellet, Tube};
pub use mass::MassProperties;
pub use mesh::{Topology, TriMesh};
pub use pellet::{Pellet, Resolution};
pub use pieces::ConvexPiece;
pub use sdf::ClosedForm;
pub use shape_spec::ShapeSpec;

/// What can go wrong while making a pellet.
#[derive(Debug, thiserror::Error)]
pub enum GeomError {
    /// A shape parameter is out of range; the message names the flag and the range.
    #[error("{0}")]
    BadParameter(String),
    /// A mesh is not a closed, consistently oriented 2-manifold, or has no volume.
    #[error("bad mesh: {0}")]
    BadMesh(String),
    /// Meshing or decomposition failed.
    #[error("meshing failed: {0}")]
    Meshing(String),
}
