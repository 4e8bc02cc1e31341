//! `bedexport --openfoam DIR`: the bed as an OpenFOAM case that meshes as
//! it is (pellet_export::openfoam), with the contact treatment sized by the
//! literature's fractions of dp and the cells refined at the contacts to fit it.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::{bail, Context};
use clap::ValueEnum;

use pellet_analysis::{bed_top, bulk_porosity, Geometry};
use pellet_cli::{mm_in_range, Outcome};
use pellet_export::openfoam::{self, CaseGeometry, Flow, MAX_REYNOLDS, WATER_20C};
use pellet_export::scene::{enclosed_volume, tube_mesh};
use pellet_export::treatment::{self, Treatment};
use pellet_export::unite::unite;
use pellet_geom::{Bed, TriMesh};

use crate::{Args, MM};

/// `--reynolds` when not given: creeping-to-inertial laminar flow, steady for simpleFoam.
const DEFAULT_REYNOLDS: f64 = 10.0;

/// The contact treatment of an OpenFOAM case.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum CaseTreatment {
    /// Cut surfaces closer than --cap-gap [default: dp/100] flat so that gap remains.
    Caps,
    /// Join surfaces closer than --bridge-gap [default: dp/100] with cylinders of --bridge-diameter [default: 0.15 dp].
    Bridges,
    /// Shrink every pellet by --shrink [default: 0.99, opening touching pellets by dp/100].
    Shrink,
    /// The pellets as they are (touching points left to snappyHexMesh).
    None,
}

