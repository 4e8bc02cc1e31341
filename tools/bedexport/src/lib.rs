//! `bedexport`: a packing file in the forms CFD and lattice-Boltzmann
//! codes load — STL (with contact treatments), VTK for ParaView, voxel
//! grids and a poses CSV. The formats are specified in `pellet_export`
//! and in tools/bedexport/README.md.

use anyhow::{bail, Context};
use clap::{Parser, ValueEnum};
use serde_json::json;

use pellet_analysis::{bulk_porosity, reference_diameters, Geometry};
use pellet_cli::{mm_in_range, positive_mm, Outcome};
use pellet_export::treatment::{self, Treatment};
use pellet_export::{clip, poses, scene, stl, voxels, vtk};
use pellet_io::OutputFile;

mod openfoam;
mod summary;

pub use openfoam::CaseTreatment;

const MM: f64 = 1e-3;

/// The default gap of a contact treatment, in units of dp: caps leave it, bridges join surfaces
/// closer than it, a shrink opens touching pellets by it. Contact studies size caps and gaps at
/// about 1–2 % of dp (tools/bedexport/README.md, "Contact treatments").
pub const DEFAULT_GAP: f64 = 0.01;

/// The default bridge diameter, in units of dp (bridges of 10–20 % of dp in the literature).
pub const DEFAULT_BRIDGE_DIAMETER: f64 = 0.15;

/// The largest porosity change (absolute, as printed) a treatment makes without a warning.
pub const MAX_POROSITY_CHANGE: f64 = 0.01;

/// Warns on stderr, one line per treatment, when a treatment changes the porosity by more than
/// [`MAX_POROSITY_CHANGE`], with the figure and the flag that reduces it.
pub(crate) fn warn_porosity(report: &treatment::TreatmentReport, dp: f64, quiet: bool) {
    for line in &report.lines {
        if quiet || line.porosity_change.abs() <= MAX_POROSITY_CHANGE {
            continue;
        }
        let how = match line.name {
            "caps" => format!("a smaller --cap-gap reduces it (default dp/100 = {:.4} mm)", DEFAULT_GAP * dp / MM),
            "bridges" => format!(
                "a smaller --bridge-diameter or --bridge-gap reduces it (defaults {:.4} mm and {:.4} mm: 0.15 dp and dp/100)",
                DEFAULT_BRIDGE_DIAMETER * dp / MM,
                DEFAULT_GAP * dp / MM
            ),
            _ => format!("a --shrink closer to 1 reduces it, or --treatment caps (a gap of dp/100 = {:.4} mm changes it far less)", DEFAULT_GAP * dp / MM),
        };
        eprintln!(
            "bedexport: warning: {} change the porosity by {:+.5}, more than {MAX_POROSITY_CHANGE}; {how}",
            line.name, line.porosity_change
        );
    }
}

const EXAMPLES: &str = "\
Examples:
  bedexport bed.packing --stl bed.stl --tube-stl tube.stl
  bedexport bed.packing --openfoam case --cell-size 1 --inlet 10 --outlet 10 --treatment caps
  bedexport bed.packing --openfoam case --reynolds 50    # water at 20 °C, u_s = 50 ν / dp
  bedexport bed.packing --stl bed.stl --shrink 0.99 --units m
  bedexport bed.packing --stl bed.stl --ascii --solids per-pellet --bridge-gap 0.1 --bridge-diameter 2
  bedexport bed.packing --vtk bed.vtp --vtk-centres centres.vtp --csv poses.csv
  bedexport bed.packing --voxels bed.raw --voxel-size 0.5 --vti bed.vti --window 0,100
  bedexport bed.packing --stl slab.stl --tube-stl tube.stl --window 20,60    # pellets cut and capped
  settle-check run.mcap -o - | bedexport - --stl bed.stl

Lengths in flags are in mm; files are in --units (mm by default); an OpenFOAM
case is in SI units (m, m/s, kinematic pressure p/ρ in m²/s², ν in m²/s). The raw
voxel file is uint8 (0 fluid, 1 pellet, 2 outside the tube), x fastest,
then y, then z; its header is FILE.json. Exit codes: 0 success, 2 error.";

