//! Measurements of packed beds: radial void fraction ε(r), axial void
//! fraction ε(z), exact bulk porosity, coordination number and the
//! orientation of pellet axes. Pure functions that return reports; the
//! `voidprof` tool only reads files and prints them.
//!
//! Lengths are in metres (as in [`pellet_geom::Bed`]); the tube axis is
//! world z and the floor is z = 0.
//!
//! - [`void_profile`]: ε(r) = 1 − S_int(r)/(2πrH) from vertical lines, exact
//!   in z (closed-form chords of spheres, cylinders and rings; crossings of
//!   the triangle mesh otherwise), sampled in θ (uniformly, refined where the
//!   line length jumps); and ε(z) from the same lines.
//! - [`bulk_porosity`]: 1 − (pellet volume in the window)/(tube volume of the
//!   window), pellets cut by the planes z0 and z1 counted exactly (closed-form
//!   caps and cylinder segments, or mesh clipping). Volumes are summed, so
//!   two pellets overlapping by a small engine penetration count their common
//!   part twice; the profile takes the union along each line and does not.
//! - [`coordination`] and [`orientation`]: contacts per pellet and the
//!   distribution of the angle between pellet axes and the tube axis.
//! - [`deepest_overlap`]: the deepest overlap between two pellets and between a
//!   pellet and the tube, on the exact shapes, independent of the engine.
//!
//! ```
//! use pellet_analysis::{bulk_porosity, void_profile, Geometry, ProfileParams};
//! use pellet_geom::{Bed, Pellet, PlacedPellet, Resolution, ShapeSpec, Tube};
//! let sphere = Pellet::build(ShapeSpec::Sphere { diameter_mm: 10.0 }, Resolution::default()).unwrap();
//! let pose = PlacedPellet { type_index: 0, position: [0.0, 0.0, 0.005], orientation: [1.0, 0.0, 0.0, 0.0] };
//! let bed = Bed { tube: Tube { diameter: 0.02, lid_height: None }, pellet_types: vec![sphere], pellets: vec![pose] };
//! let window = (0.0, 0.01);
//! let bulk = bulk_porosity(&bed, window, Geometry::Auto).unwrap();
//! // One 10 mm sphere in a 20 mm × 10 mm cylinder: 1 − (4/3 π 5³)/(π 10² · 10) = 5/6.
//! assert!((bulk.porosity - 5.0 / 6.0).abs() < 1e-12);
//! let profile = void_profile(&bed, &ProfileParams::new(window)).unwrap();
//! assert!((profile.cross_section_mean() - bulk.porosity).abs() < 0.002);
//! assert_eq!(*profile.void_fraction.last().unwrap(), 1.0);
//! ```
#![deny(missing_docs)]

pub mod average;
pub mod clip;
pub mod line;
pub mod overlap;
pub mod profile;
pub mod raster;
pub mod refine;
pub mod structure;
pub mod synthetic;

pub use average::{average_profiles, ProfileStats};
pub use line::{Geometry, LineCaster};
pub use overlap::{deepest_overlap, Boundary, BoundaryOverlap, DeepestOverlap, Overlap};
pub use profile::{check_window, void_profile, AxialProfile, ProfileParams, VoidProfile};
pub use structure::{coordination, orientation, overlapping_pairs, Coordination, OrientationHistogram};

use pellet_geom::math::Real;
use pellet_geom::{Bed, ClosedForm, Pellet, PlacedPellet, ShapeSpec};

/// What can go wrong measuring a bed.
#[derive(Debug, thiserror::Error)]
pub enum AnalysisError {
    /// A parameter is out of range; the message names it.
    #[error("{0}")]
    BadParameter(String),
    /// The window does not lie inside the bed.
    #[error("window {z0_mm} to {z1_mm} mm is outside the bed: {why}")]
    Window {
        /// Bottom of the window (mm).
        z0_mm: Real,
        /// Top of the window (mm).
        z1_mm: Real,
        /// Why it was refused.
        why: String,
    },
    /// Profiles that cannot be averaged together.
    #[error("cannot average the profiles: {0}")]
    Mismatch(String),
}

