use super::*;
use pellet_geom::{Pellet, Resolution, ShapeSpec, Tube};

const MM: Real = 1e-3;

fn bed(spec: ShapeSpec, poses: &[([Real; 3], [Real; 4])], tube_mm: Real) -> Bed {
    let pellet = Pellet::build(spec, Resolution::default()).unwrap();
    Bed {
        tube: Tube { diameter: tube_mm * MM, lid_height: None },
        pellet_types: vec![pellet],
        pellets: poses
            .iter()
            .map(|(p, q)| PlacedPellet { type_index: 0, position: p.map(|c| c * MM), orientation: *q })
            .collect(),
    }
}

fn cylinder() -> ShapeSpec {
    ShapeSpec::Cylinder { diameter_mm: 10.0, height_mm: 10.0 }
}

/// The unit quaternion of a rotation by `angle` about `axis`.
fn about(axis: [Real; 3], angle: Real) -> [Real; 4] {
    let n = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
    let (s, c) = (0.5 * angle).sin_cos();
    [c, s * axis[0] / n, s * axis[1] / n, s * axis[2] / n]
}

const UP: [Real; 4] = [1.0, 0.0, 0.0, 0.0];

#[test]
fn spheres_overlapping_by_20_micrometres() {
    let b = bed(ShapeSpec::Sphere { diameter_mm: 10.0 }, &[([0.0, 0.0, 5.0], UP), ([1.0, 0.0, 14.9], UP)], 40.0);
    let d = (1.0 + 9.9f64 * 9.9).sqrt();
    let o = deepest_overlap(&b).unwrap().pellets.unwrap();
    assert!((o.depth - (10.0 - d) * MM).abs() < 1e-12, "{o:?}");
    // And exactly 20 µm along z.
    let b = bed(ShapeSpec::Sphere { diameter_mm: 10.0 }, &[([0.0, 0.0, 5.0], UP), ([0.0, 0.0, 14.98], UP)], 40.0);
    let o = deepest_overlap(&b).unwrap().pellets.unwrap();
    assert!((o.depth - 20e-6).abs() < 1e-12, "{o:?}");
    assert!((o.point.z - 9.99 * MM).abs() < 1e-12);
}

#[test]
fn a_sphere_on_a_cylinder_cap() {
    let sphere = Pellet::build(ShapeSpec::Sphere { diameter_mm: 8.0 }, Resolution::default()).unwrap();
    let mut b = bed(cylinder(), &[([0.0, 0.0, 5.0], UP)], 40.0);
    b.pellet_types.push(sphere);
    // The sphere's lowest point 30 µm into the cap, off the axis.
    b.pellets.push(PlacedPellet { type_index: 1, position: [1e-3, 2e-3, 13.97e-3], orientation: UP });
    let o = deepest_overlap(&b).unwrap().pellets.unwrap();
    assert!((o.depth - 30e-6).abs() < 1e-9, "{o:?}");
}

#[test]
fn crossed_cylinders_side_to_side() {
    // Axes along x and y, 2r − δ apart along z: the sides overlap by δ on the common normal.
    let lying_x = about([0.0, 1.0, 0.0], PI / 2.0);
    let lying_y = about([1.0, 0.0, 0.0], PI / 2.0);
    for delta in [1e-6, 20e-6, 0.3e-3] {
        let z = 5.0 + 10.0 - delta / MM;
        let b = bed(cylinder(), &[([0.0, 0.0, 5.0], lying_x), ([0.3, -0.2, z], lying_y)], 40.0);
        let o = deepest_overlap(&b).unwrap().pellets.unwrap();
        assert!((o.depth - delta).abs() < 1e-9, "δ {delta}: {o:?}");
    }
}

#[test]
fn stacked_cylinders_face_to_face() {
    let b = bed(cylinder(), &[([0.0, 0.0, 5.0], UP), ([6.0, 2.0, 14.95], UP)], 40.0);
    let o = deepest_overlap(&b).unwrap().pellets.unwrap();
    assert!((o.depth - 50e-6).abs() < 1e-12, "{o:?}");
}

/// A cylinder tilted by 30° about y whose lowest rim point lies at (0, 5 − ε, 10 − δ) mm,
/// just inside the top rim of an upright cylinder standing on the floor: the rims cross.
fn crossed_rims(delta: Real, eps: Real) -> Bed {
    let beta = PI / 6.0;
    let (s, c) = beta.sin_cos();
    let low = [0.0, 5.0 - eps, 10.0 - delta];
    // Centre = lowest point + h·axis − r·e1, axis (sin β, 0, cos β), e1 (cos β, 0, −sin β).
    let centre = [low[0] + 5.0 * s - 5.0 * c, low[1], low[2] + 5.0 * c + 5.0 * s];
    bed(cylinder(), &[([0.0, 0.0, 5.0], UP), (centre, about([0.0, 1.0, 0.0], beta))], 40.0)
}