/// Length unit of the exported files.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Units {
    /// Millimetres.
    Mm,
    /// Metres.
    M,
}

impl Units {
    /// Factor from metres.
    pub fn scale(self) -> f64 {
        match self {
            Units::Mm => 1000.0,
            Units::M => 1.0,
        }
    }

    /// The unit's name in files.
    pub fn name(self) -> &'static str {
        match self {
            Units::Mm => "mm",
            Units::M => "m",
        }
    }
}

/// STL solids: one surface, or one named solid per pellet (ASCII only).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Solids {
    /// All pellets (and bridges) in one surface.
    Merged,
    /// One solid per pellet (`pellet_00042`), one per bridge (`bridge_00007`).
    PerPellet,
}

/// Export a packed bed for CFD and lattice-Boltzmann codes: STL surfaces
/// (with contact treatments for meshing), VTK files for ParaView, a
/// solid/fluid voxel grid and the poses as CSV.
#[derive(Debug, Parser)]
#[command(name = "bedexport", version = pellet_cli::LONG_VERSION, after_help = EXAMPLES, allow_negative_numbers = true)]
pub struct Args {
    /// The packing file (from settle-check); `-` reads stdin.
    pub packing: String,
    /// The pellets' surfaces as STL (binary unless --ascii).
    #[arg(long, value_name = "FILE")]
    pub stl: Option<String>,
    /// Write ASCII STL instead of binary.
    #[arg(long)]
    pub ascii: bool,
    /// One merged surface, or one named solid per pellet (needs --ascii).
    #[arg(long, value_enum, default_value = "merged")]
    pub solids: Solids,
    /// The tube as its own closed STL solid (circumscribed polygon, floor to top of the range).
    #[arg(long, value_name = "FILE")]
    pub tube_stl: Option<String>,
    /// Sides of the tube's polygon, 8 to 65536.
    #[arg(long, default_value_t = 256)]
    pub tube_segments: usize,
    /// The pellets' surfaces as VTK PolyData (.vtp) with a pellet_id cell field.
    #[arg(long, value_name = "FILE")]
    pub vtk: Option<String>,
    /// The pellet centres as VTK PolyData (.vtp) with axis, orientation and radial position.
    #[arg(long, value_name = "FILE")]
    pub vtk_centres: Option<String>,
    /// Solid/fluid voxels as raw uint8; the header goes to FILE.json.
    #[arg(long, value_name = "FILE")]
    pub voxels: Option<String>,
    /// The voxel grid as VTK ImageData (.vti).
    #[arg(long, value_name = "FILE")]
    pub vti: Option<String>,
    /// Voxel edge (mm) [default: dp/10].
    #[arg(long, value_name = "MM", conflicts_with = "voxels_per_dp")]
    pub voxel_size: Option<f64>,
    /// Voxels per pellet diameter dp (instead of --voxel-size).
    #[arg(long, value_name = "N")]
    pub voxels_per_dp: Option<f64>,
    /// The poses as CSV: id,type,x,y,z,qw,qx,qy,qz,axis_x,axis_y,axis_z,r.
    #[arg(long, value_name = "FILE")]
    pub csv: Option<String>,
    /// Length unit of the files.
    #[arg(long, value_enum, default_value = "mm")]
    pub units: Units,
    /// Export the slab z0 ≤ z ≤ z1 (mm): pellets cut at the planes and capped; voxels and tube span it [default: floor to bed top].
    #[arg(long, value_name = "Z0,Z1", allow_hyphen_values = true)]
    pub window: Option<String>,
    /// With --window: export whole the pellets whose centroid is in the window, instead of cutting.
    #[arg(long, requires = "window")]
    pub whole_pellets: bool,
    /// Scale every pellet about its centroid by this factor (e.g. 0.99) to open the contacts.
    #[arg(long, value_name = "FACTOR")]
    pub shrink: Option<f64>,
    /// Join surfaces closer than this gap (mm, up to dp/5) with cylindrical bridges.
    #[arg(long, value_name = "MM", conflicts_with = "cap_gap")]
    pub bridge_gap: Option<f64>,
    /// Diameter of the bridges (mm, up to dp/2) [default: 0.15 dp].
    #[arg(long, value_name = "MM", requires = "bridge_gap")]
    pub bridge_diameter: Option<f64>,
    /// Cut surfaces closer than this gap (mm, up to dp/5) flat so that this gap remains (caps).
    #[arg(long, value_name = "MM")]
    pub cap_gap: Option<f64>,
    /// Gap (mm, up to dp/5) below which --shrink counts a contact as opened [default: dp/100].
    #[arg(long, value_name = "MM")]
    pub contact_gap: Option<f64>,
    /// Write an OpenFOAM case (surfaces in m and the meshing dictionaries) to this new directory.
    #[arg(long, value_name = "DIR")]
    pub openfoam: Option<String>,
    /// With --openfoam: cell size at the pellets (mm, dp/50 to the smaller of dp/2 and D/4), twice
    /// that elsewhere [default: dp/10].
    #[arg(long, value_name = "MM", requires = "openfoam")]
    pub cell_size: Option<f64>,
    /// With --openfoam: empty tube below the floor (mm, 0 to 100 dp) [default: dp].
    #[arg(long, value_name = "MM", requires = "openfoam")]
    pub inlet: Option<f64>,
    /// With --openfoam: empty tube above the bed top (mm, 0 to 100 dp) [default: dp].
    #[arg(long, value_name = "MM", requires = "openfoam")]
    pub outlet: Option<f64>,
    /// With --openfoam: the contact treatment, gaps of dp/100 and bridges of 0.15 dp unless --cap-gap, --bridge-gap,
    /// --bridge-diameter or --shrink is given, with the cells refined at the contacts to fit the gap [default: caps].
    #[arg(long, value_enum, requires = "openfoam")]
    pub treatment: Option<CaseTreatment>,
    /// With --openfoam: the particle Reynolds number Re_p = ρ u_s dp / μ of the steady laminar
    /// flow set up along +z (water at 20 °C, ν = 1.0034e-6 m²/s; u_s the superficial velocity,
    /// dp the pellets' volume-equivalent diameter), above 0 and at most 300 [default: 10].
    #[arg(long, value_name = "RE", requires = "openfoam")]
    pub reynolds: Option<f64>,
    /// Print nothing but errors: no progress on stderr, no summary.
    #[arg(short, long)]
    pub quiet: bool,
}

