//! `bedexport --openfoam DIR`: the bed as an OpenFOAM case that meshes as
//! it is (pellet_export::openfoam), with the contact treatment sized
//! against the cell size.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::{bail, Context};
use clap::ValueEnum;

use pellet_analysis::bed_top;
use pellet_cli::{mm_in_range, Outcome};
use pellet_export::openfoam::{self, CaseGeometry};
use pellet_export::scene::{enclosed_volume, tube_mesh};
use pellet_export::treatment::{self, Treatment};
use pellet_export::unite::unite;
use pellet_geom::{Bed, TriMesh};

use crate::{Args, MM};

/// The contact treatment of an OpenFOAM case.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum CaseTreatment {
    /// Cut surfaces closer than --cap-gap [default: two cells] flat so that gap remains.
    Caps,
    /// Join surfaces closer than --bridge-gap [default: two cells] with cylinders.
    Bridges,
    /// Shrink every pellet by --shrink [default: opens touching pellets by two cells].
    Shrink,
    /// The pellets as they are (touching points left to snappyHexMesh).
    None,
}

/// Writes the case directory `dir` (never a partial one under its name).
pub fn run(args: &Args, dir: &str, bed: &Bed, dp: f64) -> anyhow::Result<Outcome> {
    let target = Path::new(dir);
    if target.exists() {
        bail!("{dir} already exists; give --openfoam a new directory");
    }
    let mm = |flag: &str, v: Option<f64>| crate::treatment_length(flag, v, dp);
    let radius = 0.5 * bed.tube.diameter;
    // Cells from dp / 50 (about 10⁷ background cells for a tube of N = 4 and 3 dp high; finer
    // is a workstation's job, asked for by hand) to dp / 2 and a quarter of the tube (coarser
    // finds no fluid point between the pellets to seed the mesh from).
    let coarsest = (dp / 2.0).min(radius / 2.0);
    let cell = match args.cell_size {
        Some(v) => {
            let why = " (dp / 50 to the smaller of dp / 2 and a quarter of the tube for this bed)";
            mm_in_range("--cell-size", v, dp / 50.0 / MM, coarsest / MM, true, why)? * MM
        }
        None => dp / 10.0,
    };
    let length = |flag: &str, v: Option<f64>| match v {
        Some(v) => mm_in_range(flag, v, 0.0, 100.0 * dp / MM, true, " (0 to 100 dp for these pellets)").map(|v| v * MM),
        None => Ok(dp),
    };
    let inlet = length("--inlet", args.inlet)?;
    let outlet = length("--outlet", args.outlet)?;
    let top = bed_top(bed);
    let (z0, z1) = (-inlet, top + outlet);
    let warn = |text: String| {
        if !args.quiet {
            eprintln!("bedexport: warning: {text}");
        }
    };
    let narrow = |flag: &str, gap: f64| {
        if gap < cell {
            warn(format!(
                "{flag} {:.4} mm is narrower than a cell ({:.4} mm) and snappyHexMesh closes it; the smallest useful value is {:.4} mm (the default, two cells, keeps the meshed volume within 2 %: {:.4} mm)",
                gap / MM,
                cell / MM,
                cell / MM,
                2.0 * cell / MM
            ));
        }
    };
    let chosen = args.treatment.unwrap_or(CaseTreatment::Caps);
    let given = [
        ("--cap-gap", args.cap_gap.is_some(), CaseTreatment::Caps),
        ("--bridge-gap", args.bridge_gap.is_some(), CaseTreatment::Bridges),
        ("--shrink", args.shrink.is_some(), CaseTreatment::Shrink),
    ];
    if let Some((flag, _, needs)) = given.iter().find(|(_, set, t)| *set && *t != chosen) {
        bail!(
            "{flag} sizes --treatment {}; with --openfoam give --treatment {0} too",
            format!("{needs:?}").to_lowercase()
        );
    }
    let plan = match chosen {
        CaseTreatment::Caps => {
            let gap = mm("--cap-gap", args.cap_gap)?.unwrap_or(2.0 * cell);
            narrow("--cap-gap", gap);
            Treatment { caps: Some(gap), ..Treatment::default() }
        }
        CaseTreatment::Bridges => {
            let gap = mm("--bridge-gap", args.bridge_gap)?.unwrap_or(2.0 * cell);
            let diameter = mm("--bridge-diameter", args.bridge_diameter)?.unwrap_or((dp / 5.0).max(2.0 * cell));
            narrow("--bridge-gap", gap);
            narrow("--bridge-diameter", diameter);
            Treatment { bridges: Some((gap, diameter)), ..Treatment::default() }
        }
        CaseTreatment::Shrink => {
            let factor = args.shrink.unwrap_or(1.0 - 2.0 * cell / dp);
            // Touching pellets open by dp (1 − factor).
            narrow("the gap --shrink opens,", dp * (1.0 - factor));
            Treatment { shrink: Some(factor), ..Treatment::default() }
        }
        CaseTreatment::None => Treatment::default(),
    };
    let selected: Vec<usize> = (0..bed.pellets.len()).collect();
    let contact_gap = mm("--contact-gap", args.contact_gap)?.unwrap_or(dp / 100.0);
    let treated = treatment::apply(bed, &selected, (0.0, top), &plan, contact_gap)?;
    let pellets = treated.meshes.len();
    let mut surfaces: Vec<TriMesh> = treated.meshes;
    let bridges = treated.bridges.len();
    surfaces.extend(treated.bridges.into_iter().map(|b| b.mesh));
    let location = openfoam::location_in_mesh(&surfaces, radius, z0, z1, 2.0 * cell)
        .context("found no fluid point in the tube for locationInMesh")?;
    let g = CaseGeometry { radius, z0, z1, cell, location };
    let tube = tube_mesh(radius, z0, z1, args.tube_segments);
    let tube_volume = enclosed_volume(&tube);
    // One solid for the mesher: pellets that touch or overlap, and the
    // bridges buried in them, as their union's surface (no faces inside a
    // solid, the real concave edge where two solids meet), its volume
    // counting every overlap once.
    let refs: Vec<&TriMesh> = surfaces.iter().collect();
    let name = |k: usize| {
        if k < pellets {
            format!("pellet {k}")
        } else {
            format!("bridge {}", k - pellets)
        }
    };
    let started = std::time::Instant::now();
    // Edges under dp / 10⁵ go first (0.1 µm for 10 mm pellets: far below a cell, far above
    // single precision's 2 nm, and below the µm overlaps of a settled bed); others if that
    // leaves a fault.
    let tolerances = [1e-5, 3e-6, 3e-5, 1e-6, 1e-4].map(|f| f * dp);
    let united = unite(&refs, &name, &tolerances)?;
    let merged = united.mesh();
    let seconds = started.elapsed().as_secs_f64();
    let solid = united.volume_in_tube(&tube)?;
    let treatment_name = format!("{chosen:?}").to_lowercase();
    let files: Vec<(&str, Vec<u8>)> = vec![
        ("constant/triSurface/pellets.stl", pellet_export::stl::ascii(&[("pellets".into(), merged)], 1.0)),
        ("constant/triSurface/tube.stl", openfoam::tube_stl(radius, z0, z1, args.tube_segments)),
        ("system/controlDict", openfoam::control_dict().into_bytes()),
        ("system/blockMeshDict", openfoam::block_mesh_dict(&g).into_bytes()),
        ("system/surfaceFeatureExtractDict", openfoam::surface_feature_extract_dict().into_bytes()),
        ("system/snappyHexMeshDict", openfoam::snappy_hex_mesh_dict(&g).into_bytes()),
        ("system/meshQualityDict", openfoam::mesh_quality_dict().into_bytes()),
        ("system/fvSchemes", openfoam::fv_schemes().into_bytes()),
        ("system/fvSolution", openfoam::fv_solution().into_bytes()),
        ("README", openfoam::readme(&g, &args.packing, &treatment_name).into_bytes()),
    ];
    write_case(target, &files).with_context(|| format!("--openfoam {dir}"))?;
    if args.quiet {
        return Ok(Outcome::Success);
    }
    let mut s = String::new();
    let _ = writeln!(s, "wrote OpenFOAM case: {dir} (lengths in m)");
    let _ = writeln!(
        s,
        "tube: z {:.3} to {:.3} mm (inlet {:.3} mm, outlet {:.3} mm); cells {:.4} mm at the pellets, {:.4} mm elsewhere",
        z0 / MM,
        z1 / MM,
        inlet / MM,
        outlet / MM,
        cell / MM,
        2.0 * cell / MM
    );
    let _ = writeln!(s, "locationInMesh: ({:.6} {:.6} {:.6}) m", location.x, location.y, location.z);
    for line in &treated.report.lines {
        let _ = writeln!(
            s,
            "{}: {} pellet-pellet, {} pellet-wall and {} pellet-floor contacts treated; porosity change {:+.5} ({})",
            line.name,
            line.pellet_contacts,
            line.wall_contacts,
            line.floor_contacts,
            line.porosity_change,
            line.parameters
        );
    }
    let joined = if bridges > 0 { format!(" and {bridges} bridges") } else { String::new() };
    let _ = writeln!(
        s,
        "pellets.stl: {pellets} pellets{joined} united into one closed surface ({} triangles, {} separate pieces, {:.6e} m3; tolerance {:.1e} mm; {seconds:.2} s)",
        merged.triangles.len(),
        united.pieces(),
        united.volume(),
        united.tolerance() / MM,
    );
    let _ = writeln!(
        s,
        "fluid volume: {:.6e} m3 (tube {:.6e} m3 minus solid {:.6e} m3 inside it)",
        tube_volume - solid,
        tube_volume,
        solid
    );
    pellet_cli::print_stdout(&s)?;
    Ok(Outcome::Success)
}

/// Writes `files` under a hidden sibling of `target`, then renames it to `target`.
fn write_case(target: &Path, files: &[(&str, Vec<u8>)]) -> anyhow::Result<()> {
    let parent = match target.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if !parent.is_dir() {
        bail!("the directory {} does not exist; create it or give another path", parent.display());
    }
    let name = target.file_name().context("needs a directory name")?.to_string_lossy();
    let staging = parent.join(format!(".{name}.part-{}", std::process::id()));
    let result = (|| -> std::io::Result<()> {
        for (path, bytes) in files {
            let path = staging.join(path);
            std::fs::create_dir_all(path.parent().expect("case files are in the case"))?;
            std::fs::write(&path, bytes)?;
        }
        std::fs::rename(&staging, target)
    })();
    if let Err(e) = result {
        let _ = std::fs::remove_dir_all(&staging);
        return Err(e.into());
    }
    Ok(())
}
