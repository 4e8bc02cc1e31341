//! Catalogue shapes against analytic formulas, topology and collision pieces.

use std::f64::consts::PI;

use pellet_geom::math::{Point, Real};
use pellet_geom::parry_boundary::PieceSet;
use pellet_geom::{MassProperties, Pellet, Resolution, ShapeSpec};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

const MM: Real = 1e-3;

/// Exact volume, area, and (axial, transverse) inertia per unit density, SI.
struct Exact {
    volume: Real,
    area: Real,
    izz: Real,
    ixx: Real,
}

fn exact(spec: &ShapeSpec) -> Exact {
    match *spec {
        ShapeSpec::Sphere { diameter_mm } => {
            let r = 0.5 * diameter_mm * MM;
            let v = 4.0 / 3.0 * PI * r.powi(3);
            Exact { volume: v, area: 4.0 * PI * r * r, izz: 0.4 * v * r * r, ixx: 0.4 * v * r * r }
        }
        ShapeSpec::Cylinder { diameter_mm, height_mm } => ring(0.0, 0.5 * diameter_mm * MM, height_mm * MM),
        ShapeSpec::Ring { outer_diameter_mm, inner_diameter_mm, height_mm } => {
            ring(0.5 * inner_diameter_mm * MM, 0.5 * outer_diameter_mm * MM, height_mm * MM)
        }
        _ => unreachable!("no closed form in this test"),
    }
}

fn ring(ri: Real, ro: Real, h: Real) -> Exact {
    let v = PI * (ro * ro - ri * ri) * h;
    Exact {
        volume: v,
        area: 2.0 * PI * (ro * ro - ri * ri) + 2.0 * PI * (ro + ri) * h,
        izz: 0.5 * v * (ro * ro + ri * ri),
        ixx: v * (3.0 * (ro * ro + ri * ri) + h * h) / 12.0,
    }
}

fn paper_shapes() -> Vec<ShapeSpec> {
    vec![
        ShapeSpec::Sphere { diameter_mm: 10.0 },
        ShapeSpec::Cylinder { diameter_mm: 10.0, height_mm: 10.0 },
        ShapeSpec::Ring { outer_diameter_mm: 10.0, inner_diameter_mm: 6.0, height_mm: 10.0 },
    ]
}

fn other_shapes() -> Vec<ShapeSpec> {
    vec![
        ShapeSpec::Lobed { lobes: 3, lobe_diameter_mm: 1.6, size_mm: 2.9, height_mm: 5.0 },
        ShapeSpec::Lobed { lobes: 4, lobe_diameter_mm: 1.5, size_mm: 2.8, height_mm: 5.0 },
        ShapeSpec::MultiHole {
            diameter_mm: 16.0,
            height_mm: 16.0,
            holes: 4,
            center_hole: false,
            hole_diameter_mm: 4.0,
            pitch_diameter_mm: 8.0,
        },
        ShapeSpec::MultiHole {
            diameter_mm: 16.0,
            height_mm: 10.0,
            holes: 7,
            center_hole: true,
            hole_diameter_mm: 2.8,
            pitch_diameter_mm: 9.0,
        },
    ]
}

fn rel(a: Real, b: Real) -> Real {
    (a / b - 1.0).abs()
}

fn errors(p: &MassProperties, e: &Exact) -> [Real; 4] {
    [
        rel(p.volume, e.volume),
        rel(p.area, e.area),
        rel(p.inertia[(2, 2)], e.izz),
        rel(p.inertia[(0, 0)], e.ixx).max(rel(p.inertia[(1, 1)], e.ixx)),
    ]
}

#[test]
fn paper_shapes_match_analytic_properties_at_default_resolution() {
    for spec in paper_shapes() {
        let pellet = Pellet::build(spec.clone(), Resolution::default()).unwrap();
        let errs = errors(&pellet.properties, &exact(&spec));
        for (what, err) in ["volume", "area", "Izz", "Ixx"].iter().zip(errs) {
            assert!(err < 0.005, "{}: {what} off by {:.4}%", spec.kind(), err * 100.0);
        }
        // Products of inertia vanish: to rounding for the prisms (built with
        // mirror symmetry), within the tolerance for the sphere's point set.
        let scale = pellet.properties.inertia[(2, 2)];
        let bound = if matches!(spec, ShapeSpec::Sphere { .. }) { 0.005 } else { 1e-9 };
        for (i, j) in [(0, 1), (0, 2), (1, 2)] {
            assert!(pellet.properties.inertia[(i, j)].abs() < bound * scale, "{} I{i}{j}", spec.kind());
        }
        // The body frame's origin is the centroid.
        assert!(pellet.properties.centroid.coords.norm() < 1e-15, "{:?}", pellet.properties.centroid);
    }
}