impl Args {
    fn output_paths(&self) -> Vec<&String> {
        [&self.stl, &self.tube_stl, &self.vtk, &self.vtk_centres, &self.voxels, &self.vti, &self.csv]
            .into_iter()
            .flatten()
            .collect()
    }

    /// Every file written, with the flag that names it (the voxel header beside --voxels).
    fn output_flags(&self) -> Vec<(String, String)> {
        let flags = [
            ("--stl", &self.stl),
            ("--tube-stl", &self.tube_stl),
            ("--vtk", &self.vtk),
            ("--vtk-centres", &self.vtk_centres),
            ("--voxels", &self.voxels),
            ("--vti", &self.vti),
            ("--csv", &self.csv),
        ];
        let mut all: Vec<(String, String)> =
            flags.iter().filter_map(|(f, p)| p.as_ref().map(|p| (f.to_string(), p.clone()))).collect();
        if let Some(v) = &self.voxels {
            all.push(("--voxels (its header)".into(), format!("{v}.json")));
        }
        all
    }
}

/// Parses `z0,z1` in mm into metres; the window starts at or above the floor.
pub fn parse_window(text: &str) -> anyhow::Result<(f64, f64)> {
    let (z0, z1) = pellet_cli::parse_window(text)?;
    if z0 < 0.0 {
        bail!("--window z0,z1 needs 0 <= z0 < z1 (got {text:?})");
    }
    Ok((z0, z1))
}

/// What was exported, for the summary.
pub struct Exported {
    /// Pellets in the bed.
    pub pellets: usize,
    /// Pellets exported.
    pub selected: usize,
    /// Pellets cut at the window's planes.
    pub cut: usize,
    /// Whether whole pellets were selected by their centroid.
    pub whole: bool,
    /// The axial range (m).
    pub range: (f64, f64),
    /// Triangles written to the pellet surface files.
    pub triangles: usize,
    /// Treatments applied.
    pub report: treatment::TreatmentReport,
    /// The voxel grid and the exact porosity over its range, if made.
    pub voxels: Option<(voxels::VoxelGrid, Option<f64>, f64)>,
    /// The files written.
    pub files: Vec<(String, String)>,
}

