//! The accuracy targets of the void-fraction analysis, on beds built in code with known geometry.

use std::f64::consts::PI;

use pellet_analysis::synthetic::{close_packed_spheres, random_placement, simple_cubic};
use pellet_analysis::{bulk_porosity, void_profile, Geometry, ProfileParams, VoidProfile};
use pellet_geom::{Bed, Pellet, PlacedPellet, Resolution, ShapeSpec, Tube};

const MM: f64 = 1e-3;

fn sphere(level: u32) -> Pellet {
    Pellet::build(ShapeSpec::Sphere { diameter_mm: 10.0 }, Resolution { level, faces: None }).unwrap()
}

fn cylinder() -> Pellet {
    Pellet::build(ShapeSpec::Cylinder { diameter_mm: 10.0, height_mm: 10.0 }, Resolution::default()).unwrap()
}

fn ring() -> Pellet {
    let spec = ShapeSpec::Ring { outer_diameter_mm: 10.0, inner_diameter_mm: 6.0, height_mm: 10.0 };
    Pellet::build(spec, Resolution::default()).unwrap()
}

fn single(pellet: Pellet, position_mm: [f64; 3], orientation: [f64; 4], tube_mm: f64) -> Bed {
    Bed {
        tube: Tube { diameter: tube_mm * MM, lid_height: None },
        pellet_types: vec![pellet],
        pellets: vec![PlacedPellet { type_index: 0, position: position_mm.map(|c| c * MM), orientation }],
    }
}

/// S_int(r) (m²) from a profile.
fn solid_area(p: &VoidProfile) -> Vec<f64> {
    let h = p.window.1 - p.window.0;
    p.radius.iter().zip(&p.void_fraction).map(|(r, e)| (1.0 - e) * 2.0 * PI * r * h).collect()
}

/// Midpoint rule with `n` points of `f` over [a, b].
fn midpoint(a: f64, b: f64, n: usize, f: impl Fn(f64) -> f64) -> f64 {
    let h = (b - a) / n as f64;
    (0..n).map(|k| f(a + (k as f64 + 0.5) * h)).sum::<f64>() * h
}

#[track_caller]
fn assert_within(profile: &VoidProfile, reference: impl Fn(f64) -> f64, what: &str) {
    let got = solid_area(profile);
    let want: Vec<f64> = profile.radius.iter().map(|&r| reference(r)).collect();
    let max = want.iter().copied().fold(0.0, f64::max);
    assert!(max > 0.0);
    for ((r, g), w) in profile.radius.iter().zip(&got).zip(&want) {
        assert!((g - w).abs() <= 0.005 * max, "{what}: r = {:.3} mm: S_int {g:e} vs {w:e} (max {max:e})", r / MM);
    }
}

#[test]
fn a_single_sphere_matches_an_independent_quadrature() {
    let (a, rho0) = (5.0 * MM, 8.0 * MM);
    let bed = single(sphere(2), [rho0 / MM, 0.0, 10.0], [1.0, 0.0, 0.0, 0.0], 30.0);
    let profile = void_profile(&bed, &ProfileParams::new((0.0, 15.0 * MM))).unwrap();
    let reference = |r: f64| {
        if r == 0.0 {
            return 0.0;
        }
        let c = ((r * r + rho0 * rho0 - a * a) / (2.0 * r * rho0)).clamp(-1.0, 1.0);
        let theta = c.acos();
        midpoint(-theta, theta, 20_000, |t| {
            let d2 = r * r + rho0 * rho0 - 2.0 * r * rho0 * t.cos();
            r * 2.0 * (a * a - d2).max(0.0).sqrt()
        })
    };
    assert_within(&profile, reference, "sphere");
}

#[test]
fn a_standing_cylinder_matches_its_closed_form() {
    let (a, h, rho0) = (5.0 * MM, 10.0 * MM, 6.0 * MM);
    let bed = single(cylinder(), [0.0, rho0 / MM, 5.0], [1.0, 0.0, 0.0, 0.0], 30.0);
    let profile = void_profile(&bed, &ProfileParams::new((0.0, 10.0 * MM))).unwrap();
    let reference = |r: f64| {
        if r == 0.0 {
            return 0.0;
        }
        let c = ((r * r + rho0 * rho0 - a * a) / (2.0 * r * rho0)).clamp(-1.0, 1.0);
        h * r * 2.0 * c.acos()
    };
    assert_within(&profile, reference, "standing cylinder");
}

