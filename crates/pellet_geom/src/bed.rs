//! A bed: a tube and pellets placed in it. Shared by `settle-check`
//! (which writes it), `voidprof` and `bedexport` (which read it).

use serde::{Deserialize, Serialize};

use crate::math::{shown, Point, Real, UnitQuaternion, Vector};
use crate::pellet::Pellet;
use crate::GeomError;

/// The container: a vertical cylinder about the z axis on the floor z = 0 (metres).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Tube {
    /// Inner diameter (m).
    pub diameter: Real,
    /// Height of a lid, if any (m).
    pub lid_height: Option<Real>,
}

/// One pellet's pose: body frame → world (metres).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PlacedPellet {
    /// Index into [`Bed::pellet_types`].
    pub type_index: u32,
    /// World position of the centroid (m).
    pub position: [Real; 3],
    /// Unit quaternion (w, x, y, z) rotating body to world.
    pub orientation: [Real; 4],
}

impl PlacedPellet {
    /// The rotation body → world.
    pub fn rotation(&self) -> UnitQuaternion {
        let [w, x, y, z] = self.orientation;
        UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(w, x, y, z))
    }

    /// The centroid in world coordinates.
    pub fn centre(&self) -> Point {
        Point::new(self.position[0], self.position[1], self.position[2])
    }

    /// A body-frame point in world coordinates.
    pub fn to_world(&self, point_in_body: &Point) -> Point {
        self.centre() + self.rotation() * point_in_body.coords
    }

    /// A world point in the body frame.
    pub fn to_body(&self, point_in_world: &Point) -> Point {
        Point::from(self.rotation().inverse() * (point_in_world - self.centre()))
    }

    /// The body z axis (the symmetry axis) in world coordinates.
    pub fn axis(&self) -> Vector {
        self.rotation() * Vector::z()
    }
}

/// A tube with pellets in it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Bed {
    /// The container.
    pub tube: Tube,
    /// The pellet types (usually one).
    pub pellet_types: Vec<Pellet>,
    /// Every pellet's type and pose.
    pub pellets: Vec<PlacedPellet>,
}

impl Bed {
    /// Checks indices, unit quaternions and finite coordinates.
    pub fn validate(&self) -> Result<(), GeomError> {
        if !(self.tube.diameter.is_finite() && self.tube.diameter > 0.0) {
            return Err(GeomError::BadParameter(format!(
                "tube diameter {} mm is not > 0",
                shown(self.tube.diameter * 1e3)
            )));
        }
        if let Some(lid) = self.tube.lid_height.filter(|h| !(h.is_finite() && *h > 0.0)) {
            return Err(GeomError::BadParameter(format!("lid height {} mm is not > 0", shown(lid * 1e3))));
        }
        for (i, p) in self.pellets.iter().enumerate() {
            if p.type_index as usize >= self.pellet_types.len() {
                return Err(GeomError::BadParameter(format!(
                    "pellet {i} has type {} but the bed has {} pellet types",
                    p.type_index,
                    self.pellet_types.len()
                )));
            }
            if !p.position.iter().chain(p.orientation.iter()).all(|c| c.is_finite()) {
                return Err(GeomError::BadParameter(format!("pellet {i} has a non-finite pose")));
            }
            let norm = p.orientation.iter().map(|c| c * c).sum::<Real>().sqrt();
            if (norm - 1.0).abs() > 1e-6 {
                return Err(GeomError::BadParameter(format!(
                    "pellet {i}'s quaternion has norm {}, not 1",
                    shown(norm)
                )));
            }
        }
        Ok(())
    }
}
