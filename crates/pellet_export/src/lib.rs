//! A packed bed in the forms particle-resolved CFD and lattice-Boltzmann
//! codes load: STL surfaces, VTK files for ParaView, solid/fluid voxel
//! grids and a poses CSV, with the standard contact treatments for meshing.
//!
//! Everything works from each pellet type's triangle mesh and each pellet's
//! pose, so every shape exports; the closed forms (sphere, cylinder, ring)
//! are only used where they make a query exact or fast (contact gaps,
//! voxel columns). Lengths are metres inside; the writers take a `scale`
//! (1000 for millimetres, 1 for metres) applied to every coordinate.
//!
//! - [`scene`]: the pellets' world meshes, the tube surface, the axial window.
//! - [`openfoam`]: an OpenFOAM case (surfaces and meshing dictionaries) for the fluid.
//! - [`clip`]: closed meshes cut at horizontal planes and capped (slabs of a bed).
//! - [`contacts`]: pellet–pellet and pellet–wall gaps below a threshold.
//! - [`treatment`]: global shrink, bridges and caps, with the porosity change of each.
//! - [`unite`]: the union of overlapping closed meshes (pellets and bridges) as one manifold surface.
//! - [`stl`], [`vtk`], [`voxels`], [`poses`]: the file formats (specified in each module).
//!
//! ```
//! use pellet_export::{scene, stl};
//! use pellet_geom::{Bed, Pellet, PlacedPellet, Resolution, ShapeSpec, Tube};
//! let sphere = Pellet::build(ShapeSpec::Sphere { diameter_mm: 10.0 }, Resolution::default()).unwrap();
//! let pose = PlacedPellet { type_index: 0, position: [0.0, 0.0, 0.005], orientation: [1.0, 0.0, 0.0, 0.0] };
//! let bed = Bed { tube: Tube { diameter: 0.02, lid_height: None }, pellet_types: vec![sphere], pellets: vec![pose] };
//! let meshes = scene::world_meshes(&bed, &[0]);
//! let bytes = stl::binary(&[&meshes[0]], 1000.0, "one sphere, mm");
//! assert_eq!(bytes.len(), 84 + 50 * bed.pellet_types[0].mesh.face_count());
//! ```
#![deny(missing_docs)]

pub mod clip;
pub mod contacts;
pub mod openfoam;
pub mod poses;
pub mod scene;
pub mod stl;
pub mod treatment;
pub mod unite;
pub mod voxels;
pub mod vtk;

pub use contacts::{find_contacts, Contact, Partner};
pub use treatment::{Bridge, Treatment, TreatmentReport};
pub use voxels::{voxelise, VoxelGrid, VoxelValue};

/// What can go wrong preparing an export.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    /// A parameter is out of range; the message names it and the range.
    #[error("{0}")]
    BadParameter(String),
    /// The union of the surfaces could not be formed; the message says which surface and why.
    #[error("{0}")]
    Union(String),
}
