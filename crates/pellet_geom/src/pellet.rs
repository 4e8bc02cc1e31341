//! A pellet: shape parameters, surface mesh, mass properties and
//! collision geometry, everything the later tools need about one pellet type.

use serde::{Deserialize, Serialize};

use crate::catalogue;
use crate::mass::MassProperties;
use crate::math::{Point, Real};
use crate::mesh::{Topology, TriMesh};
use crate::parry_boundary;
use crate::pieces::ConvexPiece;
use crate::sdf::ClosedForm;
use crate::shape_spec::ShapeSpec;
use crate::GeomError;

/// How finely to mesh a catalogue shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Resolution {
    /// Loop subdivision levels applied to the control mesh.
    pub level: u32,
    /// Target face count; `None` for the shape's default (the paper's counts).
    pub faces: Option<usize>,
}

impl Resolution {
    /// Default number of Loop levels.
    pub const DEFAULT_LEVEL: u32 = 2;
}

impl Default for Resolution {
    fn default() -> Self {
        Resolution { level: Self::DEFAULT_LEVEL, faces: None }
    }
}

/// One pellet type. All lengths in metres, body frame: origin at the
/// centroid, symmetry axis (if any) along z.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Pellet {
    /// The shape and its parameters (mm).
    pub shape: ShapeSpec,
    /// Loop subdivision levels used (0 for user meshes).
    pub level: u32,
    /// Resolution parameter of the control mesh (Fibonacci points for
    /// spheres, outer-rim edges otherwise; 0 for user meshes).
    pub control_segments: u32,
    /// The closed, outward-oriented surface mesh (m).
    pub mesh: TriMesh,
    /// Volume, area, centroid, inertia per unit density (m-based units).
    pub properties: MassProperties,
    /// Exact signed distance, for sphere, cylinder and ring.
    pub closed_form: Option<ClosedForm>,
    /// Convex pieces whose union is the pellet (m).
    pub pieces: Vec<ConvexPiece>,
    /// Radius of a centroid-centred sphere enclosing the mesh and the pieces (m).
    pub bounding_radius: Real,
    /// Remarks made while building (e.g. a user mesh was re-centred).
    pub notes: Vec<String>,
}

impl Pellet {
    /// Whether the pellet is an exact sphere (its closed form, not a mesh that looks like one).
    pub fn is_sphere(&self) -> bool {
        matches!(self.closed_form, Some(ClosedForm::Sphere { .. }))
    }

    /// Meshes a catalogue shape.
    pub fn build(shape: ShapeSpec, resolution: Resolution) -> Result<Pellet, GeomError> {
        shape.validate()?;
        if resolution.level > 6 {
            return Err(GeomError::BadParameter(format!(
                "--level must be 0 to 6 (got {}); each level multiplies the faces by 4",
                resolution.level
            )));
        }
        if let Some(f) = resolution.faces {
            if !(20..=5_000_000).contains(&f) {
                return Err(GeomError::BadParameter(format!("--faces must be 20 to 5000000 (got {f})")));
            }
        }
        let target = resolution.faces.unwrap_or_else(|| shape.default_faces());
        // Without --faces the control mesh is the one for the default count
        // at the default level, and --level refines that same control mesh.
        let search_level = if resolution.faces.is_some() { resolution.level } else { Resolution::DEFAULT_LEVEL };
        let segments = catalogue::choose_segments(&shape, search_level, target)?;
        let control = catalogue::control_mesh(&shape, segments)?;
        let mesh = control.subdivided(resolution.level).mesh;
        let mut notes = Vec::new();
        let size = mesh_size(&mesh);
        let (lo, hi) = crate::shape_spec::SIZE_RANGE_MM;
        if !(size.is_finite() && (lo..=hi).contains(&(size * 1e3))) {
            return Err(GeomError::BadMesh(format!(
                "the mesh is {} mm across; a pellet must be {lo} to {hi} mm (is --unit right?)",
                size * 1e3
            )));
        }
        let topology = mesh.check_closed()?;
        if let Some(genus) = shape.genus() {
            if topology.components != 1 || topology.genus() != genus as i64 {
                return Err(GeomError::Meshing(format!(
                    "the {} mesh has genus {} in {} parts, expected genus {genus}: the resolution is too coarse for its features",
                    shape.kind(),
                    topology.genus(),
                    topology.components
                )));
            }
        }
        let properties = MassProperties::of_mesh(&mesh)?;
        let pieces = catalogue::convex_pieces(&shape)?;
        if resolution.level == 0 {
            notes.push("level 0: the unsubdivided control mesh".into());
        }
        Ok(Pellet {
            closed_form: catalogue::closed_form(&shape),
            bounding_radius: bounding_radius(&mesh, &pieces),
            shape,
            level: resolution.level,
            control_segments: segments as u32,
            mesh,
            properties,
            pieces,
            notes,
        })
    }