#[test]
fn default_face_counts_are_near_the_papers() {
    // The sphere's default is 4400, not the paper's 3120: see ShapeSpec::default_faces.
    for (spec, paper) in paper_shapes().into_iter().zip([4400usize, 4400, 8008]) {
        let faces = Pellet::build(spec.clone(), Resolution::default()).unwrap().mesh.face_count();
        assert!(faces.abs_diff(paper) as f64 <= 0.1 * paper as f64, "{}: {faces} faces, paper {paper}", spec.kind());
    }
}

#[test]
fn errors_shrink_as_the_resolution_grows() {
    for spec in paper_shapes() {
        let e = exact(&spec);
        let errs: Vec<[Real; 4]> = (1..=3)
            .map(|level| {
                errors(&Pellet::build(spec.clone(), Resolution { level, faces: None }).unwrap().properties, &e)
            })
            .collect();
        for k in 0..4 {
            assert!(
                errs[2][k] < errs[1][k] && errs[1][k] < errs[0][k],
                "{} property {k}: errors {:?} do not shrink with level",
                spec.kind(),
                errs.iter().map(|e| e[k]).collect::<Vec<_>>()
            );
        }
    }
}

#[test]
fn faces_flag_hits_the_requested_count() {
    let paper_sphere = Pellet::build(paper_shapes()[0].clone(), Resolution { level: 2, faces: Some(3120) }).unwrap();
    assert!(paper_sphere.mesh.face_count().abs_diff(3120) <= 64);
    for spec in paper_shapes().into_iter().chain(other_shapes()) {
        // Multi-hole pellets need more faces to resolve every hole.
        let targets = if spec.genus() > Some(1) { [12000usize, 40000] } else { [2000, 20000] };
        for target in targets {
            let faces =
                Pellet::build(spec.clone(), Resolution { level: 2, faces: Some(target) }).unwrap().mesh.face_count();
            assert!(
                faces.abs_diff(target) as f64 <= 0.35 * target as f64,
                "{}: asked for {target} faces, got {faces}",
                spec.kind()
            );
        }
    }
}

#[test]
fn meshes_are_closed_manifold_outward_with_the_right_genus() {
    for spec in paper_shapes().into_iter().chain(other_shapes()) {
        for level in 0..=2 {
            let pellet = Pellet::build(spec.clone(), Resolution { level, faces: None }).unwrap();
            let topo = pellet.mesh.check_closed().unwrap();
            let genus = spec.genus().unwrap() as i64;
            assert_eq!(topo.components, 1);
            assert_eq!(topo.euler_characteristic, 2 - 2 * genus, "{} level {level}", spec.kind());
            assert!(pellet.properties.volume > 0.0, "outward orientation");
            // Every triangle's normal points away from the interior: a point a
            // hair inside along the reversed normal is inside the mesh.
            for t in (0..pellet.mesh.face_count()).step_by(97) {
                let [a, b, c] = pellet.mesh.corners(t);
                let n = pellet.mesh.area_normal(t).normalize();
                let centre = Point::from((a.coords + b.coords + c.coords) / 3.0);
                assert!(pellet.mesh.contains(&(centre - n * 1e-6)), "{} face {t} points inward", spec.kind());
                assert!(!pellet.mesh.contains(&(centre + n * 1e-6)), "{} face {t}", spec.kind());
            }
        }
    }
}

#[test]
fn flat_faces_stay_flat_and_rims_stay_round() {
    let spec = ShapeSpec::Ring { outer_diameter_mm: 10.0, inner_diameter_mm: 6.0, height_mm: 10.0 };
    let pellet = Pellet::build(spec, Resolution { level: 3, faces: None }).unwrap();
    for v in &pellet.mesh.vertices {
        let rho = v.x.hypot(v.y);
        let on_cap = (v.z.abs() - 5e-3).abs() < 1e-12;
        let on_side = (rho - 5e-3).abs() < 1e-12 || (rho - 3e-3).abs() < 1e-12;
        assert!(on_cap || on_side, "vertex {v:?} is on no exact surface");
        assert!((3e-3 * (1.0 - 1e-12)..=5e-3 * (1.0 + 1e-12)).contains(&rho));
    }
}

