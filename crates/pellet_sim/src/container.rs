//! The static container: a vertical tube seen from inside, a flat floor at z = 0, an optional lid,
//! and optional extra half-space walls (used by tests: grooves, boxes, inclines).

use crate::error::SimError;
use crate::math::{Real, Vec3};
use crate::shape::positive;
use serde::{Deserialize, Serialize};

/// A static plane wall; the allowed region is `normal · x ≥ offset`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PlaneWall {
    /// Unit normal pointing into the allowed region.
    pub normal: Vec3,
    /// Plane offset, m.
    pub offset: Real,
}

/// Identifies a static wall in contacts and warm-start keys.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
pub enum WallId {
    /// The floor z = 0.
    Floor,
    /// The tube's side wall.
    Tube,
    /// The lid.
    Lid,
    /// Extra plane number i.
    Plane(u32),
}

/// Tube of inner radius `tube_radius` with axis +z through the origin, floor at z = 0.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Container {
    /// Inner radius of the tube, m.
    pub tube_radius: Real,
    /// Height of an optional lid (a ceiling plane), m.
    pub lid_height: Option<Real>,
    /// Extra static planes.
    pub planes: Vec<PlaneWall>,
}

impl Container {
    /// A tube of inner diameter `diameter` (m) with a floor and no lid.
    pub fn tube(diameter: Real) -> Result<Self, SimError> {
        positive("tube diameter", diameter)?;
        Ok(Self { tube_radius: 0.5 * diameter, lid_height: None, planes: Vec::new() })
    }

    /// Adds a lid at height `h` (m).
    pub fn with_lid(mut self, h: Real) -> Result<Self, SimError> {
        positive("lid height", h)?;
        self.lid_height = Some(h);
        Ok(self)
    }

    /// Adds a plane wall; `normal` is normalised.
    pub fn with_plane(mut self, normal: Vec3, offset: Real) -> Result<Self, SimError> {
        let len = normal.norm();
        if !(len.is_finite() && len > 0.0 && offset.is_finite()) {
            return Err(SimError::InvalidParameter {
                name: "plane normal",
                value: len,
                reason: "must be finite and non-zero",
            });
        }
        self.planes.push(PlaneWall { normal: normal / len, offset: offset / len });
        Ok(self)
    }

    /// Validates the container against the largest pellet bounding radius.
    pub fn validate(&self, max_pellet_radius: Real) -> Result<(), SimError> {
        positive("tube radius", self.tube_radius)?;
        if self.tube_radius <= max_pellet_radius {
            return Err(SimError::ContainerTooSmall {
                tube_radius: self.tube_radius,
                pellet_radius: max_pellet_radius,
            });
        }
        if let Some(h) = self.lid_height {
            if h <= 2.0 * max_pellet_radius {
                return Err(SimError::ContainerTooSmall { tube_radius: h, pellet_radius: max_pellet_radius });
            }
        }
        Ok(())
    }

    /// Walls in a fixed order (floor, tube, lid, planes) with the clearance of a sphere of
    /// radius `r` at `x` (negative = overlapping) and the wall's inward normal there.
    pub fn wall_gaps(&self, x: &Vec3, r: Real, mut f: impl FnMut(WallId, Real)) {
        f(WallId::Floor, x.z - r);
        let rho = (x.x * x.x + x.y * x.y).sqrt();
        f(WallId::Tube, self.tube_radius - rho - r);
        if let Some(h) = self.lid_height {
            f(WallId::Lid, h - x.z - r);
        }
        for (i, p) in self.planes.iter().enumerate() {
            f(WallId::Plane(i as u32), p.normal.dot(x) - p.offset - r);
        }
    }

    /// True if a sphere of radius `r` at `x` lies inside every wall (touching allowed, with a
    /// round-off tolerance of 1e-9·r).
    pub fn contains_sphere(&self, x: &Vec3, r: Real) -> bool {
        let mut inside = true;
        self.wall_gaps(x, r, |_, gap| inside &= gap >= -1e-9 * r);
        inside
    }
}
