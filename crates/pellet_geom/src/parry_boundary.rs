//! The one module that speaks parry3d-f64.
//!
//! parry 0.26+ uses glam math types; everything else in packbed uses the
//! nalgebra aliases of [`crate::math`]. Conversions happen here and
//! nowhere else, so a parry upgrade touches one file.

use parry3d_f64::math::{Pose, Vector as PVector};
use parry3d_f64::shape::SharedShape;
use parry3d_f64::transformation::vhacd::{VHACDParameters, VHACD};

use crate::math::Point;
use crate::mesh::TriMesh;
use crate::pieces::ConvexPiece;
use crate::GeomError;

fn to_parry(p: &Point) -> PVector {
    PVector::new(p.x, p.y, p.z)
}

fn from_parry(v: &PVector) -> Point {
    Point::new(v.x, v.y, v.z)
}

/// One piece as a positioned parry shape.
fn piece_shape(piece: &ConvexPiece) -> Result<(Pose, SharedShape), GeomError> {
    Ok(match piece {
        ConvexPiece::Ball { center, radius } => (Pose::from_translation(to_parry(center)), SharedShape::ball(*radius)),
        ConvexPiece::Cylinder { center, radius, half_height } => {
            // parry's cylinder axis is local y; a +90° turn about x takes y to z.
            let pose = Pose::new(to_parry(center), PVector::new(std::f64::consts::FRAC_PI_2, 0.0, 0.0));
            (pose, SharedShape::cylinder(*half_height, *radius))
        }
        ConvexPiece::Hull { points } => {
            let pts: Vec<PVector> = points.iter().map(to_parry).collect();
            let shape = SharedShape::convex_hull(&pts)
                .ok_or_else(|| GeomError::Meshing(format!("a convex piece of {} points is degenerate", pts.len())))?;
            (Pose::IDENTITY, shape)
        }
    })
}

/// The pieces as one parry compound shape in the body frame.
pub fn compound(pieces: &[ConvexPiece]) -> Result<SharedShape, GeomError> {
    if pieces.is_empty() {
        return Err(GeomError::Meshing("a pellet needs at least one convex piece".into()));
    }
    let parts = pieces.iter().map(piece_shape).collect::<Result<Vec<_>, _>>()?;
    Ok(SharedShape::compound(parts))
}

/// Point containment against the union of convex pieces.
pub struct PieceSet {
    shape: SharedShape,
}

impl PieceSet {
    /// Builds the parry compound of `pieces`.
    pub fn new(pieces: &[ConvexPiece]) -> Result<Self, GeomError> {
        Ok(PieceSet { shape: compound(pieces)? })
    }

    /// Whether `p` (body frame) lies in some piece.
    pub fn contains(&self, p: &Point) -> bool {
        self.shape.contains_local_point(to_parry(p))
    }
}

/// The convex hull of the points as a closed outward mesh.
pub fn convex_hull(points: &[Point]) -> Result<TriMesh, GeomError> {
    let pts: Vec<PVector> = points.iter().map(to_parry).collect();
    let (vertices, triangles) = parry3d_f64::transformation::try_convex_hull(&pts)
        .map_err(|e| GeomError::Meshing(format!("convex hull failed: {e:?}")))?;
    Ok(TriMesh { vertices: vertices.iter().map(from_parry).collect(), triangles })
}

/// V-HACD convex decomposition of a closed mesh (parry's implementation),
/// each part as the exact hull of the mesh triangles it holds.
pub fn convex_decomposition(mesh: &TriMesh, resolution: u32, max_hulls: u32) -> Vec<ConvexPiece> {
    let pts: Vec<PVector> = mesh.vertices.iter().map(to_parry).collect();
    let params = VHACDParameters { resolution, max_convex_hulls: max_hulls, ..VHACDParameters::default() };
    let decomposition = VHACD::decompose(&params, &pts, &mesh.triangles, true);
    decomposition
        .compute_exact_convex_hulls(&pts, &mesh.triangles)
        .into_iter()
        .filter(|(v, _)| v.len() >= 4)
        .map(|(v, _)| ConvexPiece::Hull { points: v.iter().map(from_parry).collect() })
        .collect()
}