/// Runs `bedexport`.
/// Most sides of the tube's polygon: far finer than any mesher needs, and checked before the
/// polygon is allocated (4294967295 sides aborted the allocator).
const MAX_TUBE_SEGMENTS: usize = 65_536;

pub fn run(args: Args) -> anyhow::Result<Outcome> {
    let paths = args.output_paths();
    if let Some(dir) = &args.openfoam {
        if !paths.is_empty() || args.window.is_some() {
            bail!("--openfoam writes a whole case; give it without the other outputs and --window");
        }
        pellet_cli::refuse_clashing_outputs([&args.packing], [("--openfoam".to_string(), dir.clone())])?;
        let bed = pellet_io::decode_packing(&pellet_io::read_input(&args.packing)?, &args.packing)?.bed;
        if bed.pellets.is_empty() {
            bail!("{}: the bed holds no pellets", args.packing);
        }
        let (dp, dpv) = reference_diameters(&bed).with_context(|| args.packing.clone())?;
        return openfoam::run(&args, dir, &bed, dp, dpv);
    }
    if paths.is_empty() {
        bail!(
            "nothing to export: give --openfoam or at least one of --stl, --tube-stl, --vtk, --vtk-centres, --voxels, --vti, --csv"
        );
    }
    pellet_cli::refuse_clashing_outputs([&args.packing], args.output_flags())?;
    if args.voxels.as_deref() == Some("-") {
        bail!("--voxels needs a file name (its header is written beside it as FILE.json)");
    }
    if args.solids == Solids::PerPellet && !args.ascii {
        bail!("--solids per-pellet needs --ascii: binary STL has no named solids");
    }
    if !(8..=MAX_TUBE_SEGMENTS).contains(&args.tube_segments) {
        bail!("--tube-segments must be in [8, {MAX_TUBE_SEGMENTS}] (got {})", args.tube_segments);
    }
    let file = pellet_io::decode_packing(&pellet_io::read_input(&args.packing)?, &args.packing)?;
    let bed = file.bed;
    if bed.pellets.is_empty() {
        bail!("{}: the bed holds no pellets", args.packing);
    }
    let (dp, _) = reference_diameters(&bed).with_context(|| args.packing.clone())?;
    let window = args.window.as_deref().map(parse_window).transpose()?;
    let optional = |flag: &str, v: Option<f64>| treatment_length(flag, v, dp);
    let range = scene::axial_range(&bed, window);
    let selected = match window {
        Some(w) if !args.whole_pellets => scene::select_overlapping(&bed, w),
        _ => scene::select(&bed, window),
    };
    if selected.is_empty() {
        bail!(
            "no pellet lies in --window {} (the bed is {:.3} mm high)",
            args.window.as_deref().unwrap_or(""),
            pellet_analysis::bed_top(&bed) * 1e3
        );
    }
    let bridge_gap = optional("--bridge-gap", args.bridge_gap)?;
    let bridge_diameter = optional("--bridge-diameter", args.bridge_diameter)?.unwrap_or(DEFAULT_BRIDGE_DIAMETER * dp);
    let plan = Treatment {
        shrink: args.shrink,
        bridges: bridge_gap.map(|g| (g, bridge_diameter)),
        caps: optional("--cap-gap", args.cap_gap)?,
    };
    let contact_gap = optional("--contact-gap", args.contact_gap)?.unwrap_or(dp / 100.0);
    let treated = treatment::apply(&bed, &selected, range, &plan, contact_gap)?;
    warn_porosity(&treated.report, dp, args.quiet);
    let scale = args.units.scale();
    let unit = args.units.name();
    let provenance = format!("packbed bedexport {} from {}, unit {unit}", env!("CARGO_PKG_VERSION"), args.packing);
    let mut outputs = Vec::new();
    let mut files = Vec::new();
    let mut push = |path: &String, bytes: Vec<u8>, binary: bool, what: &str| {
        files.push((what.to_string(), path.clone()));
        outputs.push(OutputFile { path: path.clone(), bytes, binary, what: what.into() });
    };
    // Every surface to write: (pellet id or −1 for a bridge, solid name, mesh), cut to the window unless whole.
    let mut surfaces: Vec<(i32, String, pellet_geom::TriMesh)> = selected
        .iter()
        .zip(treated.meshes)
        .map(|(&i, m)| (i as i32, format!("pellet_{i:05}"), m))
        .chain(treated.bridges.into_iter().enumerate().map(|(k, b)| (-1, format!("bridge_{k:05}"), b.mesh)))
        .collect();
    let mut cut = 0;
    if let (Some((z0, z1)), false) = (window, args.whole_pellets) {
        let mut kept = Vec::with_capacity(surfaces.len());
        for (id, name, mesh) in surfaces {
            if let Some(clipped) = clip::clip_to_slab(&mesh, z0, z1).with_context(|| name.clone())? {
                cut += usize::from(clipped != mesh && id >= 0);
                kept.push((id, name, clipped));
            }
        }
        surfaces = kept;
    }
    let mut triangles = 0;
    if let Some(path) = &args.stl {
        let all: Vec<&pellet_geom::TriMesh> = surfaces.iter().map(|s| &s.2).collect();
        triangles = all.iter().map(|m| m.face_count()).sum();
        let bytes = match (args.ascii, args.solids) {
            (false, _) => stl::binary(&all, scale, &provenance),
            (true, Solids::Merged) => {
                let mut merged = pellet_geom::TriMesh::default();
                for m in &all {
                    let base = merged.vertices.len() as u32;
                    merged.vertices.extend_from_slice(&m.vertices);
                    merged.triangles.extend(m.triangles.iter().map(|t| t.map(|i| i + base)));
                }
                stl::ascii(&[("pellets".to_string(), &merged)], scale)
            }
            (true, Solids::PerPellet) => {
                let solids: Vec<(String, &pellet_geom::TriMesh)> =
                    surfaces.iter().map(|s| (s.1.clone(), &s.2)).collect();
                stl::ascii(&solids, scale)
            }
        };
        push(path, bytes, !args.ascii, "pellet STL");
    }
    if let Some(path) = &args.tube_stl {
        let tube = scene::tube_mesh(0.5 * bed.tube.diameter, range.0, range.1, args.tube_segments);
        let bytes = if args.ascii {
            stl::ascii(&[("tube".to_string(), &tube)], scale)
        } else {
            stl::binary(&[&tube], scale, &format!("tube; {provenance}"))
        };
        push(path, bytes, !args.ascii, "tube STL");
    }
    if let Some(path) = &args.vtk {
        let meshes: Vec<(i32, &pellet_geom::TriMesh)> = surfaces.iter().map(|s| (s.0, &s.2)).collect();
        push(path, vtk::polydata(&meshes, scale, &provenance), false, "pellet VTK");
    }
    if let Some(path) = &args.vtk_centres {
        push(path, vtk::centres(&bed, &selected, scale, &provenance), false, "centres VTK");
    }
    if let Some(path) = &args.csv {
        push(path, poses::csv(&bed, &selected, scale).into_bytes(), false, "poses CSV");
    }
    let mut voxel_result = None;
    if args.voxels.is_some() || args.vti.is_some() {
        let spacing = match (
            args.voxel_size.map(|v| positive_mm("--voxel-size", v).map(|v| v * MM)).transpose()?,
            args.voxels_per_dp,
        ) {
            (Some(h), _) => h,
            (None, Some(n)) if n.is_finite() && n > 0.0 => dp / n,
            (None, Some(n)) => bail!("--voxels-per-dp must be a finite number > 0 (got {n})"),
            (None, None) => dp / 10.0,
        };
        let quiet = args.quiet;
        let mut last = 0;
        let started = std::time::Instant::now();
        // Progress only when the grid takes long enough to wait for.
        let mut progress = |done: usize, total: usize| {
            let tenth = 10 * done / total.max(1);
            if !quiet && tenth > last && started.elapsed().as_secs_f64() > 1.0 {
                last = tenth;
                eprintln!("bedexport: voxels: {}% ({done}/{total} pellets)", 10 * tenth);
            }
        };
        let grid = voxels::voxelise(&bed, spacing, range, &mut progress)?;
        let exact = bulk_porosity(&bed, grid.z_range(), Geometry::Auto).ok().map(|b| b.porosity);
        if let Some(path) = &args.voxels {
            let raw_name = std::path::Path::new(path).file_name().map_or(path.clone(), |n| n.to_string_lossy().into());
            let extra = json!({
                "exact_porosity": exact,
                "z_range": [grid.z_range().0 * scale, grid.z_range().1 * scale],
                "tool": "bedexport",
                "version": env!("CARGO_PKG_VERSION"),
                "args": std::env::args().skip(1).collect::<Vec<_>>(),
            });
            let header = voxels::header_json(&grid, &raw_name, scale, unit, bed.tube.diameter, dp, extra);
            push(path, grid.data.clone(), true, "voxel raw");
            push(
                &format!("{path}.json"),
                (serde_json::to_string_pretty(&header)? + "\n").into_bytes(),
                false,
                "voxel header",
            );
        }
        if let Some(path) = &args.vti {
            push(path, vtk::image(&grid, scale, &provenance), false, "voxel VTK");
        }
        voxel_result = Some((grid, exact, dp));
    }
    pellet_io::write_outputs(&outputs)?;
    let exported = Exported {
        pellets: bed.pellets.len(),
        selected: selected.len(),
        cut,
        whole: window.is_none() || args.whole_pellets,
        range,
        triangles,
        report: treated.report,
        voxels: voxel_result,
        files,
    };
    let text = summary::text(&exported);
    if args.quiet {
        return Ok(Outcome::Success);
    }
    if paths.iter().any(|p| p.as_str() == "-") {
        eprint!("{text}");
    } else {
        pellet_cli::print_stdout(&text)?;
    }
    Ok(Outcome::Success)
}

