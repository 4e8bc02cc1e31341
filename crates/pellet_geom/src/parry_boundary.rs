//! The one module that speaks parry3d-f64.
//!
//! parry 0.26+ uses glam math types; everything else in packbed uses the
//! nalgebra aliases of [`crate::math`]. Conversions happen here and
//! nowhere else, so a parry upgrade touches one file.

use parry3d_f64::math::{Pose, Vector as PVector};
use parry3d_f64::shape::SharedShape;
use parry3d_f64::transformation::vhacd::{VHACDParameters, VHACD};

use crate::math::{Point, Real, UnitQuaternion, Vector};
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

/// A solid cylinder (axis along its body z, centred on its body origin) placed in the world.
#[derive(Clone, Copy, Debug)]
pub struct PlacedCylinder {
    /// Radius (m).
    pub radius: Real,
    /// Half of the height (m).
    pub half_height: Real,
    /// Centre (world, m).
    pub centre: Point,
    /// Body to world.
    pub rotation: UnitQuaternion,
}

impl PlacedCylinder {
    fn pose(&self) -> Pose {
        let q = self.rotation.quaternion();
        let body = Pose::from_parts(to_parry(&self.centre), parry3d_f64::math::Rotation::from_xyzw(q.i, q.j, q.k, q.w));
        // parry's cylinder axis is local y; a +90° turn about x takes y to z.
        body * Pose::new(PVector::ZERO, PVector::new(std::f64::consts::FRAC_PI_2, 0.0, 0.0))
    }
}

/// The contact of two solid cylinders by parry's query on their exact shapes (GJK, and EPA
/// where they overlap): (signed gap, the nearest point of each, the unit normal from `a`
/// towards `b`), or `None` when they are farther apart than `max_gap`.
pub fn cylinder_contact(a: &PlacedCylinder, b: &PlacedCylinder, max_gap: Real) -> Option<(Real, Point, Point, Vector)> {
    let shape = |c: &PlacedCylinder| parry3d_f64::shape::Cylinder::new(c.half_height, c.radius);
    let c = parry3d_f64::query::contact(&a.pose(), &shape(a), &b.pose(), &shape(b), max_gap).ok()??;
    let n = c.normal1;
    Some((c.dist, from_parry(&c.point1), from_parry(&c.point2), Vector::new(n.x, n.y, n.z)))
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

/// Signed distance to a closed outward mesh sampled on a regular grid (body frame): node
/// spacing `cell`, box = the mesh's bounding box grown by `margin` on every side. Distances
/// come from parry's point projection on the triangle mesh; the sign from its pseudo-normals
/// (negative inside). Returns (origin, nodes per axis, values with x fastest).
pub fn signed_distance_grid(
    mesh: &TriMesh,
    cell: Real,
    margin: Real,
) -> Result<(Point, [usize; 3], Vec<f32>), GeomError> {
    use parry3d_f64::query::PointQuery;
    use parry3d_f64::shape::{TriMesh as PTriMesh, TriMeshFlags};
    if !(cell > 0.0 && margin > 0.0) {
        return Err(GeomError::BadParameter(format!("sdf grid: cell {cell} and margin {margin} must be > 0")));
    }
    let pts: Vec<PVector> = mesh.vertices.iter().map(to_parry).collect();
    let tri = PTriMesh::with_flags(pts, mesh.triangles.clone(), TriMeshFlags::ORIENTED)
        .map_err(|e| GeomError::Meshing(format!("sdf grid: {e:?}")))?;
    let mut lo = Point::new(Real::INFINITY, Real::INFINITY, Real::INFINITY);
    let mut hi = -lo;
    for v in &mesh.vertices {
        for a in 0..3 {
            lo[a] = lo[a].min(v[a]);
            hi[a] = hi[a].max(v[a]);
        }
    }
    let mut dims = [0usize; 3];
    for a in 0..3 {
        lo[a] -= margin;
        dims[a] = ((hi[a] + margin - lo[a]) / cell).ceil() as usize + 1;
    }
    if dims.iter().product::<usize>() > 50_000_000 {
        return Err(GeomError::BadParameter(format!("sdf grid of {dims:?} nodes is too large; use a larger cell")));
    }
    let mut values = Vec::with_capacity(dims.iter().product());
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                let p = PVector::new(lo.x + cell * i as Real, lo.y + cell * j as Real, lo.z + cell * k as Real);
                let proj = tri.project_local_point(p, false);
                let d = (p - proj.point).length();
                values.push(if proj.is_inside { -d } else { d } as f32);
            }
        }
    }
    Ok((lo, dims, values))
}
