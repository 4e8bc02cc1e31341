//! The deepest overlap between the pellets of a bed, and between a pellet and the tube
//! (wall, floor, lid), measured on the exact closed-form shapes, independently of the
//! engine's contact code.
//!
//! The depth of an overlap of pellets A and B is the largest distance from a point of one
//! pellet's surface into the other, max over x ∈ ∂A of −sd_B(x) and the same with A and B
//! swapped, where sd is the exact signed distance of [`ClosedForm`]. Two spheres give
//! r_A + r_B − |c_A − c_B| in closed form. Otherwise each surface is cut into patches in
//! its own parameters (the caps as discs or annuli in ρ and φ, the sides and a ring's bore
//! in φ and z, and each rim circle in φ, since rims cross rims in most contacts between
//! cylinders) and the depth is maximised by branch and bound: sd_B is 1-Lipschitz, so a
//! cell of parameters whose image lies within s of its centre's image cannot be deeper
//! than −sd_B(centre) + s, and only cells that could beat the deepest point found so far
//! are split. The search is global up to a budget of evaluations per pair (a face resting
//! flat on a face is equally deep everywhere and cannot be bounded tighter than its cells);
//! a pattern search in the parameters then refines the deepest point until a step moves it
//! by under 1e-10 m. Only pairs whose bounding spheres overlap by more than the deepest
//! overlap found so far are searched, which bounds the work to the lens between them.
//!
//! The tube is exact: the lowest and highest points of a cylinder or ring are on a rim and
//! found in closed form; the point farthest from the tube axis is on a rim (the distance
//! from the axis is convex), found by sampling the rim and refining in φ.

use std::cmp::Ordering;
use std::collections::BinaryHeap;
use std::f64::consts::{PI, TAU};

use pellet_geom::math::{Matrix, Point, Real, Vector};
use pellet_geom::{Bed, ClosedForm, PlacedPellet};

/// Surface points evaluated per pair and direction before the search stops refining.
const BUDGET: usize = 6000;
/// The pattern search stops when its step moves a point by less than this (m).
const REFINE_STEP: Real = 1e-10;

/// The deepest overlap of two pellets.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Overlap {
    /// Depth (m): how far the deepest point of one surface lies inside the other pellet.
    pub depth: Real,
    /// The two pellets (indices into [`Bed::pellets`]), the lower index first.
    pub pellets: (usize, usize),
    /// The deepest point, world frame (m): on one pellet's surface, inside the other.
    pub point: Point,
}

/// The boundaries of the tube.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Boundary {
    /// The cylindrical wall at radius D/2.
    Wall,
    /// The floor z = 0.
    Floor,
    /// The lid, when the tube has one.
    Lid,
}

impl Boundary {
    /// Lower-case name, for reports.
    pub fn name(self) -> &'static str {
        match self {
            Boundary::Wall => "wall",
            Boundary::Floor => "floor",
            Boundary::Lid => "lid",
        }
    }
}

/// The deepest overlap of a pellet with the tube.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoundaryOverlap {
    /// Depth (m) of the pellet's farthest point beyond the boundary.
    pub depth: Real,
    /// The pellet (index into [`Bed::pellets`]).
    pub pellet: usize,
    /// Which boundary.
    pub boundary: Boundary,
    /// The pellet's farthest point beyond the boundary, world frame (m).
    pub point: Point,
}

/// The deepest overlaps of a bed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DeepestOverlap {
    /// Between two pellets; `None` when no two pellets overlap.
    pub pellets: Option<Overlap>,
    /// Between a pellet and the tube; `None` when every pellet is inside the tube.
    pub boundary: Option<BoundaryOverlap>,
    /// Pairs whose bounding spheres overlap (candidates for an overlap).
    pub candidate_pairs: usize,
}

