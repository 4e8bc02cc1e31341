//! Pellet shape descriptions and the per-type mass data registered once with the world.
//!
//! Body frame convention: origin at the centroid, symmetry axis along body z.

use crate::error::SimError;
use crate::math::{Mat3, Real};
use serde::{Deserialize, Serialize};

/// Geometric description of a pellet shape, in the body frame (metres).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum ShapeDesc {
    /// Solid sphere.
    Sphere {
        /// Radius, m.
        radius: Real,
    },
    /// Solid cylinder with its axis along body z.
    Cylinder {
        /// Radius, m.
        radius: Real,
        /// Half of the height, m.
        half_height: Real,
    },
    /// Hollow cylinder (Raschig ring) with its axis along body z.
    HollowCylinder {
        /// Inner radius, m.
        inner_radius: Real,
        /// Outer radius, m.
        outer_radius: Real,
        /// Half of the height, m.
        half_height: Real,
    },
    /// A triangle mesh or any other shape without a closed form (name for messages only).
    Mesh {
        /// Free-form description.
        name: String,
    },
}

impl ShapeDesc {
    /// Short kind name for messages.
    pub fn kind_name(&self) -> &'static str {
        match self {
            ShapeDesc::Sphere { .. } => "sphere",
            ShapeDesc::Cylinder { .. } => "cylinder",
            ShapeDesc::HollowCylinder { .. } => "hollow cylinder",
            ShapeDesc::Mesh { .. } => "mesh",
        }
    }

    /// Checks the dimensions and whether this narrow phase handles the kind.
    ///
    /// Cylinders, rings and meshes are described here so that the API is stable, but their
    /// contact generation arrives in a later issue; registering them is an error until then.
    pub fn validate(&self) -> Result<(), SimError> {
        match self {
            ShapeDesc::Sphere { radius } => positive("radius", *radius),
            other => Err(SimError::UnsupportedShape(format!(
                "{} contact generation is not implemented yet",
                other.kind_name()
            ))),
        }
    }
}

/// Checks that `value` is finite and strictly positive.
pub(crate) fn positive(name: &'static str, value: Real) -> Result<(), SimError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(SimError::InvalidParameter { name, value, reason: "must be finite and > 0" })
    }
}

/// A pellet type: shape plus mass properties per unit density. Registered once with the world.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BodyType {
    /// Shape, body frame.
    pub shape: ShapeDesc,
    /// Volume, m³.
    pub volume_m3: Real,
    /// Inertia tensor about the centroid in the body frame, divided by density (m⁵).
    pub inertia_per_density_m5: Mat3,
    /// Radius of a sphere about the centroid that contains the pellet, m.
    pub bounding_radius_m: Real,
}

impl BodyType {
    /// A solid sphere with exact volume and inertia.
    pub fn solid_sphere(radius: Real) -> Result<Self, SimError> {
        positive("radius", radius)?;
        let volume = 4.0 / 3.0 * std::f64::consts::PI * radius.powi(3);
        let i = 0.4 * volume * radius * radius;
        Ok(Self {
            shape: ShapeDesc::Sphere { radius },
            volume_m3: volume,
            inertia_per_density_m5: Mat3::from_diagonal_element(i),
            bounding_radius_m: radius,
        })
    }

    /// Validates shape, volume, inertia (symmetric, positive definite) and bounding radius.
    pub fn validate(&self) -> Result<(), SimError> {
        self.shape.validate()?;
        positive("volume_m3", self.volume_m3)?;
        positive("bounding_radius_m", self.bounding_radius_m)?;
        let i = &self.inertia_per_density_m5;
        if i.iter().any(|v| !v.is_finite()) || (i - i.transpose()).abs().max() > 1e-9 * i.abs().max() {
            return Err(SimError::InvalidParameter {
                name: "inertia_per_density_m5",
                value: i.abs().max(),
                reason: "must be finite and symmetric",
            });
        }
        if i.cholesky().is_none() {
            return Err(SimError::InvalidParameter {
                name: "inertia_per_density_m5",
                value: i.abs().max(),
                reason: "must be positive definite",
            });
        }
        if let ShapeDesc::Sphere { radius } = self.shape {
            if self.bounding_radius_m < radius {
                return Err(SimError::InvalidParameter {
                    name: "bounding_radius_m",
                    value: self.bounding_radius_m,
                    reason: "smaller than the sphere radius",
                });
            }
        }
        Ok(())
    }
}
