//! `voidprof`: the radial void fraction ε(r), the axial profile ε(z) and
//! the exact bulk porosity of packed beds, from `.packing` files or from
//! pellet poses made elsewhere (CSV).
//!
//! [`run`] reads the inputs, [`measure`] computes a [`Measurement`] (the
//! mean profile and its spread over the beds, ready for a plot), and the
//! `output` module turns it into the CSV and JSON outputs.

use anyhow::{bail, Context};
use clap::Parser;

use pellet_analysis::{
    average_profiles, bulk_porosity, coordination, deepest_overlap, orientation, reference_diameters, void_profile,
    BulkPorosity, Coordination, DeepestOverlap, Geometry, OrientationHistogram, ProfileParams, ProfileStats,
    VoidProfile,
};
use pellet_cli::{mm_in_range, parse_window, positive_mm, Outcome};
use pellet_geom::{Bed, Tube};
use pellet_io::OutputFile;

mod output;
mod poses;

const MM: f64 = 1e-3;

const EXAMPLES: &str = "\
Examples:
  voidprof bed.packing -o profile.csv --summary bed.json --plot profile.png --plot profile.svg
  voidprof a.packing b.packing c.packing -o mean.csv --spread spread.csv --summary abc.json
  voidprof --poses bed.csv --pellet sphere.pellet --tube-diameter 59.6 --window 0,100 -o -
  settle-check run.mcap -o - | voidprof - --axial axial.csv --structure --summary s.json -o profile.csv

Output CSV header: r_mm,wall_distance_mm,wall_distance_dp,wall_distance_dpv,void_fraction
All lengths are in millimetres; the tube axis is z and the floor z = 0.
Exit codes: 0 success, 2 error.";

/// Measure packed beds: radial void fraction ε(r) on coaxial cylinders, the
/// axial profile ε(z) and the exact bulk porosity of an axial window.
#[derive(Debug, Parser)]
#[command(name = "voidprof", version = pellet_cli::LONG_VERSION, after_help = EXAMPLES, allow_negative_numbers = true)]
pub struct Args {
    /// Packing files (from settle-check); `-` reads one from stdin. Several
    /// beds give the mean profile and its spread.
    #[arg(conflicts_with = "poses")]
    pub packings: Vec<String>,
    /// Pellet poses from another generator, as CSV: id,x,y,z (mm) and qw,qx,qy,qz unless spheres.
    #[arg(long, requires_all = ["pellet", "tube_diameter"])]
    pub poses: Option<String>,
    /// The pellet file for --poses (from mkpellet).
    #[arg(long, requires = "poses")]
    pub pellet: Option<String>,
    /// Inner tube diameter for --poses (mm).
    #[arg(long, requires = "poses")]
    pub tube_diameter: Option<f64>,
    /// Axial window z0,z1 (mm) [default: from the floor to one pellet diameter dp below the
    /// bed's top (its highest pellet point), leaving out the loose top layer; the lowest top of
    /// several beds; the whole bed when it is under 2 dp tall]. The paper counts 0,100.
    #[arg(long, allow_hyphen_values = true)]
    pub window: Option<String>,
    /// Radial step (mm, up to dp/2), from the wall inward [default: dp/50].
    #[arg(long)]
    pub dr: Option<f64>,
    /// Spacing of the sampled lines along each circle (mm, up to dp/2) [default: dp/250].
    #[arg(long)]
    pub arc: Option<f64>,
    /// Bin height of the axial profile (mm, up to dp/2) [default: dp/20].
    #[arg(long)]
    pub dz: Option<f64>,
    /// Intersect the triangle meshes even where the exact shape is known.
    #[arg(long)]
    pub mesh: bool,
    /// The radial profile as CSV (`-` = stdout).
    #[arg(short, long, default_value = "-")]
    pub output: String,
    /// A JSON summary: bulk porosity, window, pellets, shape, dp, dpv, N, …
    #[arg(long)]
    pub summary: Option<String>,
    /// The axial profile ε(z) as CSV: z_mm,z_dp,void_fraction.
    #[arg(long)]
    pub axial: Option<String>,
    /// The radial profile of every bed with mean, standard deviation, min and max, as CSV.
    #[arg(long)]
    pub spread: Option<String>,
    /// Add the coordination number, the orientation of pellet axes and the deepest overlap
    /// between two pellets and between a pellet and the tube (mm and fraction of dpv, over
    /// the whole bed, on the exact shapes) to the summary.
    #[arg(long)]
    pub structure: bool,
    /// Draw ε against (R − r)/dp to this file (.png or .svg; repeat for both); the plot marks
    /// the wall and the axis and names the window and the number of beds.
    #[arg(long, value_name = "FILE")]
    pub plot: Vec<String>,
    /// Surface gap below which two pellets count as touching (mm, up to dp/5) [default: dp/100].
    #[arg(long)]
    pub contact_gap: Option<f64>,
}

