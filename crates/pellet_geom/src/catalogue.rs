//! Builds the catalogue shapes: control mesh, closed form and convex pieces.

use crate::extrude::{triangulate_region, Arc, Profile};
use crate::math::{Real, Vector2};
use crate::pieces::{merge_into_quads, polygon_radius_factor, prisms, ring_sectors, ConvexPiece};
use crate::sdf::ClosedForm;
use crate::shape_spec::ShapeSpec;
use crate::subdivision::FeatureMesh;
use crate::{sphere, GeomError};

const MM: Real = 1e-3;

/// Sectors of a ring's convex decomposition: 32 keeps the chord sliver in
/// the hole below 0.5 % of the inner radius.
pub const RING_SECTORS: usize = 32;

/// The cross-section of an extruded catalogue shape, in metres, and its height.
fn profile(spec: &ShapeSpec) -> Option<(Profile, Real)> {
    let circle = |c: Vector2, d_mm: Real, ccw: bool| Arc::circle(c, 0.5 * d_mm * MM, ccw);
    let origin = Vector2::zeros();
    Some(match *spec {
        ShapeSpec::Cylinder { diameter_mm, height_mm } => {
            (Profile { outer: vec![circle(origin, diameter_mm, true)], holes: vec![] }, height_mm * MM)
        }
        ShapeSpec::Ring { outer_diameter_mm, inner_diameter_mm, height_mm } => (
            Profile {
                outer: vec![circle(origin, outer_diameter_mm, true)],
                holes: vec![vec![circle(origin, inner_diameter_mm, false)]],
            },
            height_mm * MM,
        ),
        ShapeSpec::Lobed { lobes, lobe_diameter_mm, size_mm, height_mm } => (
            Profile { outer: lobe_arcs(lobes as usize, lobe_diameter_mm * MM, size_mm * MM), holes: vec![] },
            height_mm * MM,
        ),
        ShapeSpec::MultiHole { diameter_mm, height_mm, holes, center_hole, hole_diameter_mm, pitch_diameter_mm } => {
            let holes = hole_centres(holes, center_hole, pitch_diameter_mm * MM)
                .into_iter()
                .map(|c| vec![circle(c, hole_diameter_mm, false)])
                .collect();
            (Profile { outer: vec![circle(origin, diameter_mm, true)], holes }, height_mm * MM)
        }
        _ => return None,
    })
}

/// Centres of a multi-hole pellet's holes (m).
fn hole_centres(holes: u32, center_hole: bool, pitch_diameter: Real) -> Vec<Vector2> {
    let mut out = Vec::new();
    if center_hole {
        out.push(Vector2::zeros());
    }
    let on_pitch = holes - u32::from(center_hole);
    for k in 0..on_pitch {
        let a = std::f64::consts::TAU * k as Real / on_pitch as Real;
        out.push(Vector2::new(a.cos(), a.sin()) * 0.5 * pitch_diameter);
    }
    out
}

fn lobe_centres(lobes: usize, lobe_diameter: Real, size: Real) -> Vec<Vector2> {
    let c = 0.5 * (size - lobe_diameter);
    (0..lobes)
        .map(|k| {
            let a = std::f64::consts::TAU * k as Real / lobes as Real;
            Vector2::new(a.cos(), a.sin()) * c
        })
        .collect()
}

/// The outer boundary of the union of the lobe circles: one arc per lobe
/// between its concave junctions with the neighbours.
fn lobe_arcs(lobes: usize, lobe_diameter: Real, size: Real) -> Vec<Arc> {
    let r = 0.5 * lobe_diameter;
    let centres = lobe_centres(lobes, lobe_diameter, size);
    // Junction k is the outer intersection of lobes k and k+1.
    let junction = |k: usize| -> Vector2 {
        let (a, b) = (centres[k], centres[(k + 1) % lobes]);
        let mid = (a + b) * 0.5;
        let half = (b - a).norm() * 0.5;
        mid.normalize() * (mid.norm() + (r * r - half * half).sqrt())
    };
    (0..lobes)
        .map(|k| {
            let c = centres[k];
            let from = junction((k + lobes - 1) % lobes) - c;
            let to = junction(k) - c;
            let start = from.y.atan2(from.x);
            let sweep = (to.y.atan2(to.x) - start).rem_euclid(std::f64::consts::TAU);
            Arc { center: c, radius: r, start, sweep }
        })
        .collect()
}

/// The control mesh of a catalogue shape at resolution `segments` (for a
/// sphere the number of Fibonacci points, otherwise the outer rim's edge count).
pub fn control_mesh(spec: &ShapeSpec, segments: usize) -> Result<FeatureMesh, GeomError> {
    match *spec {
        ShapeSpec::Sphere { diameter_mm } => sphere::control_mesh(0.5 * diameter_mm * MM, segments),
        _ => {
            let (profile, height) = profile(spec)
                .ok_or_else(|| GeomError::BadParameter(format!("a {} has no catalogue mesh", spec.kind())))?;
            profile.control_mesh(height, segments)
        }
    }
}

