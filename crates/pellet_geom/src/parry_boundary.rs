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
use crate::sdf::ClosedForm;
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

/// A closed-form pellet placed in the world (body frame: origin at the centroid, axis along z).
#[derive(Clone, Copy, Debug)]
pub struct PlacedClosedForm {
    /// The shape.
    pub shape: ClosedForm,
    /// Centre (world, m).
    pub centre: Point,
    /// Body to world.
    pub rotation: UnitQuaternion,
}

/// A ring is queried as this many wedges about its axis, each the convex hull of its exact outer
/// arc and the chord of its bore: the chords cut into the bore by at most
/// r_in (1 − cos(π/128)) = 3·10⁻⁴ r_in (0.9 µm for a 3 mm bore), and nowhere else does a wedge
/// differ from the ring.
const RING_WEDGES: usize = 128;
/// Wedges per group: a group (the same hull over its wedges' arc) contains its wedges, so its
/// distance bounds theirs from below and the wedges of far groups are never queried.
const WEDGES_PER_GROUP: usize = 8;

/// One convex piece of a [`PlacedClosedForm`], in its body frame.
enum Piece {
    Ball(parry3d_f64::shape::Ball),
    /// parry's cylinder, axis along its local y.
    Cylinder(parry3d_f64::shape::Cylinder),
    Wedge(Wedge),
}

/// The convex hull of a ring's outer arc from angle `from` to `to` and of its bore's chord
/// between the same angles, from z = −h to h.
struct Wedge {
    outer: Real,
    half_height: Real,
    from: Real,
    to: Real,
    /// The outer arc's ends, then the chord's (x, y): computed once, as GJK asks for support
    /// points many times per query.
    corners: [(Real, Real); 4],
}

impl Wedge {
    fn new(inner: Real, outer: Real, half_height: Real, from: Real, to: Real) -> Self {
        let at = |r: Real, a: Real| (r * a.cos(), r * a.sin());
        let corners = [at(outer, from), at(outer, to), at(inner, from), at(inner, to)];
        Self { outer, half_height, from, to, corners }
    }
}

impl parry3d_f64::shape::SupportMap for Wedge {
    fn local_support_point(&self, d: PVector) -> PVector {
        let z = if d.z >= 0.0 { self.half_height } else { -self.half_height };
        let along = |c: &(Real, Real)| d.x * c.0 + d.y * c.1;
        let mut best = self.corners[0];
        for c in &self.corners[1..] {
            if along(c) > along(&best) {
                best = *c;
            }
        }
        // The arc's point furthest along d is at d's own angle when the arc holds it, else an end.
        let phi = d.y.atan2(d.x);
        if (phi - self.from).rem_euclid(std::f64::consts::TAU) <= self.to - self.from {
            let c = (self.outer * phi.cos(), self.outer * phi.sin());
            if along(&c) > along(&best) {
                best = c;
            }
        }
        PVector::new(best.0, best.1, z)
    }
}

impl parry3d_f64::shape::SupportMap for Piece {
    fn local_support_point(&self, d: PVector) -> PVector {
        match self {
            Piece::Ball(b) => b.local_support_point(d),
            Piece::Cylinder(c) => c.local_support_point(d),
            Piece::Wedge(w) => w.local_support_point(d),
        }
    }
}

/// A piece with its pose in the body frame and a bounding sphere (body centre, radius).
struct Posed {
    piece: Piece,
    pose: Pose,
    centre: Point,
    radius: Real,
}

/// The body's convex pieces as groups: (a group's piece, which contains the group's own pieces).
fn groups(shape: &ClosedForm) -> Vec<(Posed, Vec<Posed>)> {
    let single = |piece: Piece, pose: Pose, radius: Real| {
        vec![(Posed { piece, pose, centre: Point::origin(), radius }, Vec::new())]
    };
    match *shape {
        ClosedForm::Sphere { radius } => {
            single(Piece::Ball(parry3d_f64::shape::Ball::new(radius)), Pose::IDENTITY, radius)
        }
        ClosedForm::Cylinder { radius, half_height } => single(
            Piece::Cylinder(parry3d_f64::shape::Cylinder::new(half_height, radius)),
            // parry's cylinder axis is local y; a +90° turn about x takes y to z.
            Pose::new(PVector::ZERO, PVector::new(std::f64::consts::FRAC_PI_2, 0.0, 0.0)),
            radius.hypot(half_height),
        ),
        ClosedForm::HollowCylinder { inner_radius, outer_radius, half_height } => {
            let step = std::f64::consts::TAU / RING_WEDGES as Real;
            let wedge = |first: usize, count: usize| {
                let (from, to) = (step * first as Real, step * (first + count) as Real);
                let mid = 0.5 * (from + to);
                let r = 0.5 * (inner_radius + outer_radius);
                let centre = Point::new(r * mid.cos(), r * mid.sin(), 0.0);
                let w = Wedge::new(inner_radius, outer_radius, half_height, from, to);
                // The farthest points from the centre are corners: the arc bulges towards it.
                let reach = w.corners.iter().map(|&(x, y)| (x - centre.x).hypot(y - centre.y)).fold(0.0, Real::max);
                Posed { piece: Piece::Wedge(w), pose: Pose::IDENTITY, centre, radius: reach.hypot(half_height) }
            };
            (0..RING_WEDGES / WEDGES_PER_GROUP)
                .map(|g| {
                    let first = g * WEDGES_PER_GROUP;
                    (wedge(first, WEDGES_PER_GROUP), (first..first + WEDGES_PER_GROUP).map(|k| wedge(k, 1)).collect())
                })
                .collect()
        }
    }
}