/// Writes the case directory `dir` (never a partial one under its name).
/// `dp` is the pellets' nominal size, `dpv` their volume-equivalent diameter (the Reynolds number's).
pub fn run(args: &Args, dir: &str, bed: &Bed, dp: f64, dpv: f64) -> anyhow::Result<Outcome> {
    let target = Path::new(dir);
    if target.exists() {
        bail!("{dir} already exists; give --openfoam a new directory");
    }
    let reynolds = reynolds(args.reynolds)?;
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
    let note = |text: String| {
        if !args.quiet {
            eprintln!("bedexport: note: {text}");
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
    // The defaults are the literature's, in units of dp and independent of the cells (see
    // crate::DEFAULT_GAP); each leaves a gap of DEFAULT_GAP dp where pellets touched, which
    // the contact refinement below resolves. `gap` is the fluid gap the cells must fit.
    let (plan, gap, bridge_diameter) = match chosen {
        CaseTreatment::Caps => {
            let gap = mm("--cap-gap", args.cap_gap)?.unwrap_or(crate::DEFAULT_GAP * dp);
            (Treatment { caps: Some(gap), ..Treatment::default() }, Some(gap), 0.0)
        }
        CaseTreatment::Bridges => {
            let gap = mm("--bridge-gap", args.bridge_gap)?.unwrap_or(crate::DEFAULT_GAP * dp);
            let diameter =
                mm("--bridge-diameter", args.bridge_diameter)?.unwrap_or(crate::DEFAULT_BRIDGE_DIAMETER * dp);
            (Treatment { bridges: Some((gap, diameter)), ..Treatment::default() }, Some(gap), diameter)
        }
        CaseTreatment::Shrink => {
            let factor = args.shrink.unwrap_or(1.0 - crate::DEFAULT_GAP);
            // Touching pellets open by dp (1 − factor).
            let gap = dp * (1.0 - factor);
            (Treatment { shrink: Some(factor), ..Treatment::default() }, (gap > 0.0).then_some(gap), 0.0)
        }
        CaseTreatment::None => (Treatment::default(), None, 0.0),
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
    // The cells fit the treatment: a sphere around each treated contact refined so that its
    // cells are no wider than the gap (capped at MAX_CONTACT_LEVEL). Its radius covers the fluid
    // thinner than about twice the gap between two touching spheres of dp beyond the bridge's
    // rim: there the surfaces are 2 r² / dp + gap apart, so r² = dp gap + (d / 2)².
    let (refine, capped) = match gap {
        Some(gap) if !treated.contacts.is_empty() => {
            let (level, capped) = openfoam::contact_level(cell, gap);
            let r = (dp * gap + 0.25 * bridge_diameter * bridge_diameter).sqrt();
            let spheres = treated.contacts.iter().map(|c| (c.midpoint(), r)).collect();
            (openfoam::ContactRefinement { level, spheres }, capped.then_some(gap))
        }
        _ => (openfoam::ContactRefinement::default(), None),
    };
    if let Some(gap) = capped {
        let fine = 2.0 * cell / f64::from(1u32 << refine.level);
        note(format!(
            "the contacts' cells are {:.4} mm (--cell-size {:.4} mm refined {} levels, the most this writes), wider than the treatment's gap {:.4} mm: snappyHexMesh may close the gap; a smaller --cell-size or a wider gap fits them",
            fine / MM,
            cell / MM,
            refine.level,
            gap / MM
        ));
    }
    crate::warn_porosity(&treated.report, dp, args.quiet);
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
    // The packed section is voidprof's default window: the floor to one dp below the bed's top,
    // leaving out the loose top layer the flow goes round (the whole bed when under 2 dp tall).
    let (packed_top, rule) = if top >= 2.0 * dp {
        (top - dp, format!("the bed's top {:.3} mm minus dp, as voidprof", top / MM))
    } else {
        (top, "the bed's top; the bed is under 2 dp tall".to_string())
    };
    let flow = Flow { fluid: WATER_20C, reynolds, dp: dpv, packed: (0.0, packed_top) };
    // Its porosity as exported (the united solid in the tube polygon) and of the bed as it is
    // (exact, as voidprof).
    let section = tube_mesh(radius, 0.0, packed_top, args.tube_segments);
    let exported_porosity = 1.0 - united.volume_in_tube(&section)? / enclosed_volume(&section);
    let bed_porosity = bulk_porosity(bed, (0.0, packed_top), Geometry::Auto).map(|b| b.porosity).ok();
    let files: Vec<(&str, Vec<u8>)> = vec![
        ("0/U", openfoam::field_u(&flow).into_bytes()),
        ("0/p", openfoam::field_p().into_bytes()),
        ("constant/transportProperties", openfoam::transport_properties(&flow).into_bytes()),
        ("constant/turbulenceProperties", openfoam::turbulence_properties().into_bytes()),
        ("constant/triSurface/pellets.stl", pellet_export::stl::ascii(&[("pellets".into(), merged)], 1.0)),
        ("constant/triSurface/tube.stl", openfoam::tube_stl(radius, z0, z1, args.tube_segments)),
        ("system/controlDict", openfoam::control_dict(&flow).into_bytes()),
        ("system/blockMeshDict", openfoam::block_mesh_dict(&g).into_bytes()),
        ("system/surfaceFeatureExtractDict", openfoam::surface_feature_extract_dict().into_bytes()),
        ("system/snappyHexMeshDict", openfoam::snappy_hex_mesh_dict(&g, &refine).into_bytes()),
        ("system/meshQualityDict", openfoam::mesh_quality_dict().into_bytes()),
        ("system/fvSchemes", openfoam::fv_schemes().into_bytes()),
        ("system/fvSolution", openfoam::fv_solution().into_bytes()),
        ("README", openfoam::readme(&g, &flow, &args.packing, &treatment_name).into_bytes()),
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
    if !refine.spheres.is_empty() {
        let _ = writeln!(
            s,
            "contact refinement: {} spheres of radius {:.4} mm at level {} (cells {:.4} mm; the treatment's gap {:.4} mm)",
            refine.spheres.len(),
            refine.spheres[0].1 / MM,
            refine.level,
            2.0 * cell / f64::from(1u32 << refine.level) / MM,
            gap.unwrap_or(0.0) / MM
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
    let _ = writeln!(
        s,
        "packed section: z 0.000 to {:.3} mm ({rule}), porosity {exported_porosity:.5} as exported{}",
        packed_top / MM,
        bed_porosity.map_or(String::new(), |e| format!(" ({e:.5} before the contact treatment, as voidprof)"))
    );
    let _ = writeln!(
        s,
        "flow: {} (nu {:e} m2/s, rho {} kg/m3), Re_p {reynolds} on dp {:.4} mm (volume-equivalent): u_s {:.6e} m/s along +z",
        flow.fluid.name,
        flow.fluid.nu,
        flow.fluid.rho,
        dpv / MM,
        flow.velocity()
    );
    let _ = writeln!(
        s,
        "Ergun at porosity {exported_porosity:.5}: dp/L {:.6e} Pa/m, {:.6e} Pa over the packed section",
        flow.ergun(exported_porosity),
        flow.ergun(exported_porosity) * packed_top
    );
    pellet_cli::print_stdout(&s)?;
    Ok(Outcome::Success)
}

/// `--reynolds`, checked: finite, above 0, at most [`MAX_REYNOLDS`] (steady laminar flow).
fn reynolds(value: Option<f64>) -> anyhow::Result<f64> {
    let Some(re) = value else { return Ok(DEFAULT_REYNOLDS) };
    if !(re.is_finite() && re > 0.0 && re <= MAX_REYNOLDS) {
        bail!(
            "--reynolds must be above 0 and at most {MAX_REYNOLDS} (Re_p = rho u_s dp / mu; above {MAX_REYNOLDS} packed-bed flow is not steady and laminar) (got {re})"
        );
    }
    Ok(re)
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