/// One measured bed.
pub struct BedResult {
    /// Where it came from.
    pub source: String,
    /// Pellets in the bed.
    pub pellets: usize,
    /// The radial (and axial) profile.
    pub profile: VoidProfile,
    /// Bulk porosity of the window.
    pub bulk: BulkPorosity,
    /// Contacts, with --structure and a closed-form shape.
    pub coordination: Option<Coordination>,
    /// Axis orientations, with --structure and an axial shape.
    pub orientation: Option<OrientationHistogram>,
    /// The deepest overlaps of the whole bed, with --structure and a closed-form shape.
    pub overlap: Option<DeepestOverlap>,
}

/// Everything `voidprof` reports: each bed and the mean over the beds.
pub struct Measurement {
    /// The beds, in the order given.
    pub beds: Vec<BedResult>,
    /// Mean radial profile and its spread (what a plot draws).
    pub stats: ProfileStats,
    /// Pellet diameter dp (m).
    pub dp: f64,
    /// Equal-volume sphere diameter dpv (m).
    pub dpv: f64,
    /// Shape name of the first pellet type.
    pub shape: String,
    /// Tube diameter (m).
    pub tube_diameter: f64,
    /// The window (m).
    pub window: (f64, f64),
    /// How the window was chosen: `None` when given by `--window`, else the default's rule
    /// with the bed top it was taken from.
    pub window_rule: Option<String>,
    /// Whether meshes were used throughout.
    pub mesh: bool,
}

/// Runs `voidprof`.
pub fn run(args: Args) -> anyhow::Result<Outcome> {
    let inputs = args.packings.iter().chain(&args.poses).chain(&args.pellet);
    let singles = [("--summary", &args.summary), ("--axial", &args.axial), ("--spread", &args.spread)];
    let outputs = std::iter::once(("-o".to_string(), args.output.clone()))
        .chain(singles.iter().filter_map(|(f, p)| p.as_ref().map(|p| (f.to_string(), p.clone()))))
        .chain(args.plot.iter().map(|p| ("--plot".to_string(), p.clone())));
    pellet_cli::refuse_clashing_outputs(inputs, outputs)?;
    let beds = read_beds(&args)?;
    let m = measure(&args, beds)?;
    if let Some(rule) = &m.window_rule {
        eprintln!("voidprof: window {:.3} to {:.3} mm ({rule})", m.window.0 * 1e3, m.window.1 * 1e3);
    }
    let mut outputs = vec![OutputFile {
        path: args.output.clone(),
        bytes: output::radial_csv(&m).into_bytes(),
        binary: false,
        what: "profile CSV".into(),
    }];
    if let Some(path) = &args.summary {
        let text = serde_json::to_string_pretty(&output::summary(&m))? + "\n";
        outputs.push(OutputFile {
            path: path.clone(),
            bytes: text.into_bytes(),
            binary: false,
            what: "summary".into(),
        });
    }
    if let Some(path) = &args.axial {
        let bytes = output::axial_csv(&m).into_bytes();
        outputs.push(OutputFile { path: path.clone(), bytes, binary: false, what: "axial CSV".into() });
    }
    if let Some(path) = &args.spread {
        let bytes = output::spread_csv(&m).into_bytes();
        outputs.push(OutputFile { path: path.clone(), bytes, binary: false, what: "spread CSV".into() });
    }
    pellet_io::write_outputs(&outputs)?;
    for path in &args.plot {
        plot(&m, std::path::Path::new(path)).with_context(|| path.clone())?;
    }
    Ok(Outcome::Success)
}