/// The deepest pellet–pellet and pellet–tube overlaps of `bed` (all its pellets), on the
/// exact shapes (see the module documentation); `None` when a pellet type has no closed form.
pub fn deepest_overlap(bed: &Bed) -> Option<DeepestOverlap> {
    if bed.pellet_types.iter().any(|p| p.closed_form.is_none()) {
        return None;
    }
    let shape = |i: usize| bed.pellet_types[bed.pellets[i].type_index as usize].closed_form.unwrap();
    let n = bed.pellets.len();
    let reach: Vec<Real> = (0..n).map(|i| shape(i).bounding_radius()).collect();
    let max_reach = reach.iter().copied().fold(0.0, Real::max);
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| bed.pellets[a].position[2].total_cmp(&bed.pellets[b].position[2]));
    let mut best: Option<Overlap> = None;
    let mut candidate_pairs = 0;
    for (oi, &i) in order.iter().enumerate() {
        for &j in &order[oi + 1..] {
            let (pi, pj) = (&bed.pellets[i], &bed.pellets[j]);
            if pj.position[2] - pi.position[2] > 2.0 * max_reach {
                break;
            }
            let slack = reach[i] + reach[j] - (pi.centre() - pj.centre()).norm();
            if slack <= 0.0 {
                continue;
            }
            candidate_pairs += 1;
            // A point at depth d inside B is within B's bounding sphere by d: only pairs whose
            // spheres overlap by more than the deepest so far can beat it.
            let floor = best.map_or(0.0, |b| b.depth);
            if slack <= floor {
                continue;
            }
            if let Some((depth, point)) = pair_depth(&shape(i), pi, &shape(j), pj, floor) {
                best = Some(Overlap { depth, pellets: (i.min(j), i.max(j)), point });
            }
        }
    }
    let boundary = (0..n)
        .filter_map(|i| boundary_depth(&shape(i), &bed.pellets[i], bed, i))
        .max_by(|a, b| a.depth.total_cmp(&b.depth));
    Some(DeepestOverlap { pellets: best, boundary, candidate_pairs })
}

/// The overlap depth of two placed shapes and the deepest point, when deeper than `floor` (m).
pub(crate) fn pair_depth(
    a: &ClosedForm,
    pa: &PlacedPellet,
    b: &ClosedForm,
    pb: &PlacedPellet,
    floor: Real,
) -> Option<(Real, Point)> {
    if let (ClosedForm::Sphere { radius: ra }, ClosedForm::Sphere { radius: rb }) = (a, b) {
        let d = pb.centre() - pa.centre();
        let depth = ra + rb - d.norm();
        let unit = if d.norm() > 0.0 { d / d.norm() } else { Vector::z() };
        // Midway through the lens, on the line of centres.
        let point = pa.centre() + unit * (ra - 0.5 * depth);
        return (depth > floor).then_some((depth, point));
    }
    let one = deepest_into(a, pa, b, pb, floor);
    let floor = one.map_or(floor, |(d, _)| d);
    let other = deepest_into(b, pb, a, pa, floor);
    other.or(one)
}

