//! Pellet shape descriptions and the per-type mass data registered once with the world.
//!
//! Body frame convention: origin at the centroid, symmetry axis along body z.

use crate::error::SimError;
use crate::geometry::sdf::SdfGrid;
use crate::math::{Mat3, Real, Vec3};
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
    /// Any other shape (trilobe, multi-hole cylinder, a user mesh): surface samples plus a
    /// sampled signed-distance field, both in the body frame (centroid at the origin).
    Mesh {
        /// Free-form description (for messages).
        name: String,
        /// Points on the surface used as contact candidates (e.g. the mesh vertices), m.
        samples: Vec<Vec3>,
        /// Signed distance to the surface, m.
        grid: SdfGrid,
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

    /// Checks the dimensions.
    pub fn validate(&self) -> Result<(), SimError> {
        match self {
            ShapeDesc::Sphere { radius } => positive("radius", *radius),
            ShapeDesc::Cylinder { radius, half_height } => {
                positive("radius", *radius)?;
                positive("half_height", *half_height)
            }
            ShapeDesc::HollowCylinder { inner_radius, outer_radius, half_height } => {
                positive("inner_radius", *inner_radius)?;
                positive("half_height", *half_height)?;
                if !(outer_radius.is_finite() && outer_radius > inner_radius) {
                    return Err(SimError::InvalidParameter {
                        name: "outer_radius",
                        value: *outer_radius,
                        reason: "must be finite and larger than inner_radius",
                    });
                }
                Ok(())
            }
            ShapeDesc::Mesh { samples, grid, .. } => {
                if samples.is_empty() || samples.iter().any(|p| !p.iter().all(|v| v.is_finite())) {
                    return Err(SimError::UnsupportedShape(
                        "a mesh shape needs at least one finite surface sample".into(),
                    ));
                }
                grid.validate()
            }
        }
    }

    /// Radius of the narrowest tube the shape fits into (axis along the tube): the sphere or
    /// outer radius for the closed forms; for meshes the smallest, over the body axes, of the
    /// largest distance of a sample from that axis.
    pub fn fit_radius(&self) -> Real {
        match self {
            ShapeDesc::Sphere { radius } => *radius,
            ShapeDesc::Cylinder { radius, .. } => *radius,
            ShapeDesc::HollowCylinder { outer_radius, .. } => *outer_radius,
            ShapeDesc::Mesh { samples, .. } => (0..3)
                .map(|k| samples.iter().map(|p| (p.norm_squared() - p[k] * p[k]).max(0.0).sqrt()).fold(0.0, Real::max))
                .fold(Real::INFINITY, Real::min),
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

    /// A solid cylinder (axis along body z) with exact volume and inertia.
    pub fn solid_cylinder(radius: Real, half_height: Real) -> Result<Self, SimError> {
        positive("radius", radius)?;
        positive("half_height", half_height)?;
        Self::hollow_or_solid(0.0, radius, half_height, ShapeDesc::Cylinder { radius, half_height })
    }

    /// A hollow cylinder (Raschig ring, axis along body z) with exact volume and inertia.
    pub fn hollow_cylinder(inner_radius: Real, outer_radius: Real, half_height: Real) -> Result<Self, SimError> {
        let shape = ShapeDesc::HollowCylinder { inner_radius, outer_radius, half_height };
        shape.validate()?;
        Self::hollow_or_solid(inner_radius, outer_radius, half_height, shape)
    }

    fn hollow_or_solid(ri: Real, ro: Real, h: Real, shape: ShapeDesc) -> Result<Self, SimError> {
        let height = 2.0 * h;
        let volume = std::f64::consts::PI * (ro * ro - ri * ri) * height;
        let r2 = ro * ro + ri * ri;
        let izz = 0.5 * volume * r2;
        let ixx = volume * (3.0 * r2 + height * height) / 12.0;
        Ok(Self {
            shape,
            volume_m3: volume,
            inertia_per_density_m5: Mat3::from_diagonal(&Vec3::new(ixx, ixx, izz)),
            bounding_radius_m: ro.hypot(h),
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
        let needed = match &self.shape {
            ShapeDesc::Sphere { radius } => *radius,
            ShapeDesc::Cylinder { radius, half_height } => radius.hypot(*half_height),
            ShapeDesc::HollowCylinder { outer_radius, half_height, .. } => outer_radius.hypot(*half_height),
            ShapeDesc::Mesh { samples, .. } => samples.iter().map(|p| p.norm()).fold(0.0, Real::max),
        };
        // The broad phase and the culling trust the bounding sphere: it must hold the shape.
        if self.bounding_radius_m < needed * (1.0 - 1e-12) {
            return Err(SimError::InvalidParameter {
                name: "bounding_radius_m",
                value: self.bounding_radius_m,
                reason: "does not enclose the shape",
            });
        }
        Ok(())
    }
}
