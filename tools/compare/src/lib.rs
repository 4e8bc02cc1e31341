//! `compare`: scores packed beds against the literature's correlations and
//! experimental profiles, writes a report directory with plots, and gates
//! on quality (`--fail-above rmse=0.08` → exit 1 when a score is worse).
//!
//! The correlations and the scoring are in `pellet_refs`, the plots in
//! `pellet_plot`; this crate reads the inputs, assembles the beds and
//! writes the outputs.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use clap::{Parser, ValueEnum};

use pellet_cli::{mm_in_range, shown, Outcome};
use pellet_io::OutputFile;
use pellet_refs::radial::EpsBSource;
use pellet_refs::registry::{self, Reference};
use pellet_refs::scoring::{self, Bed, EpsBChoice, Score, ZUnit};
use pellet_refs::Shape;

mod beds;
mod gates;
mod inputs;
mod list;
mod plots;
mod report;

const EXAMPLES: &str = "\
Examples:
  compare out/profile.csv --summary out/summary.json --ref mueller-1992,de-klerk-2003,dixon-1988 -o out/report/
  compare theirs.csv --dp 10 --tube-diameter 50 --ref de-klerk,mueller --exp roshani.csv -o report/
  compare --summary a.json --summary b.json --summary c.json --ref dixon,foumeny,cheng -o report/ --fail-above mre=0.05
  compare out/profile.csv --summary out/summary.json -o report/ --fail-above rmse=0.08 --fail-below r2=0.5
  compare out/profile.csv --summary out/summary.json -o report/ --table -
  compare --list-refs

Outputs in the -o directory: scores.json, scores.csv, report.md, profile.png/.svg (when a profile is
given), porosity_vs_n.png/.svg (when bulk correlations are scored). Scores against grade C
correlations and outside a correlation's validity range are computed and flagged, never gated.
Exit codes: 0 success, 1 a --fail-above/--fail-below gate failed, 2 error.";