/// The deepest point of `a`'s surface inside `b`, when deeper than `floor`.
fn deepest_into(
    a: &ClosedForm,
    pa: &PlacedPellet,
    b: &ClosedForm,
    pb: &PlacedPellet,
    floor: Real,
) -> Option<(Real, Point)> {
    // A's body frame into B's, as one matrix and offset.
    let inv = pb.rotation().inverse();
    let rot: Matrix = (inv * pa.rotation()).to_rotation_matrix().into_inner();
    let shift: Vector = inv * (pa.centre() - pb.centre());
    let depth = |p: &Point| -b.signed_distance(&Point::from(rot * p.coords + shift));
    let patches = patches(a);
    let mut heap = BinaryHeap::new();
    let mut best: Option<(Real, usize, Real, Real)> = None;
    let mut best_depth = floor;
    let mut evaluations = 0;
    let visit = |heap: &mut BinaryHeap<Cell>, best: &mut Option<_>, best_depth: &mut Real, cell: Cell| {
        if cell.value > *best_depth {
            *best_depth = cell.value;
            *best = Some((cell.value, cell.patch, cell.u, cell.v));
        }
        if cell.bound > *best_depth {
            heap.push(cell);
        }
    };
    for (k, patch) in patches.iter().enumerate() {
        let (u0, u1, v0, v1) = patch.domain();
        let (nu, nv) = patch.initial_cells();
        let (hu, hv) = (0.5 * (u1 - u0) / nu as Real, 0.5 * (v1 - v0) / nv as Real);
        for iu in 0..nu {
            for iv in 0..nv {
                let (u, v) = (u0 + (2 * iu + 1) as Real * hu, v0 + (2 * iv + 1) as Real * hv);
                let cell = Cell::new(patch, k, u, v, hu, hv, &depth);
                evaluations += 1;
                visit(&mut heap, &mut best, &mut best_depth, cell);
            }
        }
    }
    while let Some(cell) = heap.pop() {
        if cell.bound <= best_depth + REFINE_STEP || evaluations >= BUDGET {
            break;
        }
        let patch = &patches[cell.patch];
        let (eu, ev) = patch.extent(cell.u, cell.hu, cell.hv);
        // Split across the longer side in space, both when they are alike.
        let (su, sv) = (eu >= 0.5 * ev, ev >= 0.5 * eu && cell.hv > 0.0);
        let us: &[Real] = if su { &[-0.5, 0.5] } else { &[0.0] };
        let vs: &[Real] = if sv { &[-0.5, 0.5] } else { &[0.0] };
        let (hu, hv) = (if su { 0.5 * cell.hu } else { cell.hu }, if sv { 0.5 * cell.hv } else { cell.hv });
        for &du in us {
            for &dv in vs {
                let child = Cell::new(patch, cell.patch, cell.u + du * cell.hu, cell.v + dv * cell.hv, hu, hv, &depth);
                evaluations += 1;
                visit(&mut heap, &mut best, &mut best_depth, child);
            }
        }
    }
    let (value, k, u, v) = best?;
    let patch = &patches[k];
    let (value, u, v) = refine(patch, value, u, v, &depth);
    Some((value, pa.to_world(&patch.point(u, v))))
}

/// Pattern search from (u, v) on `patch`: steps of a fraction of a millimetre in space,
/// halved when no neighbour is deeper, down to [`REFINE_STEP`].
fn refine(
    patch: &Patch,
    mut value: Real,
    mut u: Real,
    mut v: Real,
    depth: &impl Fn(&Point) -> Real,
) -> (Real, Real, Real) {
    let scale = patch.scale();
    let (mut du, mut dv) = (1e-4 / scale.0, if scale.1 > 0.0 { 1e-4 / scale.1 } else { 0.0 });
    let (u0, u1, v0, v1) = patch.domain();
    while du * scale.0 + dv * scale.1 > REFINE_STEP {
        let mut moved = false;
        for (su, sv) in
            [(1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0), (1.0, 1.0), (-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0)]
        {
            let (nu, nv) = ((u + su * du).clamp(u0, u1), (v + sv * dv).clamp(v0, v1));
            let d = depth(&patch.point(nu, nv));
            if d > value {
                (value, u, v, moved) = (d, nu, nv, true);
            }
        }
        if !moved {
            du *= 0.5;
            dv *= 0.5;
        }
    }
    (value, u, v)
}

/// A box of surface parameters, centre (u, v) and half-widths (hu, hv), with the depth at
/// its centre and the bound on the depth anywhere in it.
struct Cell {
    bound: Real,
    value: Real,
    patch: usize,
    u: Real,
    v: Real,
    hu: Real,
    hv: Real,
}