/// The control resolution (sphere: Fibonacci points; others: outer-rim
/// edges) whose mesh after `level` subdivisions has the
/// face count nearest to `target`.
pub fn choose_segments(spec: &ShapeSpec, level: u32, target: usize) -> Result<usize, GeomError> {
    let factor = 4usize.saturating_pow(level);
    if let ShapeSpec::Sphere { .. } = spec {
        // faces = (2n − 4)·4^level: solve for n and take the nearer neighbour.
        let n = (target / factor + 4) / 2;
        return Ok((n.max(sphere::MIN_POINTS)..=n.max(sphere::MIN_POINTS) + 2)
            .min_by_key(|&n| (sphere::control_faces(n) * factor).abs_diff(target))
            .unwrap_or(sphere::MIN_POINTS));
    }
    let mut best = (usize::MAX, 8);
    for segments in 8..=4096 {
        let faces = control_mesh(spec, segments)?.mesh.face_count() * factor;
        let miss = faces.abs_diff(target);
        if miss < best.0 {
            best = (miss, segments);
        }
        if faces > 2 * target {
            break;
        }
    }
    Ok(best.1)
}

/// The exact signed-distance description, for the shapes that have one.
pub fn closed_form(spec: &ShapeSpec) -> Option<ClosedForm> {
    match *spec {
        ShapeSpec::Sphere { diameter_mm } => Some(ClosedForm::Sphere { radius: 0.5 * diameter_mm * MM }),
        ShapeSpec::Cylinder { diameter_mm, height_mm } => {
            Some(ClosedForm::Cylinder { radius: 0.5 * diameter_mm * MM, half_height: 0.5 * height_mm * MM })
        }
        ShapeSpec::Ring { outer_diameter_mm, inner_diameter_mm, height_mm } => Some(ClosedForm::HollowCylinder {
            inner_radius: 0.5 * inner_diameter_mm * MM,
            outer_radius: 0.5 * outer_diameter_mm * MM,
            half_height: 0.5 * height_mm * MM,
        }),
        _ => None,
    }
}

/// Convex pieces whose union is the catalogue shape.
pub fn convex_pieces(spec: &ShapeSpec) -> Result<Vec<ConvexPiece>, GeomError> {
    let origin = crate::math::Point::origin();
    Ok(match *spec {
        ShapeSpec::Sphere { diameter_mm } => vec![ConvexPiece::Ball { center: origin, radius: 0.5 * diameter_mm * MM }],
        ShapeSpec::Cylinder { diameter_mm, height_mm } => vec![ConvexPiece::Cylinder {
            center: origin,
            radius: 0.5 * diameter_mm * MM,
            half_height: 0.5 * height_mm * MM,
        }],
        ShapeSpec::Ring { outer_diameter_mm, inner_diameter_mm, height_mm } => {
            ring_sectors(0.5 * inner_diameter_mm * MM, 0.5 * outer_diameter_mm * MM, 0.5 * height_mm * MM, RING_SECTORS)
        }
        // Overlapping lobe cylinders: their union is exactly the pellet.
        ShapeSpec::Lobed { lobes, lobe_diameter_mm, size_mm, height_mm } => {
            lobe_centres(lobes as usize, lobe_diameter_mm * MM, size_mm * MM)
                .into_iter()
                .map(|c| ConvexPiece::Cylinder {
                    center: crate::math::Point::new(c.x, c.y, 0.0),
                    radius: 0.5 * lobe_diameter_mm * MM,
                    half_height: 0.5 * height_mm * MM,
                })
                .collect()
        }
        ShapeSpec::MultiHole { diameter_mm, height_mm, holes, center_hole, hole_diameter_mm, pitch_diameter_mm } => {
            let polygon = |c: Vector2, r: Real, n: usize, ccw: bool| -> Vec<Vector2> {
                let k = polygon_radius_factor(n);
                (0..n)
                    .map(|i| {
                        let a = std::f64::consts::TAU * i as Real / n as Real;
                        let a = if ccw { a } else { -a };
                        c + Vector2::new(a.cos(), a.sin()) * r * k
                    })
                    .collect()
            };
            let mut loops = vec![polygon(Vector2::zeros(), 0.5 * diameter_mm * MM, 48, true)];
            for c in hole_centres(holes, center_hole, pitch_diameter_mm * MM) {
                loops.push(polygon(c, 0.5 * hole_diameter_mm * MM, 16, false));
            }
            let (points, triangles) = triangulate_region(&loops, None)?;
            prisms(&merge_into_quads(&points, &triangles), 0.5 * height_mm * MM)
        }
        ShapeSpec::UserMesh { .. } => {
            return Err(GeomError::BadParameter("user meshes are decomposed from their mesh".into()))
        }
    })
}
