//! The catalogue of pellet shapes and the checks on their parameters.
//!
//! Parameters are in millimetres, as users type them; every check names
//! the `mkpellet` flag and the allowed range in its error.

use serde::{Deserialize, Serialize};

use crate::math::Real;
use crate::GeomError;

/// A pellet shape and its parameters (lengths in mm).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum ShapeSpec {
    /// A sphere.
    Sphere {
        /// Diameter (mm).
        diameter_mm: Real,
    },
    /// A solid cylinder.
    Cylinder {
        /// Diameter (mm).
        diameter_mm: Real,
        /// Height (mm).
        height_mm: Real,
    },
    /// A Raschig ring (hollow cylinder).
    Ring {
        /// Outer diameter (mm).
        outer_diameter_mm: Real,
        /// Inner (hole) diameter (mm).
        inner_diameter_mm: Real,
        /// Height (mm).
        height_mm: Real,
    },
    /// A multi-lobe extrudate (trilobe: 3, quadrilobe: 4): the union of
    /// `lobes` circles of the lobe diameter whose outer edges touch a circle
    /// of diameter `size`.
    Lobed {
        /// Number of lobes (3–8).
        lobes: u32,
        /// Diameter of each lobe (mm).
        lobe_diameter_mm: Real,
        /// Overall size: diameter of the circumscribed circle (mm).
        size_mm: Real,
        /// Height (mm).
        height_mm: Real,
    },
    /// A cylinder with axial holes: optionally one on the axis, the rest
    /// equally spaced on the pitch circle.
    MultiHole {
        /// Outer diameter (mm).
        diameter_mm: Real,
        /// Height (mm).
        height_mm: Real,
        /// Total number of holes.
        holes: u32,
        /// Whether one of the holes is on the axis.
        center_hole: bool,
        /// Diameter of every hole (mm).
        hole_diameter_mm: Real,
        /// Diameter of the circle the off-axis hole centres lie on (mm).
        pitch_diameter_mm: Real,
    },
    /// A user's closed triangle mesh.
    UserMesh {
        /// File the mesh came from (as given).
        source: String,
        /// Length unit of that file.
        unit: String,
    },
}

/// The lengths a pellet may have (mm): its size, and each dimension given for it. Beyond them
/// the meshing and the engine's double precision fail with messages about hulls and
/// non-finite states instead of about the size.
pub const SIZE_RANGE_MM: (Real, Real) = (1e-3, 1e4);

fn positive(flag: &str, value: Real) -> Result<(), GeomError> {
    let (lo, hi) = SIZE_RANGE_MM;
    if value.is_finite() && (lo..=hi).contains(&value) {
        Ok(())
    } else if value.is_finite() && value > 0.0 {
        Err(GeomError::BadParameter(format!("{flag} must be between {lo} and {hi} mm (got {value:e} mm)")))
    } else {
        Err(GeomError::BadParameter(format!("{flag} must be a finite number > 0 mm (got {value})")))
    }
}

/// Smallest wall left between holes, or between a hole and the outside,
/// as a fraction of the outer diameter: thinner walls cannot be meshed.
pub const MIN_LIGAMENT_FRACTION: Real = 0.02;