impl Cell {
    fn new(patch: &Patch, k: usize, u: Real, v: Real, hu: Real, hv: Real, depth: &impl Fn(&Point) -> Real) -> Cell {
        let value = depth(&patch.point(u, v));
        let (eu, ev) = patch.extent(u, hu, hv);
        Cell { bound: value + eu + ev, value, patch: k, u, v, hu, hv }
    }
}

impl PartialEq for Cell {
    fn eq(&self, other: &Self) -> bool {
        self.bound == other.bound
    }
}
impl Eq for Cell {}
impl PartialOrd for Cell {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Cell {
    fn cmp(&self, other: &Self) -> Ordering {
        self.bound.total_cmp(&other.bound)
    }
}

/// A piece of a closed-form surface in the body frame, in two parameters (u, v) (one for a rim).
#[derive(Clone, Copy, Debug)]
enum Patch {
    /// A cap at height z: u = ρ from r0 to r1, v = φ.
    Disc { z: Real, r0: Real, r1: Real },
    /// A side (or a ring's bore) of radius r: u = φ, v = z from −h to h.
    Side { r: Real, h: Real },
    /// A rim circle of radius r at height z: u = φ.
    Rim { r: Real, z: Real },
    /// A sphere: u = polar angle, v = φ.
    Sphere { r: Real },
}

fn patches(shape: &ClosedForm) -> Vec<Patch> {
    match *shape {
        ClosedForm::Sphere { radius } => vec![Patch::Sphere { r: radius }],
        ClosedForm::Cylinder { radius: r, half_height: h } => vec![
            Patch::Rim { r, z: h },
            Patch::Rim { r, z: -h },
            Patch::Side { r, h },
            Patch::Disc { z: h, r0: 0.0, r1: r },
            Patch::Disc { z: -h, r0: 0.0, r1: r },
        ],
        ClosedForm::HollowCylinder { inner_radius: ri, outer_radius: ro, half_height: h } => vec![
            Patch::Rim { r: ro, z: h },
            Patch::Rim { r: ro, z: -h },
            Patch::Rim { r: ri, z: h },
            Patch::Rim { r: ri, z: -h },
            Patch::Side { r: ro, h },
            Patch::Side { r: ri, h },
            Patch::Disc { z: h, r0: ri, r1: ro },
            Patch::Disc { z: -h, r0: ri, r1: ro },
        ],
    }
}

impl Patch {
    /// (u0, u1, v0, v1).
    fn domain(&self) -> (Real, Real, Real, Real) {
        match *self {
            Patch::Disc { r0, r1, .. } => (r0, r1, 0.0, TAU),
            Patch::Side { h, .. } => (0.0, TAU, -h, h),
            Patch::Rim { .. } => (0.0, TAU, 0.0, 0.0),
            Patch::Sphere { .. } => (0.0, PI, 0.0, TAU),
        }
    }

    /// The first cells (u, v): about 1 to 2 mm on a 10 mm pellet.
    fn initial_cells(&self) -> (usize, usize) {
        match *self {
            Patch::Disc { .. } => (3, 24),
            Patch::Side { .. } => (24, 6),
            Patch::Rim { .. } => (48, 1),
            Patch::Sphere { .. } => (12, 24),
        }
    }

    /// Metres per unit of u and of v at their largest.
    fn scale(&self) -> (Real, Real) {
        match *self {
            Patch::Disc { r1, .. } => (1.0, r1),
            Patch::Side { r, .. } => (r, 1.0),
            Patch::Rim { r, .. } => (r, 0.0),
            Patch::Sphere { r } => (r, r),
        }
    }

    /// Bounds on how far, along u and along v, a point of the cell with centre u and
    /// half-widths (hu, hv) lies from the centre's point; their sum bounds the distance.
    fn extent(&self, u: Real, hu: Real, hv: Real) -> (Real, Real) {
        match *self {
            Patch::Disc { .. } => (hu, (u + hu) * hv),
            Patch::Side { r, .. } => (r * hu, hv),
            Patch::Rim { r, .. } => (r * hu, 0.0),
            Patch::Sphere { r } => (r * hu, r * hv),
        }
    }

