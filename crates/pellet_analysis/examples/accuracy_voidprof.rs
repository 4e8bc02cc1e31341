//! The accuracy figures of the voidprof README, measured on beds built in code.
//!
//! ```sh
//! cargo run -p pellet_analysis --example accuracy_voidprof
//! ```

use std::f64::consts::PI;

use pellet_analysis::synthetic::{close_packed_spheres, random_placement, simple_cubic};
use pellet_analysis::{bulk_porosity, void_profile, Geometry, ProfileParams, VoidProfile};
use pellet_geom::{Bed, Pellet, PlacedPellet, Resolution, ShapeSpec, Tube};

const MM: f64 = 1e-3;

fn build(spec: ShapeSpec, level: u32) -> Pellet {
    Pellet::build(spec, Resolution { level, faces: None }).expect("pellet")
}

fn single(pellet: Pellet, position_mm: [f64; 3], orientation: [f64; 4]) -> Bed {
    Bed {
        tube: Tube { diameter: 30.0 * MM, lid_height: None },
        pellet_types: vec![pellet],
        pellets: vec![PlacedPellet { type_index: 0, position: position_mm.map(|c| c * MM), orientation }],
    }
}

fn midpoint(a: f64, b: f64, n: usize, f: impl Fn(f64) -> f64) -> f64 {
    let h = (b - a) / n as f64;
    (0..n).map(|k| f(a + (k as f64 + 0.5) * h)).sum::<f64>() * h
}

/// Largest |S_int − reference| over the radii, as a fraction of the largest reference S_int.
fn worst(p: &VoidProfile, reference: impl Fn(f64) -> f64) -> f64 {
    let h = p.window.1 - p.window.0;
    let got: Vec<f64> = p.radius.iter().zip(&p.void_fraction).map(|(r, e)| (1.0 - e) * 2.0 * PI * r * h).collect();
    let want: Vec<f64> = p.radius.iter().map(|&r| reference(r)).collect();
    let max = want.iter().copied().fold(0.0, f64::max);
    got.iter().zip(&want).map(|(g, w)| (g - w).abs()).fold(0.0, f64::max) / max
}