/// ε against the wall distance in dp: the mean over the beds, with ± one
/// standard deviation as a band when there are several. The chart marks the
/// wall and the axis, and its caption names the axial window and says
/// whether the profile is one bed (a single sample) or a mean.
fn plot(m: &Measurement, path: &std::path::Path) -> anyhow::Result<()> {
    let s = &m.stats;
    // Wall first, so that x ascends.
    let order: Vec<usize> = (0..s.radius.len()).rev().collect();
    let x: Vec<f64> = order.iter().map(|&i| (s.tube_radius - s.radius[i]) / m.dp).collect();
    let y: Vec<f64> = order.iter().map(|&i| s.mean[i]).collect();
    let label = if s.count > 1 { format!("mean of {} beds ± 1 s.d.", s.count) } else { "simulated".to_string() };
    let mut series = pellet_plot::ProfileSeries::new(label, x, y);
    if s.count > 1 {
        series.spread = Some(order.iter().map(|&i| s.std[i]).collect());
    }
    let title =
        format!("{} bed, D = {:.2} mm, N = D/dp = {:.2}", m.shape, m.tube_diameter * 1e3, m.tube_diameter / m.dp);
    pellet_plot::plot_profile(path, &title, &plot_frame(m), &[series], &[]).map_err(|e| anyhow::anyhow!("{e}"))
}

/// The plot's wall (x = 0), axis (x = R/dp) and caption: the window and how many beds.
fn plot_frame(m: &Measurement) -> pellet_plot::ProfileFrame {
    let how = if m.window_rule.is_some() { "voidprof's default window" } else { "given by --window" };
    let window = format!("{} ({how})", pellet_plot::window_note(m.window.0 / MM, m.window.1 / MM));
    let beds = match m.beds.as_slice() {
        [one] => pellet_plot::single_bed_note(if one.source == "-" { "stdin" } else { &one.source }),
        many => pellet_plot::spread_note(many.len(), "beds"),
    };
    pellet_plot::ProfileFrame::wall_distance(Some(m.stats.tube_radius / m.dp)).with_note(window).with_note(beds)
}

/// Reads the beds named by the arguments.
pub fn read_beds(args: &Args) -> anyhow::Result<Vec<(String, Bed)>> {
    if let Some(poses_path) = &args.poses {
        let pellet_path = args.pellet.as_deref().context("--poses needs --pellet")?;
        let diameter = positive_mm("--tube-diameter", args.tube_diameter.context("--poses needs --tube-diameter")?)?;
        if pellet_path == "-" && poses_path == "-" {
            bail!("only one of --pellet and --poses can read stdin (-)");
        }
        let pellet = pellet_io::decode_pellet(&pellet_io::read_input(pellet_path)?, pellet_path)?.pellet;
        let is_sphere = matches!(pellet.shape, pellet_geom::ShapeSpec::Sphere { .. });
        let poses = pellet_io::decode_poses_csv(&pellet_io::read_input(poses_path)?, poses_path, !is_sphere)?;
        let bed = Bed {
            tube: Tube { diameter: diameter * MM, lid_height: None },
            pellet_types: vec![pellet],
            pellets: poses,
        };
        bed.validate().with_context(|| poses_path.clone())?;
        if bed.pellets.is_empty() {
            bail!("{poses_path}: no pellet poses (the file holds no data rows)");
        }
        let (dp, _) = reference_diameters(&bed).with_context(|| poses_path.clone())?;
        if let Some(warning) = poses::check(&bed, poses_path, dp)? {
            eprintln!("voidprof: warning: {warning}");
        }
        return Ok(vec![(poses_path.clone(), bed)]);
    }
    if args.packings.is_empty() {
        bail!("give a packing file (or - for stdin), or --poses with --pellet and --tube-diameter");
    }
    if args.packings.iter().filter(|p| *p == "-").count() > 1 {
        bail!("stdin (-) can be read only once");
    }
    args.packings
        .iter()
        .map(|path| Ok((path.clone(), pellet_io::decode_packing(&pellet_io::read_input(path)?, path)?.bed)))
        .collect()
}