#[test]
fn a_lying_cylinder_matches_an_independent_quadrature() {
    // Axis along world x (90° about y), resting on the floor.
    let (a, half, xc, yc) = (5.0 * MM, 5.0 * MM, 4.0 * MM, -3.0 * MM);
    let s = std::f64::consts::FRAC_1_SQRT_2;
    let bed = single(cylinder(), [xc / MM, yc / MM, 5.0], [s, 0.0, s, 0.0], 30.0);
    let profile = void_profile(&bed, &ProfileParams::new((0.0, 10.0 * MM))).unwrap();
    let reference = |r: f64| {
        midpoint(0.0, 2.0 * PI, 400_000, |t| {
            let (x, y) = (r * t.cos(), r * t.sin());
            if (x - xc).abs() > half {
                return 0.0;
            }
            r * 2.0 * (a * a - (y - yc).powi(2)).max(0.0).sqrt()
        })
    };
    assert_within(&profile, reference, "lying cylinder");
    // The window cuts the cylinder: only the part below z = 7 mm counts.
    let cut = void_profile(&bed, &ProfileParams::new((0.0, 7.0 * MM))).unwrap();
    let reference_cut = |r: f64| {
        midpoint(0.0, 2.0 * PI, 400_000, |t| {
            let (x, y) = (r * t.cos(), r * t.sin());
            let half_chord = (a * a - (y - yc).powi(2)).max(0.0).sqrt();
            if (x - xc).abs() > half || half_chord == 0.0 {
                return 0.0;
            }
            r * ((5.0 * MM + half_chord).min(7.0 * MM) - (5.0 * MM - half_chord)).max(0.0)
        })
    };
    assert_within(&cut, reference_cut, "lying cylinder cut at 7 mm");
}

#[test]
fn the_mesh_path_agrees_with_the_closed_form_to_the_faceting() {
    let s = (0.35f64).sin();
    let c = (0.35f64).cos();
    for pellet in [cylinder(), ring()] {
        let bed = single(pellet, [3.0, 2.0, 7.0], [c, s, 0.0, 0.0], 30.0);
        let exact = void_profile(&bed, &ProfileParams::new((0.0, 12.0 * MM))).unwrap();
        let mut params = ProfileParams::new((0.0, 12.0 * MM));
        params.geometry = Geometry::Mesh;
        let mesh = void_profile(&bed, &params).unwrap();
        let (e, m) = (solid_area(&exact), solid_area(&mesh));
        let max = e.iter().copied().fold(0.0, f64::max);
        for (k, (a, b)) in e.iter().zip(&m).enumerate() {
            assert!((a - b).abs() < 0.01 * max, "r = {:.2} mm: {a:e} vs mesh {b:e}", exact.radius[k] / MM);
        }
    }
}

/// Volume of a sphere (radius a, centre zc) between z0 and z1, from the cap formula.
fn sphere_in_slab(a: f64, zc: f64, z0: f64, z1: f64) -> f64 {
    let above = |z: f64| {
        let h = (a - (z - zc)).clamp(0.0, 2.0 * a);
        PI * h * h * (3.0 * a - h) / 3.0
    };
    above(z0) - above(z1)
}

fn analytic_sphere_porosity(bed: &Bed, window: (f64, f64)) -> f64 {
    let a = 5.0 * MM;
    let solid: f64 = bed.pellets.iter().map(|p| sphere_in_slab(a, p.position[2], window.0, window.1)).sum();
    let r = 0.5 * bed.tube.diameter;
    1.0 - solid / (PI * r * r * (window.1 - window.0))
}

#[test]
fn lattices_of_spheres_match_their_analytic_bulk_porosity() {
    // Simple cubic, touching spheres, 9 columns in a 40 mm tube, cut by the window.
    let cubic = simple_cubic(&sphere(3), 40.0 * MM, 10.0 * MM, 5);
    assert_eq!(cubic.pellets.len(), 45);
    // Close packed, 2 % gaps, in a 41 mm tube.
    let hex = close_packed_spheres(&sphere(3), 41.0 * MM, 10.2 * MM, 60);
    for (name, bed, window) in [("cubic", &cubic, (3.0 * MM, 41.5 * MM)), ("close packed", &hex, (2.0 * MM, 20.0 * MM))]
    {
        let analytic = analytic_sphere_porosity(bed, window);
        let exact = bulk_porosity(bed, window, Geometry::Auto).unwrap();
        assert!((exact.porosity - analytic).abs() < 1e-9, "{name}: {} vs {analytic}", exact.porosity);
        assert!(exact.cut > 0, "{name}: the window should cut spheres");
        // Clipping the 17 664-face mesh: within the mesh's volume deficit.
        let mesh = bulk_porosity(bed, window, Geometry::Mesh).unwrap();
        assert!((mesh.porosity - analytic).abs() < 0.001, "{name}: mesh {} vs {analytic}", mesh.porosity);
        let profile = void_profile(bed, &ProfileParams::new(window)).unwrap();
        let mean = profile.cross_section_mean();
        assert!((mean - analytic).abs() < 0.002, "{name}: ∫ε(r) {mean} vs analytic {analytic}");
    }
}

