//! Timing of each export stage on a 600-sphere bed (10 mm spheres, close
//! packed in a 60 mm tube), and the bed written as a packing file so that
//! the `bedexport` binary can be timed on it too:
//!
//! `cargo run --release -p pellet_export --example bench_export -- /tmp/bed600.packing`
//! then `time target/release/bedexport /tmp/bed600.packing --stl /tmp/b.stl --voxels /tmp/b.raw`.

use std::time::Instant;

use pellet_analysis::synthetic::close_packed_spheres;
use pellet_export::treatment::{apply, Treatment};
use pellet_export::{find_contacts, scene, stl, voxelise, vtk};
use pellet_geom::{Pellet, Resolution, ShapeSpec};

fn main() {
    let sphere = Pellet::build(ShapeSpec::Sphere { diameter_mm: 10.0 }, Resolution::default()).unwrap();
    let bed = close_packed_spheres(&sphere, 0.06, 0.01, 600);
    if let Some(path) = std::env::args().nth(1) {
        let file = pellet_io::PackingFile {
            length_unit: "m".into(),
            provenance: pellet_io::Provenance { tool: "bench_export".into(), version: "0".into(), args: vec![] },
            time_s: 0.0,
            verdict: None,
            bed: bed.clone(),
        };
        std::fs::write(&path, pellet_io::encode_packing(&file).unwrap()).unwrap();
        println!("wrote {path}");
    }
    let all: Vec<usize> = (0..bed.pellets.len()).collect();
    let range = scene::axial_range(&bed, None);
    let time = |label: &str, f: &mut dyn FnMut() -> String| {
        let t = Instant::now();
        let what = f();
        println!("{label:<34} {:>8.3} s   {what}", t.elapsed().as_secs_f64());
    };
    println!("600 spheres of 10 mm, close packed in a 60 mm tube, bed height {:.1} mm", range.1 * 1e3);
    time("contacts (gap dp/100)", &mut || format!("{} contacts", find_contacts(&bed, &all, 1e-4).len()));
    time("world meshes", &mut || format!("{} meshes", scene::world_meshes(&bed, &all).len()));
    time("binary STL bytes", &mut || {
        let meshes = scene::world_meshes(&bed, &all);
        let refs: Vec<_> = meshes.iter().collect();
        format!("{} MB", stl::binary(&refs, 1000.0, "bench").len() / 1_000_000)
    });
    time("VTK PolyData bytes", &mut || {
        let meshes = scene::world_meshes(&bed, &all);
        let ids: Vec<_> = meshes.iter().enumerate().map(|(i, m)| (i as i32, m)).collect();
        format!("{} MB", vtk::polydata(&ids, 1000.0, "bench").len() / 1_000_000)
    });
    for (name, t) in [
        ("shrink 0.99", Treatment { shrink: Some(0.99), ..Default::default() }),
        ("bridges (gap 0.1 mm, d 2 mm)", Treatment { bridges: Some((1e-4, 2e-3)), ..Default::default() }),
        ("caps (gap 0.1 mm)", Treatment { caps: Some(1e-4), ..Default::default() }),
    ] {
        time(name, &mut || {
            let r = apply(&bed, &all, range, &t, 1e-4).unwrap();
            let l = &r.report.lines[0];
            format!(
                "{} pellet, {} wall, {} floor contacts; porosity change {:+.5}",
                l.pellet_contacts, l.wall_contacts, l.floor_contacts, l.porosity_change
            )
        });
    }
    for per_dp in [10.0, 20.0] {
        time(&format!("voxels, {per_dp} per dp"), &mut || {
            let g = voxelise(&bed, 0.01 / per_dp, range, &mut |_, _| {}).unwrap();
            let exact = pellet_analysis::bulk_porosity(&bed, g.z_range(), pellet_analysis::Geometry::Auto).unwrap();
            format!(
                "{:?} voxels, porosity {:.5} vs exact {:.5} ({:+.5})",
                g.dims,
                g.porosity(),
                exact.porosity,
                g.porosity() - exact.porosity
            )
        });
    }
}