impl ShapeSpec {
    /// Short name of the shape kind.
    pub fn kind(&self) -> &'static str {
        match self {
            ShapeSpec::Sphere { .. } => "sphere",
            ShapeSpec::Cylinder { .. } => "cylinder",
            ShapeSpec::Ring { .. } => "ring",
            ShapeSpec::Lobed { lobes: 3, .. } => "trilobe",
            ShapeSpec::Lobed { lobes: 4, .. } => "quadrilobe",
            ShapeSpec::Lobed { .. } => "multilobe",
            ShapeSpec::MultiHole { .. } => "multihole",
            ShapeSpec::UserMesh { .. } => "mesh",
        }
    }

    /// Number of through-holes (the genus of the surface).
    pub fn genus(&self) -> Option<u32> {
        match self {
            ShapeSpec::Ring { .. } => Some(1),
            ShapeSpec::MultiHole { holes, .. } => Some(*holes),
            ShapeSpec::UserMesh { .. } => None,
            _ => Some(0),
        }
    }

    /// Checks every parameter; the error names the flag and the allowed range.
    pub fn validate(&self) -> Result<(), GeomError> {
        match *self {
            ShapeSpec::Sphere { diameter_mm } => positive("--diameter", diameter_mm),
            ShapeSpec::Cylinder { diameter_mm, height_mm } => {
                positive("--diameter", diameter_mm)?;
                positive("--height", height_mm)
            }
            ShapeSpec::Ring { outer_diameter_mm, inner_diameter_mm, height_mm } => {
                positive("--outer-diameter", outer_diameter_mm)?;
                positive("--inner-diameter", inner_diameter_mm)?;
                positive("--height", height_mm)?;
                if inner_diameter_mm >= outer_diameter_mm {
                    return Err(GeomError::BadParameter(format!(
                        "--inner-diameter must be smaller than --outer-diameter {outer_diameter_mm} mm \
                         (got {inner_diameter_mm} mm; equivalently --wall must be < half the outer diameter)"
                    )));
                }
                if outer_diameter_mm - inner_diameter_mm < 2.0 * MIN_LIGAMENT_FRACTION * outer_diameter_mm {
                    return Err(GeomError::BadParameter(format!(
                        "the ring wall ({} mm) must be at least {}% of the outer diameter",
                        0.5 * (outer_diameter_mm - inner_diameter_mm),
                        MIN_LIGAMENT_FRACTION * 100.0
                    )));
                }
                Ok(())
            }
            ShapeSpec::Lobed { lobes, lobe_diameter_mm, size_mm, height_mm } => {
                if !(3..=8).contains(&lobes) {
                    return Err(GeomError::BadParameter(format!("--lobes must be 3 to 8 (got {lobes})")));
                }
                positive("--lobe-diameter", lobe_diameter_mm)?;
                positive("--size", size_mm)?;
                positive("--height", height_mm)?;
                // Lobe centres sit at c = (size − d)/2 from the axis; the lobes
                // cover the axis (a star-shaped section) iff c < d/2.
                if !(size_mm > lobe_diameter_mm * 1.05 && size_mm < 2.0 * lobe_diameter_mm) {
                    return Err(GeomError::BadParameter(format!(
                        "--size must lie between 1.05 × and 2 × --lobe-diameter, i.e. {:.4} to {:.4} mm \
                         so that the lobes overlap and cover the axis (got {size_mm} mm)",
                        1.05 * lobe_diameter_mm,
                        2.0 * lobe_diameter_mm
                    )));
                }
                Ok(())
            }
            ShapeSpec::MultiHole {
                diameter_mm,
                height_mm,
                holes,
                center_hole,
                hole_diameter_mm,
                pitch_diameter_mm,
            } => {
                positive("--diameter", diameter_mm)?;
                positive("--height", height_mm)?;
                positive("--hole-diameter", hole_diameter_mm)?;
                if !(1..=64).contains(&holes) {
                    return Err(GeomError::BadParameter(format!("--holes must be 1 to 64 (got {holes})")));
                }
                if !(pitch_diameter_mm.is_finite() && pitch_diameter_mm >= 0.0) {
                    return Err(GeomError::BadParameter(format!(
                        "--pitch-diameter must be a finite number ≥ 0 mm (got {pitch_diameter_mm})"
                    )));
                }
                let min_wall = MIN_LIGAMENT_FRACTION * diameter_mm;
                let (r_out, r_h, p) = (0.5 * diameter_mm, 0.5 * hole_diameter_mm, 0.5 * pitch_diameter_mm);
                let on_pitch = holes - u32::from(center_hole);
                let fail = |what: String| Err(GeomError::BadParameter(format!("holes do not fit: {what}")));
                if center_hole && r_out - r_h < min_wall {
                    return fail(format!("the axial hole (--hole-diameter {hole_diameter_mm} mm) leaves no wall inside --diameter {diameter_mm} mm"));
                }
                if on_pitch > 0 {
                    if r_out - (p + r_h) < min_wall {
                        return fail(format!(
                            "--pitch-diameter + --hole-diameter must be at most --diameter − {:.4} mm (got {} + {} mm for {diameter_mm} mm)",
                            2.0 * min_wall, pitch_diameter_mm, hole_diameter_mm
                        ));
                    }
                    if on_pitch == 1 && !center_hole {
                        return Ok(());
                    }
                    if p <= 0.0 {
                        return fail("--pitch-diameter must be > 0 mm when several holes are used".into());
                    }
                    if on_pitch >= 2 {
                        let gap = 2.0 * p * (std::f64::consts::PI / on_pitch as Real).sin() - 2.0 * r_h;
                        if gap < min_wall {
                            return fail(format!(
                                "{on_pitch} holes of {hole_diameter_mm} mm on a {pitch_diameter_mm} mm pitch circle leave a wall of {gap:.4} mm between neighbours (minimum {min_wall:.4} mm): enlarge --pitch-diameter or reduce --hole-diameter"
                            ));
                        }
                    }
                    if center_hole && p - 2.0 * r_h < min_wall {
                        return fail(format!(
                            "--pitch-diameter must exceed 2 × --hole-diameter + {:.4} mm to clear the axial hole (got {pitch_diameter_mm} mm)",
                            2.0 * min_wall
                        ));
                    }
                }
                Ok(())
            }
            ShapeSpec::UserMesh { .. } => Ok(()),
        }
    }

    /// Face count used when no resolution is given: the paper's counts for
    /// the cylinder (4400) and the Raschig ring (8008). For the sphere the
    /// paper's 3120 faces leave the inertia 0.61 % below the exact value
    /// (any inscribed polyhedron that fine does), so the default is 4400,
    /// which keeps volume, area and inertia within 0.5 %; `--faces 3120`
    /// gives the paper's mesh.
    pub fn default_faces(&self) -> usize {
        match self {
            ShapeSpec::Sphere { .. } => 4400,
            ShapeSpec::Cylinder { .. } => 4400,
            ShapeSpec::Ring { .. } => 8008,
            ShapeSpec::Lobed { .. } => 6000,
            ShapeSpec::MultiHole { holes, .. } => 6000 + 2000 * *holes as usize,
            ShapeSpec::UserMesh { .. } => 0,
        }
    }
}