impl PlacedClosedForm {
    fn pose(&self) -> Pose {
        let q = self.rotation.quaternion();
        Pose::from_parts(to_parry(&self.centre), parry3d_f64::math::Rotation::from_xyzw(q.i, q.j, q.k, q.w))
    }
}

/// The contact of two closed-form pellets by parry's query on their exact shapes (GJK, and EPA
/// where they overlap; a ring as 128 wedges, its contact the nearest or deepest of
/// its wedges'): (signed gap, the nearest point of each, the unit normal from `a` towards `b`),
/// or `None` when they are farther apart than `max_gap`.
pub fn closed_form_contact(
    a: &PlacedClosedForm,
    b: &PlacedClosedForm,
    max_gap: Real,
) -> Option<(Real, Point, Point, Vector)> {
    use parry3d_f64::query::contact::contact_support_map_support_map;
    let (pose_a, pose_b) = (a.pose(), b.pose());
    let query = |pa: &Posed, pb: &Posed, limit: Real| {
        let (wa, wb) = (pose_a * pa.pose, pose_b * pb.pose);
        // Bounding spheres first: most pairs of a ring's pieces are far apart.
        let apart = (from_parry(&(pose_a * to_parry(&pa.centre))) - from_parry(&(pose_b * to_parry(&pb.centre))))
            .norm()
            - pa.radius
            - pb.radius;
        if apart > limit {
            return None;
        }
        let mut c = contact_support_map_support_map(&wa.inv_mul(&wb), &pa.piece, &pb.piece, limit)?;
        c.transform_by_mut(&wa, &wb);
        Some(c)
    };
    let (ga, gb) = (groups(&a.shape), groups(&b.shape));
    let mut near: Vec<(Real, usize, usize)> = Vec::new();
    for (i, (pa, _)) in ga.iter().enumerate() {
        for (j, (pb, _)) in gb.iter().enumerate() {
            if let Some(c) = query(pa, pb, max_gap) {
                near.push((c.dist, i, j));
            }
        }
    }
    near.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut best: Option<parry3d_f64::query::Contact> = None;
    for (bound, i, j) in near {
        if best.is_some_and(|c| c.dist <= bound) {
            break;
        }
        // A group's own pieces, or the group itself when it is one piece.
        let (ga_i, gb_j) = (&ga[i], &gb[j]);
        let pieces_a: Vec<&Posed> = if ga_i.1.is_empty() { vec![&ga_i.0] } else { ga_i.1.iter().collect() };
        let pieces_b: Vec<&Posed> = if gb_j.1.is_empty() { vec![&gb_j.0] } else { gb_j.1.iter().collect() };
        for pa in &pieces_a {
            for pb in &pieces_b {
                // GJK is asked for no more than the best so far (never below 0: EPA takes overlaps).
                let limit = best.map_or(max_gap, |c| c.dist.max(0.0).min(max_gap));
                if let Some(c) = query(pa, pb, limit) {
                    if best.is_none_or(|b| c.dist < b.dist) {
                        best = Some(c);
                    }
                }
            }
        }
    }
    let c = best?;
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

#[cfg(test)]
mod tests {
    use super::*;

    fn ring(centre: Point, rotation: UnitQuaternion) -> PlacedClosedForm {
        PlacedClosedForm {
            shape: ClosedForm::HollowCylinder { inner_radius: 3e-3, outer_radius: 5e-3, half_height: 5e-3 },
            centre,
            rotation,
        }
    }

    #[test]
    fn rings_touch_at_their_sides_ends_and_bores() {
        let a = ring(Point::origin(), UnitQuaternion::identity());
        let near = |b: &PlacedClosedForm, gap: Real, normal: Vector, tolerance: Real, angle: Real| {
            let (g, p, q, n) = closed_form_contact(&a, b, 1e-3).expect("within 1 mm");
            assert!((g - gap).abs() < tolerance, "gap {g}");
            assert!(n.angle(&normal) <= angle, "normal {n:?}");
            assert!(((q - p).dot(&n) - g).abs() < 1e-9, "points {p:?} {q:?}");
        };
        near(&ring(Point::new(10.01e-3, 0.0, 0.0), UnitQuaternion::identity()), 1e-5, Vector::x(), 1e-9, 1e-6);
        near(&ring(Point::new(0.0, 0.0, 9.99e-3), UnitQuaternion::identity()), -1e-5, Vector::z(), 1e-9, 1e-6);
        // A ball in the bore, 0.01 mm from it at +x: the contact is on the bore, its normal
        // inwards; the wedges' chords may cut 0.9 µm into the bore and turn the normal by up to
        // half a wedge (π/128).
        let ball = PlacedClosedForm {
            shape: ClosedForm::Sphere { radius: 2.49e-3 },
            centre: Point::new(0.5e-3, 0.0, 0.0),
            rotation: UnitQuaternion::identity(),
        };
        near(&ball, 1e-5, -Vector::x(), 1e-6, std::f64::consts::PI / 128.0 + 1e-9);
        // Farther than asked for: none.
        let far = ring(Point::new(12e-3, 0.0, 0.0), UnitQuaternion::identity());
        assert!(closed_form_contact(&a, &far, 1e-3).is_none());
    }
}
