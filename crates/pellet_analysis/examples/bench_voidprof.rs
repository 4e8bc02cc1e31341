//! Speed of the default profile on a 600-sphere bed (the target: under 10 s on one core).
//!
//! ```sh
//! cargo run --release -p pellet_analysis --example bench_voidprof [poses.csv]
//! ```
//!
//! With a file name, the bed is also written as a poses CSV (mm) for
//! timing the `voidprof` binary itself (`--poses … --tube-diameter 79.9`).
//!
//! The bed: 600 spheres of 10 mm, close-packed triangular layers 10.1 mm
//! apart (lattice-like; porosity 0.494 in the window, looser than a poured
//! bed at N = 8, about 0.42, so a real bed has ~15 % more solid per line)
//! in a tube of D = 79.9 mm (the paper's widest sphere tube), measured in
//! the window 0–100 mm at the default resolution. Single-threaded.

use std::time::Instant;

use pellet_analysis::synthetic::close_packed_spheres;
use pellet_analysis::{bed_top, bulk_porosity, void_profile, Geometry, ProfileParams};
use pellet_geom::{Pellet, Resolution, ShapeSpec};

fn main() {
    let sphere = Pellet::build(ShapeSpec::Sphere { diameter_mm: 10.0 }, Resolution::default()).expect("sphere");
    let bed = close_packed_spheres(&sphere, 79.9e-3, 10.1e-3, 600);
    let window = (0.0, 0.100);
    println!(
        "bed: {} spheres of 10 mm, D = 79.9 mm, top at {:.1} mm; window 0–100 mm",
        bed.pellets.len(),
        bed_top(&bed) * 1e3
    );
    if let Some(path) = std::env::args().nth(1) {
        let mut csv = String::from("id,x,y,z\n");
        for (i, p) in bed.pellets.iter().enumerate() {
            csv += &format!("{i},{:.9},{:.9},{:.9}\n", p.position[0] * 1e3, p.position[1] * 1e3, p.position[2] * 1e3);
        }
        std::fs::write(&path, csv).expect("write the poses CSV");
        println!("poses written to {path}");
    }
    for (name, geometry) in [("exact shape", Geometry::Auto), ("triangle mesh (--mesh)", Geometry::Mesh)] {
        let mut params = ProfileParams::new(window);
        params.geometry = geometry;
        let start = Instant::now();
        let profile = void_profile(&bed, &params).expect("profile");
        let profile_s = start.elapsed().as_secs_f64();
        let start = Instant::now();
        let bulk = bulk_porosity(&bed, window, geometry).expect("bulk");
        let bulk_s = start.elapsed().as_secs_f64();
        let lines: usize = profile.lines.iter().sum();
        println!(
            "{name}: profile {profile_s:.2} s ({} radii, {lines} lines), bulk porosity {bulk_s:.3} s; \
             bulk {:.5}, ∫ε(r) {:.5}, difference {:.1e}",
            profile.radius.len(),
            bulk.porosity,
            profile.cross_section_mean(),
            (bulk.porosity - profile.cross_section_mean()).abs()
        );
    }
}
