//! Prints the mesh errors of the paper's three pellets against their
//! analytic volume, area and inertia, per Loop level:
//! `cargo run --release -p pellet_geom --example accuracy`.

use std::f64::consts::PI;

use pellet_geom::{Pellet, Resolution, ShapeSpec};

fn main() {
    let shapes = [
        ("sphere d=10", ShapeSpec::Sphere { diameter_mm: 10.0 }, 0.0, 5.0, f64::NAN),
        ("cylinder 10x10", ShapeSpec::Cylinder { diameter_mm: 10.0, height_mm: 10.0 }, 0.0, 5.0, 10.0),
        (
            "ring 10/6x10",
            ShapeSpec::Ring { outer_diameter_mm: 10.0, inner_diameter_mm: 6.0, height_mm: 10.0 },
            3.0,
            5.0,
            10.0,
        ),
    ];
    println!(
        "{:<15} {:>5} {:>7} {:>10} {:>10} {:>10} {:>10}",
        "shape", "level", "faces", "volume %", "area %", "Izz %", "Ixx %"
    );
    for (name, spec, ri, ro, h) in shapes {
        // Exact values in mm-based units.
        let (v, a, izz, ixx) = if h.is_nan() {
            let v = 4.0 / 3.0 * PI * ro * ro * ro;
            (v, 4.0 * PI * ro * ro, 0.4 * v * ro * ro, 0.4 * v * ro * ro)
        } else {
            let v = PI * (ro * ro - ri * ri) * h;
            let a = 2.0 * PI * (ro * ro - ri * ri) + 2.0 * PI * (ro + ri) * h;
            (v, a, 0.5 * v * (ro * ro + ri * ri), v * (3.0 * (ro * ro + ri * ri) + h * h) / 12.0)
        };
        for level in 0..=4 {
            let p = Pellet::build(spec.clone(), Resolution { level, faces: None }).expect("catalogue shape");
            let m = &p.properties;
            let pct = |x: f64, e: f64| (x / e - 1.0) * 100.0;
            println!(
                "{:<15} {:>5} {:>7} {:>10.4} {:>10.4} {:>10.4} {:>10.4}{}",
                name,
                level,
                p.mesh.face_count(),
                pct(m.volume * 1e9, v),
                pct(m.area * 1e6, a),
                pct(m.inertia[(2, 2)] * 1e15, izz),
                pct(m.inertia[(0, 0)] * 1e15, ixx),
                if level == Resolution::DEFAULT_LEVEL { "   <- default" } else { "" }
            );
        }
    }
}