/// Measures every bed and averages the profiles.
pub fn measure(args: &Args, beds: Vec<(String, Bed)>) -> anyhow::Result<Measurement> {
    let (window, window_rule) = match &args.window {
        Some(text) => (parse_window(text)?, None),
        None => default_window(&beds)?,
    };
    let (first_source, first_bed) = beds.first().context("no beds")?;
    let (dp, dpv) = reference_diameters(first_bed).with_context(|| first_source.clone())?;
    // Steps above half a pellet resolve nothing of the profile, and a gap above dp / 5 counts
    // neighbours that do not touch; the lower ends are bounded by the work they ask for.
    let ranged = |flag: &str, v: Option<f64>, hi: f64, why: &str| {
        v.map(|v| mm_in_range(flag, v, 0.0, hi / MM, false, why).map(|v| v * MM)).transpose()
    };
    let step = |flag: &str, v: Option<f64>| ranged(flag, v, dp / 2.0, " (0 to dp / 2 for these pellets)");
    let geometry = if args.mesh { Geometry::Mesh } else { Geometry::Auto };
    let params = ProfileParams {
        window,
        radial_step: step("--dr", args.dr)?,
        arc_step: step("--arc", args.arc)?,
        axial_step: step("--dz", args.dz)?,
        geometry,
    };
    let gap = ranged("--contact-gap", args.contact_gap, dp / 5.0, " (0 to dp / 5 for these pellets)")?;
    let shape = first_bed.pellet_types[0].shape.kind().to_string();
    let tube_diameter = first_bed.tube.diameter;
    let mut results = Vec::new();
    for (source, bed) in beds {
        let hint =
            |e: pellet_analysis::AnalysisError| anyhow::anyhow!("{source}: {e} (set it with --window z0,z1 in mm)");
        let profile = void_profile(&bed, &params).map_err(|e| match e {
            pellet_analysis::AnalysisError::Window { .. } => hint(e),
            other => anyhow::anyhow!("{source}: {other}"),
        })?;
        let bulk = bulk_porosity(&bed, window, geometry).with_context(|| source.clone())?;
        let (coordination, orientation, overlap) = if args.structure {
            (
                coordination(&bed, window, gap.unwrap_or(dp / 100.0)),
                orientation(&bed, window, 10.0),
                deepest_overlap(&bed),
            )
        } else {
            (None, None, None)
        };
        let pellets = bed.pellets.len();
        results.push(BedResult { source, pellets, profile, bulk, coordination, orientation, overlap });
    }
    let profiles: Vec<VoidProfile> = results.iter().map(|b| b.profile.clone()).collect();
    let stats = average_profiles(&profiles)?;
    Ok(Measurement { beds: results, stats, dp, dpv, shape, tube_diameter, window, window_rule, mesh: args.mesh })
}

/// The window when `--window` is not given: from the floor to one pellet diameter dp below
/// the top of the bed (its highest pellet point), so that the loose top layer is left out;
/// over several beds the lowest top; a bed under 2 dp tall is taken whole. Returns the window
/// (m) and the rule with the numbers it used, for the summary and stderr.
pub fn default_window(beds: &[(String, Bed)]) -> anyhow::Result<((f64, f64), Option<String>)> {
    let (first_source, first_bed) = beds.first().context("no beds")?;
    let (dp, _) = reference_diameters(first_bed).with_context(|| first_source.clone())?;
    let top = beds.iter().map(|(_, bed)| pellet_analysis::bed_top(bed)).fold(f64::INFINITY, f64::min);
    if top <= 0.0 {
        bail!("{first_source}: the bed has no pellets above the floor (set a window with --window z0,z1 in mm)");
    }
    let (z1, rule) = if top >= 2.0 * dp {
        (top - dp, format!("default: z = 0 to the bed's top ({:.3} mm) minus dp ({:.3} mm)", top / MM, dp / MM))
    } else {
        (top, format!("default: z = 0 to the bed's top ({:.3} mm); the bed is under 2 dp tall", top / MM))
    };
    Ok(((0.0, z1), Some(rule)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flags_parse() {
        let a =
            Args::try_parse_from(["voidprof", "a.packing", "b.packing", "--window", "10,90", "--dr", "0.1"]).unwrap();
        assert_eq!(a.packings, ["a.packing", "b.packing"]);
        assert_eq!(parse_window(a.window.as_deref().unwrap()).unwrap(), (0.010, 0.090));
        assert_eq!(a.dr, Some(0.1));
        assert_eq!(a.output, "-");
        let p =
            Args::try_parse_from(["voidprof", "--poses", "b.csv", "--pellet", "s.pellet", "--tube-diameter", "59.6"])
                .unwrap();
        assert_eq!(p.tube_diameter, Some(59.6));
        // --poses needs the pellet and the tube; and excludes packing files.
        assert!(Args::try_parse_from(["voidprof", "--poses", "b.csv"]).is_err());
        assert!(Args::try_parse_from([
            "voidprof",
            "a.packing",
            "--poses",
            "b.csv",
            "--pellet",
            "s.pellet",
            "--tube-diameter",
            "30"
        ])
        .is_err());
        for bad in ["10", "a,b", "5,5", "9,1", "1,2,3", "0,inf"] {
            assert!(parse_window(bad).is_err(), "{bad}");
        }
    }
}