/// The deepest point of either rim inside the other pellet, by 200 000 samples per rim
/// and golden-section search around the deepest sample.
fn rims_reference(b: &Bed) -> Real {
    let shape = b.pellet_types[0].closed_form.unwrap();
    let (r, h) = (5.0 * MM, 5.0 * MM);
    let mut deepest = Real::NEG_INFINITY;
    for (pa, pb) in [(&b.pellets[0], &b.pellets[1]), (&b.pellets[1], &b.pellets[0])] {
        for z in [h, -h] {
            let f = |phi: Real| {
                let w = pa.to_world(&Point::new(r * phi.cos(), r * phi.sin(), z));
                -shape.signed_distance(&pb.to_body(&w))
            };
            let n = 200_000;
            let step = TAU / n as Real;
            let k = (0..n).max_by(|&i, &j| f(i as Real * step).total_cmp(&f(j as Real * step))).unwrap();
            let (mut lo, mut hi) = ((k as Real - 1.0) * step, (k as Real + 1.0) * step);
            let g = 0.5 * (5f64.sqrt() - 1.0);
            for _ in 0..100 {
                let (x1, x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
                if f(x1) < f(x2) {
                    lo = x1;
                } else {
                    hi = x2;
                }
            }
            deepest = deepest.max(f(0.5 * (lo + hi)));
        }
    }
    deepest
}

#[test]
fn cylinders_whose_rims_cross() {
    for (delta, eps) in [(0.1, 0.05), (0.02, 0.01), (0.2, 0.15)] {
        let b = crossed_rims(delta, eps);
        let reference = rims_reference(&b);
        assert!(reference > 0.0 && reference < delta * MM, "δ {delta}, ε {eps}: {reference}");
        let o = deepest_overlap(&b).unwrap().pellets.unwrap();
        assert!((o.depth - reference).abs() < 1e-9, "δ {delta}, ε {eps}: {o:?} against {reference}");
    }
}

#[test]
fn rings_overlap_through_the_bore() {
    // A ring lying across the top of an upright ring, its side 40 µm below the top plane:
    // the lying ring's outer side dips into the upright ring's wall, not into its hole.
    let ring = ShapeSpec::Ring { outer_diameter_mm: 10.0, inner_diameter_mm: 6.0, height_mm: 10.0 };
    let lying = about([1.0, 0.0, 0.0], PI / 2.0);
    let b = bed(ring, &[([0.0, 0.0, 5.0], UP), ([0.0, 0.0, 9.96 + 5.0], lying)], 40.0);
    let o = deepest_overlap(&b).unwrap().pellets.unwrap();
    assert!((o.depth - 40e-6).abs() < 1e-9, "{o:?}");
}

#[test]
fn pellets_through_the_floor_and_the_wall() {
    // Upright, 7 µm through the floor.
    let b = bed(cylinder(), &[([0.0, 0.0, 4.993], UP)], 40.0);
    let o = deepest_overlap(&b).unwrap().boundary.unwrap();
    assert_eq!(o.boundary, Boundary::Floor);
    assert!((o.depth - 7e-6).abs() < 1e-12, "{o:?}");
    assert!(deepest_overlap(&b).unwrap().pellets.is_none());
    // Tilted by 40°: the lowest point is h cos β + r sin β below the centre.
    let beta: Real = 40f64.to_radians();
    let drop = 5.0 * beta.cos() + 5.0 * beta.sin();
    let b = bed(cylinder(), &[([3.0, 0.0, drop - 0.011], about([1.0, 1.0, 0.0], beta))], 40.0);
    let o = deepest_overlap(&b).unwrap().boundary.unwrap();
    assert!((o.depth - 11e-6).abs() < 1e-12, "{o:?}");
    // Tilted by 30° about y at x = 12 mm, 20 µm through the wall of a 40 mm tube: the
    // farthest point is x + h sin β + r cos β on the rim.
    let beta: Real = 30f64.to_radians();
    let x = 20.0 + 0.02 - 5.0 * beta.sin() - 5.0 * beta.cos();
    let b = bed(cylinder(), &[([x, 0.0, 20.0], about([0.0, 1.0, 0.0], beta))], 40.0);
    let o = deepest_overlap(&b).unwrap().boundary.unwrap();
    assert_eq!(o.boundary, Boundary::Wall);
    assert!((o.depth - 20e-6).abs() < 1e-12, "{o:?}");
    // Inside the tube: nothing.
    let b = bed(cylinder(), &[([0.0, 0.0, 6.0], UP)], 40.0);
    assert_eq!(deepest_overlap(&b).unwrap().boundary, None);
}

#[test]
fn user_meshes_have_no_closed_form() {
    let mut b = bed(cylinder(), &[([0.0, 0.0, 5.0], UP)], 40.0);
    b.pellet_types[0].closed_form = None;
    assert!(deepest_overlap(&b).is_none());
}