    /// A pellet from a user's closed mesh (already in metres). The mesh is
    /// re-centred on its centroid; an inside-out mesh is flipped.
    pub fn from_mesh(mut mesh: TriMesh, source: String, unit: String) -> Result<Pellet, GeomError> {
        let mut notes = Vec::new();
        let size = mesh_size(&mesh);
        let (lo, hi) = crate::shape_spec::SIZE_RANGE_MM;
        if !(size.is_finite() && (lo..=hi).contains(&(size * 1e3))) {
            return Err(GeomError::BadMesh(format!(
                "the mesh is {} mm across; a pellet must be {lo} to {hi} mm (is --unit right?)",
                size * 1e3
            )));
        }
        let topology = mesh.check_closed()?;
        // Moved to the origin first: the volume and centroid sum products of coordinates, which
        // far from the origin cancel to noise (a sphere 1e4 m out came out with sphericity 0.84).
        let shift = -bounding_box_centre(&mesh);
        mesh.translate(&shift);
        if topology.components != 1 {
            return Err(GeomError::BadMesh(format!(
                "the mesh has {} separate parts; a pellet must be one closed surface",
                topology.components
            )));
        }
        let properties = match MassProperties::of_mesh(&mesh) {
            Ok(p) => p,
            Err(_) => {
                mesh.flip();
                notes.push("the mesh was inside-out (normals pointing inward) and was flipped".into());
                MassProperties::of_mesh(&mesh)?
            }
        };
        let offset = -properties.centroid.coords;
        let moved = shift + offset;
        // Say so only when the move is visible at the precision printed (1 nm).
        if moved.norm() > 1e-9 {
            notes.push(format!(
                "re-centred on the centroid: moved by ({:.6}, {:.6}, {:.6}) mm",
                moved.x * 1e3,
                moved.y * 1e3,
                moved.z * 1e3
            ));
        }
        if offset.norm() > 0.0 {
            mesh.translate(&offset);
        }
        let properties = MassProperties::of_mesh(&mesh)?;
        let hull = parry_boundary::convex_hull(&mesh.vertices)?;
        let hull_volume = MassProperties::of_mesh(&hull).map(|p| p.volume).unwrap_or(Real::INFINITY);
        let pieces = if hull_volume <= properties.volume * 1.01 {
            vec![ConvexPiece::Hull { points: hull.vertices.clone() }]
        } else {
            notes.push(format!(
                "nonconvex (hull volume {:.2}% above the mesh's): convex pieces by V-HACD",
                (hull_volume / properties.volume - 1.0) * 100.0
            ));
            let pieces = parry_boundary::convex_decomposition(&mesh, 64, 32);
            // The hulls' summed volume bounds their union from above: say how
            // far the pieces may overfill the mesh (V-HACD hulls bloat).
            let summed: Real = pieces
                .iter()
                .filter_map(|p| match p {
                    ConvexPiece::Hull { points } => parry_boundary::convex_hull(points).ok(),
                    _ => None,
                })
                .filter_map(|h| MassProperties::of_mesh(&h).ok().map(|m| m.volume))
                .sum();
            notes.push(format!(
                "{} convex pieces whose volumes sum to {:.1}% of the mesh volume (an upper bound on their union)",
                pieces.len(),
                100.0 * summed / properties.volume
            ));
            pieces
        };
        if pieces.is_empty() {
            return Err(GeomError::Meshing("convex decomposition of the mesh produced no pieces".into()));
        }
        Ok(Pellet {
            shape: ShapeSpec::UserMesh { source, unit },
            level: 0,
            control_segments: 0,
            bounding_radius: bounding_radius(&mesh, &pieces),
            mesh,
            properties,
            closed_form: None,
            pieces,
            notes,
        })
    }

    /// Topology of the mesh (it was checked when the pellet was made).
    pub fn topology(&self) -> Result<Topology, GeomError> {
        self.mesh.check_closed()
    }

    /// Whether the body-frame point lies inside the pellet's mesh.
    pub fn contains(&self, p: &Point) -> bool {
        self.mesh.contains(p)
    }
}

fn bounding_radius(mesh: &TriMesh, pieces: &[ConvexPiece]) -> Real {
    let pieces_max = pieces
        .iter()
        .map(|p| match p {
            ConvexPiece::Ball { center, radius } => center.coords.norm() + radius,
            ConvexPiece::Cylinder { center, radius, half_height } => center.coords.norm() + radius.hypot(*half_height),
            ConvexPiece::Hull { points } => points.iter().map(|q| q.coords.norm()).fold(0.0, Real::max),
        })
        .fold(0.0, Real::max);
    mesh.max_radius().max(pieces_max)
}

/// Each axis's (min, max) over a mesh's vertices.
fn bounding_box(mesh: &TriMesh) -> [(Real, Real); 3] {
    std::array::from_fn(|k| {
        mesh.vertices
            .iter()
            .fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), v| (lo.min(v.coords[k]), hi.max(v.coords[k])))
    })
}

/// The largest extent of a mesh's bounding box (m).
fn mesh_size(mesh: &TriMesh) -> Real {
    bounding_box(mesh).iter().map(|(lo, hi)| hi - lo).fold(0.0, Real::max)
}

fn bounding_box_centre(mesh: &TriMesh) -> crate::math::Vector {
    let b = bounding_box(mesh);
    crate::math::Vector::new(0.5 * (b[0].0 + b[0].1), 0.5 * (b[1].0 + b[1].1), 0.5 * (b[2].0 + b[2].1))
}