    fn point(&self, u: Real, v: Real) -> Point {
        match *self {
            Patch::Disc { z, .. } => Point::new(u * v.cos(), u * v.sin(), z),
            Patch::Side { r, .. } => Point::new(r * u.cos(), r * u.sin(), v),
            Patch::Rim { r, z } => Point::new(r * u.cos(), r * u.sin(), z),
            Patch::Sphere { r } => Point::new(r * u.sin() * v.cos(), r * u.sin() * v.sin(), r * u.cos()),
        }
    }
}

/// The deepest overlap of pellet `i` with the tube's wall, floor and lid, if any.
fn boundary_depth(shape: &ClosedForm, pose: &PlacedPellet, bed: &Bed, i: usize) -> Option<BoundaryOverlap> {
    let c = pose.centre();
    let a = pose.axis();
    // The extreme points along ±z: on a rim, where the rim's radius points most along ±z
    // (any rim point when the axis is vertical).
    let extreme = |up: Real| -> Point {
        let dir = Vector::z() * up;
        match *shape {
            ClosedForm::Sphere { radius } => c + dir * radius,
            ClosedForm::Cylinder { radius, half_height }
            | ClosedForm::HollowCylinder { outer_radius: radius, half_height, .. } => {
                let across = dir - a * a.dot(&dir);
                let across = if across.norm() > 1e-12 { across / across.norm() } else { Vector::zeros() };
                c + a * (half_height * a.dot(&dir).signum()) + across * radius
            }
        }
    };
    let bottom = extreme(-1.0);
    let mut found = vec![BoundaryOverlap { depth: -bottom.z, pellet: i, boundary: Boundary::Floor, point: bottom }];
    if let Some(lid) = bed.tube.lid_height {
        let top = extreme(1.0);
        found.push(BoundaryOverlap { depth: top.z - lid, pellet: i, boundary: Boundary::Lid, point: top });
    }
    let radius = 0.5 * bed.tube.diameter;
    let far = farthest_from_axis(shape, pose);
    found.push(BoundaryOverlap {
        depth: far.coords.xy().norm() - radius,
        pellet: i,
        boundary: Boundary::Wall,
        point: far,
    });
    found.into_iter().filter(|b| b.depth > 0.0).max_by(|x, y| x.depth.total_cmp(&y.depth))
}

/// The point of a placed shape farthest from the tube axis (world z).
fn farthest_from_axis(shape: &ClosedForm, pose: &PlacedPellet) -> Point {
    let c = pose.centre();
    let (r, h) = match *shape {
        ClosedForm::Sphere { radius } => {
            let out = Vector::new(c.x, c.y, 0.0);
            let out = if out.norm() > 0.0 { out / out.norm() } else { Vector::x() };
            return c + out * radius;
        }
        ClosedForm::Cylinder { radius, half_height } => (radius, half_height),
        ClosedForm::HollowCylinder { outer_radius, half_height, .. } => (outer_radius, half_height),
    };
    let rims = [Patch::Rim { r, z: h }, Patch::Rim { r, z: -h }];
    let rho = |p: &Point| pose.to_world(p).coords.xy().norm();
    let mut best = (Real::NEG_INFINITY, 0, 0.0);
    for (k, rim) in rims.iter().enumerate() {
        for s in 0..720 {
            let phi = s as Real * TAU / 720.0;
            let d = rho(&rim.point(phi, 0.0));
            if d > best.0 {
                best = (d, k, phi);
            }
        }
    }
    let (value, k, phi) = best;
    let (_, phi, _) = refine(&rims[k], value, phi, 0.0, &rho);
    pose.to_world(&rims[k].point(phi, 0.0))
}

#[cfg(test)]
mod tests;