/// Score packed beds against the literature's correlations (bulk porosity
/// and radial void fraction) and experimental profiles, with plots.
#[derive(Debug, Parser)]
#[command(name = "compare", version = pellet_cli::LONG_VERSION, after_help = EXAMPLES, allow_negative_numbers = true)]
pub struct Args {
    /// Profile CSV(s) (`-` = stdin): needs `void_fraction` and
    /// `wall_distance_dp`, `wall_distance_dpv` or `wall_distance_mm`;
    /// optional `r_mm`, `void_fraction_std`. Several = several packings of
    /// one bed (scored as their mean, plotted with ± spread).
    #[arg(value_name = "PROFILE")]
    profiles: Vec<String>,
    /// A profile CSV (same as the positional argument; repeatable).
    #[arg(long = "profile", value_name = "CSV")]
    profile_flags: Vec<String>,
    /// voidprof summary JSON(s): bulk_porosity, shape, N, N_dpv, diameters.
    /// Several (repeat, or comma-separate) = several beds, for the MRE.
    #[arg(long = "summary", value_name = "JSON", value_delimiter = ',')]
    summaries: Vec<String>,
    /// References to score against, comma-separated (see --list-refs).
    /// Default: every radial correlation (with a profile) and every bulk
    /// one for the pellet shape.
    #[arg(long = "ref", value_name = "NAMES", value_delimiter = ',')]
    refs: Vec<String>,
    /// Experimental profile CSV(s), same columns as a profile; the
    /// simulated profile is interpolated at their wall distances.
    #[arg(long = "exp", value_name = "CSV")]
    exp: Vec<String>,
    /// Output directory (created if missing).
    #[arg(short, long, value_name = "DIR", required_unless_present = "list_refs")]
    output: Option<PathBuf>,
    /// Pellet diameter dp (mm), for a profile or bed without a summary.
    #[arg(long, value_name = "MM")]
    dp: Option<f64>,
    /// Volume-equivalent sphere diameter dpv (mm); spheres: = dp.
    #[arg(long, value_name = "MM")]
    dpv: Option<f64>,
    /// Tube diameter D (mm).
    #[arg(long, value_name = "MM")]
    tube_diameter: Option<f64>,
    /// Pellet shape (default: the summary's, else sphere).
    #[arg(long, value_enum)]
    shape: Option<ShapeArg>,
    /// Rings: inner over outer diameter (for the ring envelope estimate).
    #[arg(long, value_name = "RATIO")]
    ring_di_do: Option<f64>,
    /// Wadell sphericity φ of the pellets (for the sphericity form of
    /// Benyahia & O'Neill; spheres: 1; equilateral cylinders: 0.874).
    #[arg(long, value_name = "PHI")]
    sphericity: Option<f64>,
    /// Bulk porosity of the bed, when neither a summary nor a whole-tube
    /// profile gives it.
    #[arg(long, value_name = "EPS")]
    bulk_porosity: Option<f64>,
    /// What scales the wall distance z = (R − r)/length of the profile; the
    /// radial correlations are defined with dp.
    #[arg(long, value_enum, default_value = "dp")]
    wall_unit: WallUnit,
    /// ε_b for de Klerk, Cohen & Metzner, Martin, Bey & Eigenberger:
    /// `fitted` (profile's cross-section mean = bed's bulk porosity; the
    /// default, since ε_b is the voidage far from the wall), `bulk` (the
    /// bed's bulk porosity as given) or a number.
    #[arg(long, value_name = "fitted|bulk|VALUE", default_value = "fitted")]
    eps_b: String,
    /// Exit 1 if a gated score is above a limit: `rmse=0.08,mre=0.05`
    /// (metrics: rmse, mae, max_abs_error, mre, relative_error).
    #[arg(long, value_name = "METRIC=LIMIT,...")]
    fail_above: Vec<String>,
    /// Exit 1 if a gated score is below a limit: `r2=0.5`.
    #[arg(long, value_name = "METRIC=LIMIT,...")]
    fail_below: Vec<String>,
    /// Also write the scores as an aligned text table to FILE (`-` = stdout, in place of the
    /// line per score): reference, kind, grade, rmse and r2 of a profile (void fraction,
    /// dimensionless), simulated and predicted bulk porosity (dimensionless) and their relative
    /// error (%), and a note for scores that are not gated.
    #[arg(long, value_name = "FILE")]
    table: Option<String>,
    /// Skip the plots.
    #[arg(long)]
    no_plots: bool,
    /// List the references (names, aliases, grade, range, N definition) and exit.
    #[arg(long)]
    list_refs: bool,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum ShapeArg {
    Sphere,
    Cylinder,
    Ring,
}

impl From<ShapeArg> for Shape {
    fn from(s: ShapeArg) -> Shape {
        match s {
            ShapeArg::Sphere => Shape::Sphere,
            ShapeArg::Cylinder => Shape::Cylinder,
            ShapeArg::Ring => Shape::Ring,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum WallUnit {
    Dp,
    Dpv,
}

/// ε_b as asked on the command line.
#[derive(Clone, Copy, Debug, PartialEq)]
enum EpsBMode {
    Fitted,
    Bulk,
    Value(f64),
}

fn parse_eps_b(s: &str) -> Result<EpsBMode> {
    match s.trim() {
        "fitted" => Ok(EpsBMode::Fitted),
        "bulk" | "given" => Ok(EpsBMode::Bulk),
        v => match v.parse::<f64>() {
            Ok(x) if x > 0.0 && x < 1.0 => Ok(EpsBMode::Value(x)),
            _ => bail!("--eps-b must be fitted, bulk or a number in (0, 1) (got {v:?})"),
        },
    }
}

/// Runs the tool.
pub fn run(args: Args) -> Result<Outcome> {
    if args.list_refs {
        pellet_cli::print_stdout(&list::table())?;
        return Ok(Outcome::Success);
    }
    let out_dir = args.output.clone().context("-o DIR is required")?;
    if out_dir.as_os_str() == "-" {
        bail!("-o takes a directory (the report has several files), not - for stdout");
    }
    // Lengths as pack and mkpellet take them: up to 10 m.
    for (flag, v) in [("--dp", args.dp), ("--dpv", args.dpv), ("--tube-diameter", args.tube_diameter)] {
        if let Some(v) = v {
            mm_in_range(flag, v, 0.0, 1e4, false, "")?;
        }
    }
    if let Some(r) = args.ring_di_do {
        if !(r > 0.0 && r < 1.0) {
            bail!("--ring-di-do must lie in (0, 1) (got {})", shown(r));
        }
    }
    if let Some(phi) = args.sphericity {
        if !(phi > 0.0 && phi <= 1.0) {
            bail!("--sphericity must lie in (0, 1] (got {}): 1 for spheres, less for any other shape", shown(phi));
        }
    }
    let eps_b_mode = parse_eps_b(&args.eps_b)?;
    let mut gate_list = gates::parse(&args.fail_above, true)?;
    gate_list.extend(gates::parse(&args.fail_below, false)?);

    let profile_paths: Vec<String> = args.profiles.iter().chain(&args.profile_flags).cloned().collect();
    if profile_paths.is_empty() && args.summaries.is_empty() {
        bail!("nothing to compare: give a profile CSV and/or --summary JSON (see --help)");
    }
    if profile_paths.iter().chain(&args.exp).chain(&args.summaries).filter(|p| *p == "-").count() > 1 {
        bail!("only one input can be read from stdin (-)");
    }
    // Every file the report may write into -o DIR.
    let written = ["scores.json", "scores.csv", "report.md", "profile.png", "profile.svg"]
        .into_iter()
        .chain(["porosity_vs_n.png", "porosity_vs_n.svg"])
        .map(|n| ("-o".to_string(), out_dir.join(n).display().to_string()))
        .chain(args.table.iter().map(|t| ("--table".to_string(), t.clone())));
    pellet_cli::refuse_clashing_outputs(profile_paths.iter().chain(&args.exp).chain(&args.summaries), written)?;
    let unit = match args.wall_unit {
        WallUnit::Dp => ZUnit::Dp,
        WallUnit::Dpv => ZUnit::Dpv,
    };
    let input = beds::Inputs::read(&args, &profile_paths, unit)?;
    let mut info = input.info.clone();
    let shape = input.beds.first().map_or(Shape::Sphere, |b| b.shape);
    let has_profile = input.profile.is_some();

    let references: Vec<Reference> = if args.refs.is_empty() {
        registry::defaults(shape)
            .into_iter()
            .filter(|r| has_profile || matches!(r, Reference::Bulk(_)))
            .filter(|r| !matches!(r, Reference::Bulk(_)) || input.beds.iter().all(|b| b.bulk_porosity.is_some()))
            .collect()
    } else {
        let mut v: Vec<Reference> = Vec::new();
        for name in args.refs.iter().map(|s| s.trim()).filter(|s| !s.is_empty()) {
            let r = registry::resolve(name, shape)?;
            if !v.iter().any(|x| std::ptr::eq(ref_ptr(x), ref_ptr(&r))) {
                v.push(r);
            }
        }
        v
    };

    let mut scores = Vec::new();
    let mut curves = Vec::new();
    let explicit = !args.refs.is_empty();
    for r in &references {
        match score_one(r, &input, eps_b_mode) {
            Ok((score, curve)) => {
                scores.push(score);
                curves.extend(curve);
            }
            // A default reference the inputs cannot feed is skipped, not fatal.
            Err(e) if !explicit => eprintln!("compare: warning: skipped {}: {}", r.name(), pellet_cli::one_line(&e)),
            Err(e) => return Err(e),
        }
    }
    for path in &args.exp {
        let Some(profile) = &input.profile else { bail!("--exp {path}: give a simulated profile CSV to compare with") };
        let (name, z, eps) = beds::read_experiment(path, unit, input.lengths_mm)?;
        let score = scoring::score_experimental(&name, &profile.profile, &z, &eps)
            .with_context(|| format!("{path}: no data point inside the simulated profile's range"))?;
        curves.push(plots::experiment_points(&name, &z, &eps));
        scores.push(Score::Profile(score));
    }
    if scores.is_empty() {
        bail!("no score to compute: give --ref names (see --list-refs)");
    }
    let (violations, unused) = gates::check(&scores, &gate_list);

    pellet_cli::create_output_dir("-o", &out_dir)?;
    let mut plot_paths = Vec::new();
    if !args.no_plots {
        if let Some(profile) = &input.profile {
            let frame = plots::profile_frame(profile, input.beds.first(), &input.summaries);
            plot_paths.extend(plots::profile_plot(&out_dir, profile, input.beds.first(), &frame, &curves)?);
        }
        let bulk: Vec<&scoring::BulkScore> =
            scores.iter().filter_map(|s| if let Score::Bulk(b) = s { Some(b) } else { None }).collect();
        if !bulk.is_empty() {
            plot_paths.extend(plots::porosity_plot(&out_dir, &references, &input.beds, &bulk)?);
        }
    }
    info.eps_b_mode = match eps_b_mode {
        EpsBMode::Fitted => "fitted (the profile's cross-section mean equals the bed's bulk porosity)".into(),
        EpsBMode::Bulk => "given: the bed's bulk porosity".into(),
        EpsBMode::Value(v) => format!("given: {v}"),
    };
    let mut outputs = report::outputs(&out_dir, &info, &scores, &gate_list, &violations, &plot_paths)?;
    let table_on_stdout = args.table.as_deref() == Some("-");
    if let Some(path) = args.table.as_ref().filter(|_| !table_on_stdout) {
        outputs.push(OutputFile {
            path: path.clone(),
            bytes: report::table(&scores).into_bytes(),
            binary: false,
            what: "score table".into(),
        });
    }
    pellet_io::write_outputs(&outputs)?;
    for g in &unused {
        eprintln!("compare: warning: gate {}={} applies to no gated score", g.metric, g.limit);
    }
    pellet_cli::print_stdout(&report::stdout_summary(&scores, table_on_stdout, &violations, &out_dir, &plot_paths))?;
    Ok(if violations.is_empty() { Outcome::Success } else { Outcome::CheckFailed })
}

/// Scores one reference; radial ones also give their plot curve.
fn score_one(
    r: &Reference,
    input: &beds::Inputs,
    eps_b_mode: EpsBMode,
) -> Result<(Score, Option<pellet_plot::RefCurve>)> {
    match r {
        Reference::Radial(c) => {
            let (profile, bed) = match (&input.profile, input.beds.first()) {
                (Some(p), Some(b)) => (p, b),
                _ => bail!("{} is a radial profile correlation: give a profile CSV", c.name),
            };
            let choice = match c.eps_b {
                // Mueller's form computes its own ε_b from N; the choice is not used.
                EpsBSource::OwnFromN => EpsBChoice::Given(f64::NAN),
                EpsBSource::Parameter => eps_b_choice(eps_b_mode, bed, c.name)?,
            };
            let score = scoring::score_radial(c, &profile.profile, bed, choice)?
                .with_context(|| format!("{}: no profile point at a wall distance ≥ 0", profile.source))?;
            let curve = plots::radial_reference(c, profile, bed, choice)?;
            Ok((Score::Profile(score), Some(curve)))
        }
        Reference::Bulk(c) => Ok((Score::Bulk(scoring::score_bulk(c, &input.beds)?), None)),
    }
}

fn ref_ptr(r: &Reference) -> *const () {
    match r {
        Reference::Bulk(c) => *c as *const _ as *const (),
        Reference::Radial(c) => *c as *const _ as *const (),
    }
}

fn eps_b_choice(mode: EpsBMode, bed: &Bed, name: &str) -> Result<EpsBChoice> {
    Ok(match mode {
        EpsBMode::Value(v) => EpsBChoice::Given(v),
        EpsBMode::Bulk | EpsBMode::Fitted => {
            let bulk = bed.bulk_porosity.with_context(|| {
                format!("{name} needs the bed's bulk porosity for ε_b: give --summary, --bulk-porosity, a whole-tube profile with the tube diameter, or --eps-b VALUE")
            })?;
            if mode == EpsBMode::Bulk {
                EpsBChoice::Given(bulk)
            } else {
                EpsBChoice::Fitted { bulk_porosity: bulk }
            }
        }
    })
}

/// The file stem used for the plots in the output directory.
pub(crate) fn plot_path(dir: &Path, stem: &str, ext: &str) -> PathBuf {
    dir.join(format!("{stem}.{ext}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(args: &[&str]) -> Args {
        Args::try_parse_from(std::iter::once("compare").chain(args.iter().copied())).unwrap()
    }

    #[test]
    fn flags_parse() {
        let a = parse(&["p.csv", "--summary", "a.json,b.json", "--ref", "de-klerk,mueller", "-o", "r"]);
        assert_eq!(a.profiles, ["p.csv"]);
        assert_eq!(a.summaries, ["a.json", "b.json"]);
        assert_eq!(a.refs, ["de-klerk", "mueller"]);
        assert_eq!(a.wall_unit, WallUnit::Dp);
        assert_eq!(parse_eps_b(&a.eps_b).unwrap(), EpsBMode::Fitted);
        let a = parse(&["--profile", "p.csv", "--shape", "cylinder", "--wall-unit", "dpv", "-o", "r"]);
        assert_eq!((a.profile_flags.len(), a.shape, a.wall_unit), (1, Some(ShapeArg::Cylinder), WallUnit::Dpv));
        assert!(Args::try_parse_from(["compare", "p.csv"]).is_err(), "-o is required");
        assert!(parse(&["--list-refs"]).list_refs);
    }

    #[test]
    fn eps_b_modes() {
        assert_eq!(parse_eps_b("bulk").unwrap(), EpsBMode::Bulk);
        assert_eq!(parse_eps_b("0.38").unwrap(), EpsBMode::Value(0.38));
        assert!(parse_eps_b("1.5").is_err());
        assert!(parse_eps_b("fit").is_err());
    }
}