/// A treatment's length flag (mm) checked against its range and turned into metres. Gaps are
/// at most dp / 5 and bridges at most dp / 2 across: the literature's treatments are 1–2 % of
/// dp (gaps) and 10–20 % (bridges), and a larger one is a different bed, not a treated one.
pub(crate) fn treatment_length(flag: &str, value: Option<f64>, dp: f64) -> anyhow::Result<Option<f64>> {
    let Some(v) = value else { return Ok(None) };
    let (hi, why) = if flag == "--bridge-diameter" { (dp / 2.0, "dp / 2") } else { (dp / 5.0, "dp / 5") };
    let why = format!(" (0 to {why} for these pellets)");
    Ok(Some(mm_in_range(flag, v, 0.0, hi / MM, false, &why)? * MM))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flags_parse() {
        let a = Args::try_parse_from(["bedexport", "b.packing", "--stl", "b.stl", "--shrink", "0.99", "--units", "m"])
            .unwrap();
        assert_eq!((a.stl.as_deref(), a.shrink, a.units), (Some("b.stl"), Some(0.99), Units::M));
        assert_eq!(a.solids, Solids::Merged);
        let b = Args::try_parse_from(["bedexport", "-", "--voxels", "v.raw", "--voxels-per-dp", "20"]).unwrap();
        assert_eq!(b.voxels_per_dp, Some(20.0));
        // Bridges and caps exclude each other; a bridge diameter needs bridges.
        assert!(Args::try_parse_from(["bedexport", "b", "--bridge-gap", "0.1", "--cap-gap", "0.1"]).is_err());
        assert!(Args::try_parse_from(["bedexport", "b", "--bridge-diameter", "1"]).is_err());
        assert!(Args::try_parse_from(["bedexport", "b", "--voxel-size", "1", "--voxels-per-dp", "2"]).is_err());
        assert_eq!(parse_window("0,100").unwrap(), (0.0, 0.1));
        for bad in ["10", "a,b", "5,5", "-1,3", "1,2,3"] {
            assert!(parse_window(bad).is_err(), "{bad}");
        }
    }
}