/// The pellet diameter dp and the equal-volume sphere diameter dpv of the
/// bed's first pellet type (m). dp is the sphere's or cylinder's diameter,
/// a ring's outer diameter, a lobed shape's circumscribed size, and dpv
/// for user meshes.
pub fn reference_diameters(bed: &Bed) -> Result<(Real, Real), AnalysisError> {
    let pellet =
        bed.pellet_types.first().ok_or_else(|| AnalysisError::BadParameter("the bed has no pellet types".into()))?;
    let dpv = pellet.properties.equivalent_diameter;
    let mm = match pellet.shape {
        ShapeSpec::Sphere { diameter_mm } => diameter_mm,
        ShapeSpec::Cylinder { diameter_mm, .. } => diameter_mm,
        ShapeSpec::Ring { outer_diameter_mm, .. } => outer_diameter_mm,
        ShapeSpec::Lobed { size_mm, .. } => size_mm,
        ShapeSpec::MultiHole { diameter_mm, .. } => diameter_mm,
        ShapeSpec::UserMesh { .. } => return Ok((dpv, dpv)),
    };
    Ok((mm * 1e-3, dpv))
}

/// Half of a placed pellet's extent along world z (m): exact for closed forms, the mesh's otherwise.
pub fn half_extent_z(pellet: &Pellet, pose: &PlacedPellet) -> Real {
    let axis = pose.axis();
    let cos = axis.z.abs().min(1.0);
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    match pellet.closed_form {
        Some(ClosedForm::Sphere { radius }) => radius,
        Some(ClosedForm::Cylinder { radius, half_height }) => half_height * cos + radius * sin,
        Some(ClosedForm::HollowCylinder { outer_radius, half_height, .. }) => half_height * cos + outer_radius * sin,
        None => {
            let r = pose.rotation();
            pellet.mesh.vertices.iter().map(|v| (r * v.coords).z.abs()).fold(0.0, Real::max)
        }
    }
}

/// The highest point of any pellet (m); 0 for an empty bed.
pub fn bed_top(bed: &Bed) -> Real {
    bed.pellets
        .iter()
        .map(|p| p.position[2] + half_extent_z(&bed.pellet_types[p.type_index as usize], p))
        .fold(0.0, Real::max)
}

/// Bulk porosity of a window and what went into it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BulkPorosity {
    /// 1 − pellet volume / window volume.
    pub porosity: Real,
    /// Pellet volume inside the window (m³), cut pellets counted in part.
    pub pellet_volume: Real,
    /// Tube volume of the window, πR²(z1 − z0) (m³).
    pub window_volume: Real,
    /// Pellets whose centroid lies in the window.
    pub centres_in_window: usize,
    /// Pellets cut by the plane z0 or z1.
    pub cut: usize,
}

/// Exact bulk porosity of `window` (m): each pellet's volume between the
/// planes, summed. Overlaps between pellets (engine penetration) are
/// counted twice, and pellet parts beyond the wall are counted.
pub fn bulk_porosity(bed: &Bed, window: (Real, Real), geometry: Geometry) -> Result<BulkPorosity, AnalysisError> {
    bed.validate().map_err(|e| AnalysisError::BadParameter(e.to_string()))?;
    check_window(bed, window)?;
    let (z0, z1) = window;
    let (mut volume, mut centres, mut cut) = (0.0, 0, 0);
    for pose in &bed.pellets {
        let pellet = &bed.pellet_types[pose.type_index as usize];
        let (z, h) = (pose.position[2], half_extent_z(pellet, pose));
        if z + h <= z0 || z - h >= z1 {
            continue;
        }
        if (z0..z1).contains(&z) {
            centres += 1;
        }
        if z - h < z0 || z + h > z1 {
            cut += 1;
            volume += clip::volume_in_slab(pellet, pose, z0, z1, geometry);
        } else {
            volume += match (geometry, pellet.closed_form) {
                (Geometry::Auto, Some(c)) => closed_form_volume(&c),
                _ => pellet.properties.volume,
            };
        }
    }
    let r = 0.5 * bed.tube.diameter;
    let window_volume = std::f64::consts::PI * r * r * (z1 - z0);
    Ok(BulkPorosity {
        porosity: 1.0 - volume / window_volume,
        pellet_volume: volume,
        window_volume,
        centres_in_window: centres,
        cut,
    })
}

/// The exact volume of a closed-form shape (m³).
pub fn closed_form_volume(shape: &ClosedForm) -> Real {
    let pi = std::f64::consts::PI;
    match *shape {
        ClosedForm::Sphere { radius } => 4.0 / 3.0 * pi * radius.powi(3),
        ClosedForm::Cylinder { radius, half_height } => 2.0 * pi * radius * radius * half_height,
        ClosedForm::HollowCylinder { inner_radius, outer_radius, half_height } => {
            2.0 * pi * (outer_radius * outer_radius - inner_radius * inner_radius) * half_height
        }
    }
}