fn main() {
    let sphere = build(ShapeSpec::Sphere { diameter_mm: 10.0 }, 2);
    let cylinder = build(ShapeSpec::Cylinder { diameter_mm: 10.0, height_mm: 10.0 }, 2);
    let ring = build(ShapeSpec::Ring { outer_diameter_mm: 10.0, inner_diameter_mm: 6.0, height_mm: 10.0 }, 2);
    let trilobe = build(ShapeSpec::Lobed { lobes: 3, lobe_diameter_mm: 5.0, size_mm: 9.5, height_mm: 8.0 }, 2);
    let a = 5.0 * MM;

    println!("Single pellets, D = 30 mm, default resolution: max |S_int − reference| / max S_int");
    let rho0 = 8.0 * MM;
    let p = void_profile(
        &single(sphere.clone(), [8.0, 0.0, 10.0], [1.0, 0.0, 0.0, 0.0]),
        &ProfileParams::new((0.0, 0.015)),
    )
    .unwrap();
    let e = worst(&p, |r| {
        if r == 0.0 {
            return 0.0;
        }
        let t = ((r * r + rho0 * rho0 - a * a) / (2.0 * r * rho0)).clamp(-1.0, 1.0).acos();
        midpoint(-t, t, 20_000, |u| {
            r * 2.0 * (a * a - (r * r + rho0 * rho0 - 2.0 * r * rho0 * u.cos())).max(0.0).sqrt()
        })
    });
    println!("  sphere 10 mm at 8 mm from the axis (vs 20 000-point quadrature): {:.4} %", e * 100.0);
    let rho0 = 6.0 * MM;
    let p = void_profile(
        &single(cylinder.clone(), [0.0, 6.0, 5.0], [1.0, 0.0, 0.0, 0.0]),
        &ProfileParams::new((0.0, 0.010)),
    )
    .unwrap();
    let e = worst(&p, |r| {
        if r == 0.0 {
            return 0.0;
        }
        10.0 * MM * r * 2.0 * ((r * r + rho0 * rho0 - a * a) / (2.0 * r * rho0)).clamp(-1.0, 1.0).acos()
    });
    println!("  standing cylinder 10×10 mm at 6 mm (vs closed form): {:.4} %", e * 100.0);
    let s = std::f64::consts::FRAC_1_SQRT_2;
    let (xc, yc) = (4.0 * MM, -3.0 * MM);
    let p =
        void_profile(&single(cylinder.clone(), [4.0, -3.0, 5.0], [s, 0.0, s, 0.0]), &ProfileParams::new((0.0, 0.010)))
            .unwrap();
    let e = worst(&p, |r| {
        midpoint(0.0, 2.0 * PI, 400_000, |t| {
            let (x, y) = (r * t.cos(), r * t.sin());
            if (x - xc).abs() > a {
                return 0.0;
            }
            r * 2.0 * (a * a - (y - yc).powi(2)).max(0.0).sqrt()
        })
    });
    println!("  lying cylinder 10×10 mm (vs 400 000-point quadrature): {:.4} %", e * 100.0);

    println!("Lattices of 10 mm spheres cut by the window: bulk porosity against the analytic value");
    let fine = build(ShapeSpec::Sphere { diameter_mm: 10.0 }, 3);
    let cubic = simple_cubic(&fine, 40.0 * MM, 10.0 * MM, 5);
    let hex = close_packed_spheres(&fine, 41.0 * MM, 10.2 * MM, 60);
    for (name, bed, window) in
        [("simple cubic, D = 40", &cubic, (3.0 * MM, 41.5 * MM)), ("close packed, D = 41", &hex, (2.0 * MM, 20.0 * MM))]
    {
        let solid: f64 = bed
            .pellets
            .iter()
            .map(|q| {
                let above = |z: f64| {
                    let h = (a - (z - q.position[2])).clamp(0.0, 2.0 * a);
                    PI * h * h * (3.0 * a - h) / 3.0
                };
                above(window.0) - above(window.1)
            })
            .sum();
        let r = 0.5 * bed.tube.diameter;
        let analytic = 1.0 - solid / (PI * r * r * (window.1 - window.0));
        let exact = bulk_porosity(bed, window, Geometry::Auto).unwrap().porosity;
        let mesh = bulk_porosity(bed, window, Geometry::Mesh).unwrap().porosity;
        let profile = void_profile(bed, &ProfileParams::new(window)).unwrap().cross_section_mean();
        println!(
            "  {name}: analytic {analytic:.6}; exact clip {:.1e}, mesh clip (17 664 faces) {:.1e}, ∫ε(r) {:.1e}",
            (exact - analytic).abs(),
            (mesh - analytic).abs(),
            (profile - analytic).abs()
        );
    }

    println!("Beds, window as given: |∫ε(r) 2πr dr/πR² − bulk porosity|; resolution: max |Δε(r)| when halving --arc,");
    println!("and when halving --dr, max |ε(new midpoint) − linear interpolation of the default grid| (all radii / beyond dp/10 from the wall)");
    let s2 = std::f64::consts::FRAC_1_SQRT_2;
    let mut lying = simple_cubic(&cylinder, 40.0 * MM, 10.2 * MM, 4);
    lying.pellets.iter_mut().for_each(|p| p.orientation = [s2, 0.0, s2, 0.0]);
    let cases: Vec<(String, Bed, (f64, f64), Geometry)> = vec![
        (
            "close-packed spheres, D = 41".into(),
            close_packed_spheres(&sphere, 41.0 * MM, 10.2 * MM, 60),
            (2.0 * MM, 20.0 * MM),
            Geometry::Auto,
        ),
        (
            "cubic lattice of standing cylinders, D = 40".into(),
            simple_cubic(&cylinder, 40.0 * MM, 10.2 * MM, 4),
            (2.0 * MM, 35.0 * MM),
            Geometry::Auto,
        ),
        ("cubic lattice of lying cylinders, D = 40".into(), lying, (2.0 * MM, 35.0 * MM), Geometry::Auto),
        (
            "random spheres".into(),
            random_placement(&sphere, 40.0 * MM, 60.0 * MM, 40, 7),
            (4.0 * MM, 45.0 * MM),
            Geometry::Auto,
        ),
        (
            "random cylinders".into(),
            random_placement(&cylinder, 40.0 * MM, 60.0 * MM, 40, 7),
            (4.0 * MM, 45.0 * MM),
            Geometry::Auto,
        ),
        (
            "random rings".into(),
            random_placement(&ring, 40.0 * MM, 60.0 * MM, 40, 7),
            (4.0 * MM, 45.0 * MM),
            Geometry::Auto,
        ),
        (
            "random rings, --mesh".into(),
            random_placement(&ring, 40.0 * MM, 60.0 * MM, 40, 7),
            (4.0 * MM, 45.0 * MM),
            Geometry::Mesh,
        ),
        (
            "random trilobes (mesh)".into(),
            random_placement(&trilobe, 40.0 * MM, 60.0 * MM, 40, 7),
            (4.0 * MM, 45.0 * MM),
            Geometry::Auto,
        ),
    ];
    for (name, bed, window, geometry) in cases {
        let mut params = ProfileParams::new(window);
        params.geometry = geometry;
        let base = void_profile(&bed, &params).unwrap();
        let bulk = bulk_porosity(&bed, window, geometry).unwrap().porosity;
        let (dr, arc, _) = base.steps;
        let halved_r = void_profile(&bed, &ProfileParams { radial_step: Some(dr / 2.0), ..params }).unwrap();
        let halved_arc = void_profile(&bed, &ProfileParams { arc_step: Some(arc / 2.0), ..params }).unwrap();
        let d_arc =
            base.void_fraction.iter().zip(&halved_arc.void_fraction).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        let (mut d_mid, mut d_mid_inner) = (0.0f64, 0.0f64);
        for (j, &r) in halved_r.radius.iter().enumerate() {
            if let Some(i) = base.radius.windows(2).position(|w| w[0] < r - 1e-12 && r < w[1] - 1e-12) {
                let t = (r - base.radius[i]) / (base.radius[i + 1] - base.radius[i]);
                let interp = base.void_fraction[i] * (1.0 - t) + base.void_fraction[i + 1] * t;
                let d = (halved_r.void_fraction[j] - interp).abs();
                d_mid = d_mid.max(d);
                if base.tube_radius - r > 1.0 * MM {
                    d_mid_inner = d_mid_inner.max(d);
                }
            }
        }
        println!(
            "  {name} ({} pellets, ε = {bulk:.4}): integral {:.1e}; arc/2 {d_arc:.1e}; dr/2 midpoints {d_mid:.1e} / {d_mid_inner:.1e}",
            bed.pellets.len(),
            (base.cross_section_mean() - bulk).abs()
        );
    }
}