#[test]
fn the_integrated_profile_equals_the_bulk_porosity() {
    let lobed = ShapeSpec::Lobed { lobes: 3, lobe_diameter_mm: 5.0, size_mm: 9.5, height_mm: 8.0 };
    let trilobe = Pellet::build(lobed, Resolution::default()).unwrap();
    for (pellet, geometry) in [
        (sphere(2), Geometry::Auto),
        (cylinder(), Geometry::Auto),
        (ring(), Geometry::Auto),
        (ring(), Geometry::Mesh),
        (trilobe, Geometry::Auto),
    ] {
        let bed = random_placement(&pellet, 40.0 * MM, 60.0 * MM, 40, 7);
        assert!(bed.pellets.len() >= 10, "{}: {} pellets", pellet.shape.kind(), bed.pellets.len());
        let window = (4.0 * MM, 45.0 * MM);
        let mut params = ProfileParams::new(window);
        params.geometry = geometry;
        let profile = void_profile(&bed, &params).unwrap();
        let bulk = bulk_porosity(&bed, window, geometry).unwrap();
        let mean = profile.cross_section_mean();
        assert!(
            (mean - bulk.porosity).abs() < 0.002,
            "{} ({geometry:?}): ∫ε(r) {mean} vs bulk {}",
            pellet.shape.kind(),
            bulk.porosity
        );
        // The axial profile averages to the same number.
        let ax = &profile.axial;
        let axial_mean: f64 =
            ax.void_fraction.iter().zip(ax.edges.windows(2)).map(|(e, w)| e * (w[1] - w[0])).sum::<f64>()
                / (window.1 - window.0);
        assert!((axial_mean - mean).abs() < 1e-9, "axial {axial_mean} vs radial {mean}");
        assert_eq!(*profile.void_fraction.last().unwrap(), 1.0);
    }
}

#[test]
fn halving_the_steps_changes_the_profile_by_less_than_0_002() {
    // Lattices of standing and lying cylinders are the hard case: their
    // vertical faces make the line length jump with θ, in step around the circle.
    let s = std::f64::consts::FRAC_1_SQRT_2;
    let mut lying = simple_cubic(&cylinder(), 40.0 * MM, 10.2 * MM, 3);
    lying.pellets.iter_mut().for_each(|p| p.orientation = [s, 0.0, s, 0.0]);
    let beds = [
        (random_placement(&cylinder(), 40.0 * MM, 60.0 * MM, 40, 11), (4.0 * MM, 45.0 * MM)),
        (random_placement(&sphere(2), 40.0 * MM, 60.0 * MM, 40, 11), (4.0 * MM, 45.0 * MM)),
        (simple_cubic(&cylinder(), 40.0 * MM, 10.2 * MM, 3), (2.0 * MM, 28.0 * MM)),
        (lying, (2.0 * MM, 28.0 * MM)),
    ];
    for (bed, window) in beds {
        let pellet = &bed.pellet_types[0];
        let base = void_profile(&bed, &ProfileParams::new(window)).unwrap();
        let (dr, arc, _) = base.steps;
        let mut fine_r = ProfileParams::new(window);
        fine_r.radial_step = Some(dr / 2.0);
        let fine_r = void_profile(&bed, &fine_r).unwrap();
        let mut fine_arc = ProfileParams::new(window);
        fine_arc.arc_step = Some(arc / 2.0);
        let fine_arc = void_profile(&bed, &fine_arc).unwrap();
        let mut worst: f64 = 0.0;
        for (i, r) in base.radius.iter().enumerate() {
            let j =
                fine_r.radius.iter().position(|q| (q - r).abs() < 1e-12).expect("the halved grid holds every radius");
            worst = worst.max((fine_r.void_fraction[j] - base.void_fraction[i]).abs());
            worst = worst.max((fine_arc.void_fraction[i] - base.void_fraction[i]).abs());
        }
        assert!(worst < 0.002, "{}: halving a step moved ε(r) by {worst}", pellet.shape.kind());
    }
}

#[test]
fn the_wall_value_is_one_even_for_a_pellet_through_the_wall() {
    // A sphere whose centre is 1 mm from the wall of a 30 mm tube: half of it is outside.
    let bed = single(sphere(2), [14.0, 0.0, 5.0], [1.0, 0.0, 0.0, 0.0], 30.0);
    let profile = void_profile(&bed, &ProfileParams::new((0.0, 10.0 * MM))).unwrap();
    assert_eq!(*profile.void_fraction.last().unwrap(), 1.0);
    assert!(profile.void_fraction[profile.void_fraction.len() - 2] < 0.99);
}

#[test]
fn windows_outside_the_bed_and_zero_steps_are_refused() {
    let bed = single(sphere(2), [0.0, 0.0, 5.0], [1.0, 0.0, 0.0, 0.0], 30.0);
    for window in [(0.0, 11.0 * MM), (-MM, 5.0 * MM), (5.0 * MM, 5.0 * MM), (6.0 * MM, 2.0 * MM)] {
        let err = void_profile(&bed, &ProfileParams::new(window)).unwrap_err().to_string();
        assert!(err.contains("outside the bed"), "{err}");
    }
    let mut params = ProfileParams::new((0.0, 10.0 * MM));
    params.radial_step = Some(0.0);
    assert!(void_profile(&bed, &params).unwrap_err().to_string().contains("radial step"));
    params.radial_step = None;
    params.arc_step = Some(f64::NAN);
    assert!(void_profile(&bed, &params).unwrap_err().to_string().contains("arc step"));
}