/// Monte-Carlo volume of the pieces' union and agreement of point tests.
#[test]
fn convex_pieces_match_the_mesh() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for spec in paper_shapes().into_iter().chain(other_shapes()) {
        let pellet = Pellet::build(spec.clone(), Resolution::default()).unwrap();
        let pieces = PieceSet::new(&pellet.pieces).unwrap();
        let r = pellet.bounding_radius;
        let samples = 4000;
        let (mut in_mesh, mut in_pieces, mut disagree) = (0usize, 0usize, 0usize);
        for _ in 0..samples {
            let p = Point::new(rng.random_range(-r..r), rng.random_range(-r..r), rng.random_range(-r..r));
            let (a, b) = (pellet.contains(&p), pieces.contains(&p));
            in_mesh += a as usize;
            in_pieces += b as usize;
            disagree += (a != b) as usize;
        }
        let box_volume = 8.0 * r * r * r;
        let mc_mesh = box_volume * in_mesh as Real / samples as Real;
        // The mesh's own winding-number test against its exact volume: 4σ.
        let p = in_mesh as Real / samples as Real;
        let sigma = box_volume * (p * (1.0 - p) / samples as Real).sqrt();
        assert!((mc_mesh - pellet.properties.volume).abs() < 4.0 * sigma, "{}", spec.kind());
        // Points classified differently lie in the thin shell between the
        // faceted mesh and the pieces: under 1 % of the pellet's points.
        assert!(
            (disagree as Real) < 0.01 * in_mesh as Real + 3.0,
            "{}: {disagree} of {in_mesh} points disagree",
            spec.kind()
        );
        assert!(rel(in_pieces as Real, in_mesh as Real) < 0.02, "{}", spec.kind());
    }
}

#[test]
fn catalogue_piece_volumes_match_the_mesh_within_one_percent() {
    // Disjoint pieces: the sum of their volumes is the union's volume.
    for spec in [paper_shapes()[2].clone(), other_shapes()[2].clone(), other_shapes()[3].clone()] {
        let pellet = Pellet::build(spec.clone(), Resolution::default()).unwrap();
        let mut total = 0.0;
        for piece in &pellet.pieces {
            let pellet_geom::ConvexPiece::Hull { points } = piece else { panic!("hulls expected") };
            let hull = pellet_geom::parry_boundary::convex_hull(points).unwrap();
            total += MassProperties::of_mesh(&hull).unwrap().volume;
        }
        assert!(
            rel(total, pellet.properties.volume) < 0.01,
            "{}: pieces {total:e} vs mesh {:e}",
            spec.kind(),
            pellet.properties.volume
        );
    }
}

#[test]
fn closed_form_sdf_agrees_with_the_mesh() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    for spec in paper_shapes() {
        let pellet = Pellet::build(spec.clone(), Resolution::default()).unwrap();
        let sdf = pellet.closed_form.unwrap();
        let r = pellet.bounding_radius;
        for _ in 0..500 {
            let p = Point::new(rng.random_range(-r..r), rng.random_range(-r..r), rng.random_range(-r..r));
            let d = sdf.signed_distance(&p);
            // Far enough from the surface that faceting cannot flip the answer.
            if d.abs() > 0.01 * r {
                assert_eq!(d < 0.0, pellet.contains(&p), "{} at {p:?}", spec.kind());
            }
        }
    }
}

#[test]
fn same_input_gives_identical_meshes() {
    for spec in other_shapes() {
        let a = Pellet::build(spec.clone(), Resolution::default()).unwrap();
        let b = Pellet::build(spec, Resolution::default()).unwrap();
        assert_eq!(a, b);
    }
}

#[test]
fn bad_parameters_name_the_flag() {
    let cases: Vec<(ShapeSpec, &str)> = vec![
        (ShapeSpec::Sphere { diameter_mm: -1.0 }, "--diameter"),
        (ShapeSpec::Sphere { diameter_mm: f64::NAN }, "--diameter"),
        (ShapeSpec::Cylinder { diameter_mm: 10.0, height_mm: 0.0 }, "--height"),
        (ShapeSpec::Ring { outer_diameter_mm: 10.0, inner_diameter_mm: 12.0, height_mm: 10.0 }, "--inner-diameter"),
        (ShapeSpec::Lobed { lobes: 3, lobe_diameter_mm: 1.0, size_mm: 3.0, height_mm: 5.0 }, "--size"),
        (
            ShapeSpec::MultiHole {
                diameter_mm: 10.0,
                height_mm: 10.0,
                holes: 4,
                center_hole: false,
                hole_diameter_mm: 4.0,
                pitch_diameter_mm: 5.0,
            },
            "holes do not fit",
        ),
    ];
    for (spec, needle) in cases {
        let err = Pellet::build(spec.clone(), Resolution::default()).unwrap_err().to_string();
        assert!(err.contains(needle), "{spec:?}: {err}");
    }
}
