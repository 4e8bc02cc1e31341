//! `paper-report`: the paper's validation study as a report, from
//! whatever beds `pipelines/paper.mk` has finished.
//!
//! [`table`] reads the bed table, [`collect`] finds each bed's files,
//! [`analysis`] turns them into the study's numbers, and [`figures`],
//! [`page`] and [`summary`] write them. Missing beds are listed, never
//! guessed.

use std::path::Path;

use anyhow::{bail, Context};
use clap::Parser;

use pellet_cli::Outcome;
use pellet_io::OutputFile;
use pellet_refs::Shape;

pub mod analysis;
pub mod collect;
pub mod figures;
pub mod page;
pub mod progress;
pub mod stats;
pub mod summary;
pub mod table;

const EXAMPLES: &str = "\
Examples:
  paper-report --table pipelines/paper/beds.csv --runs docs/validation/runs --runs out/paper/runs -o docs/validation
  paper-report --table pipelines/paper/beds.csv --runs out/paper/runs --repeats 1 -o /tmp/v

Writes to the -o directory: README.md (the page), summary.json, PNG figures and
beds/<id>.csv (settled poses of each finished validation bed, mm). A bed's
record comes from the first --runs directory that holds its <id>.summary.json;
its poses from the first that holds <id>.poses.csv (where none does, an
existing beds/<id>.csv is left as it is). Beds of the table without a summary
in any --runs directory are listed as missing.
Exit codes: 0 success, 2 error.";

/// Write the validation report of the paper's study from the
/// beds that `make paper` (pipelines/paper.mk) has finished.
#[derive(Debug, Parser)]
#[command(name = "paper-report", version = pellet_cli::LONG_VERSION, after_help = EXAMPLES)]
pub struct Args {
    /// The bed table (CSV: config, study, shape, tube_diameter_mm (mm), seeds, scheme, cor, friction, …).
    #[arg(long, value_name = "CSV")]
    pub table: String,
    /// Directory of the beds' files (ID.summary.json, ID.profile.csv, ID.settle.json, ID.poses.csv, ID.*.time);
    /// repeat to search several, in order (the committed archive, then the work directory).
    #[arg(long, value_name = "DIR", required = true)]
    pub runs: Vec<String>,
    /// Count only seeds 1..K of every row (as `make paper REPEATS=K`) [default: every seed of the table].
    #[arg(long, value_name = "K")]
    pub repeats: Option<u32>,
    /// Output directory (created if missing).
    #[arg(short, long, value_name = "DIR")]
    pub output: String,
}

/// Runs `paper-report`.
pub fn run(args: Args) -> anyhow::Result<Outcome> {
    if args.repeats == Some(0) {
        bail!("--repeats must be at least 1 (got 0)");
    }
    let text = String::from_utf8(pellet_io::read_input(&args.table)?)
        .with_context(|| format!("{}: not UTF-8 text", args.table))?;
    let rows = table::parse(&text, &args.table)?;
    let runs: Vec<&Path> = args.runs.iter().map(Path::new).collect();
    if let Some(missing) = runs.iter().find(|r| !r.is_dir()) {
        bail!("--runs {}: not a directory (run `make paper-validation` first)", missing.display());
    }
    let groups = collect::collect(&rows, &runs, args.repeats)?;
    let out = Path::new(&args.output);
    pellet_cli::create_output_dir("-o", out)?;

    let shapes = [Shape::Sphere, Shape::Cylinder, Shape::Ring];
    let validation: Vec<_> = shapes
        .iter()
        .map(|&s| {
            let (tubes, mre) = analysis::validation(&groups, s);
            (s, tubes, mre)
        })
        .collect();
    let profiles = analysis::profiles(&groups);
    let cor = analysis::parameter_study(&groups, "cor");
    let friction = analysis::parameter_study(&groups, "friction");

    let mut figures = Vec::new();
    for (shape, tubes, _) in &validation {
        if let Some(f) = figures::porosity_vs_n(out, *shape, tubes)? {
            figures.push((format!("Bulk porosity against N, {}s, with the correlations (Fig. 14)", shape.name()), f));
        }
    }
    for p in &profiles {
        let caption = match p.shape {
            Shape::Sphere => format!("Radial void fraction, spheres N = {:.2}, vs de Klerk and Mueller (Fig. 16)", p.n),
            Shape::Cylinder => format!(
                "Radial void fraction, cylinders N = {:.2}; de Klerk dashed: a sphere correlation, z/dpv (Fig. 17)",
                p.n
            ),
            Shape::Ring => format!("Radial void fraction, Raschig rings N = {:.2} (Fig. 18)", p.n),
        };
        figures.push((caption, figures::profile(out, p)?));
    }
    for (study, series, caption) in [
        ("cor", &cor, "Bulk porosity against COR (Fig. 10)"),
        ("friction", &friction, "Bulk porosity against friction (Fig. 11)"),
    ] {
        if let Some(f) = figures::parameter(out, study, series)? {
            figures.push((caption.to_string(), f));
        }
    }

    let compute_seconds: f64 = collect::distinct_beds(&groups).iter().map(|b| b.seconds).sum();
    let machine = summary::machine();
    let shape_refs: Vec<(&str, &[analysis::TubeResult], Option<f64>)> =
        validation.iter().map(|(s, t, m)| (s.name(), t.as_slice(), *m)).collect();
    let json = summary::summary(&shape_refs, &profiles, compute_seconds, &machine);
    let page = page::Page {
        command: format!("paper-report {}", std::env::args().skip(1).collect::<Vec<_>>().join(" ")),
        groups: &groups,
        validation,
        profiles: &profiles,
        cor: &cor,
        friction: &friction,
        figures,
        compute_seconds,
        machine,
        parked: parked_runs(out, &crate::collect::distinct_missing(&groups)),
    };

    let mut outputs = vec![
        OutputFile {
            path: out.join("summary.json").display().to_string(),
            bytes: (serde_json::to_string_pretty(&json)? + "\n").into_bytes(),
            binary: false,
            what: "summary".into(),
        },
        OutputFile {
            path: out.join("README.md").display().to_string(),
            bytes: with_kept_tail(page.render(), &out.join("README.md")).into_bytes(),
            binary: false,
            what: "report page".into(),
        },
    ];
    let beds_dir = out.join("beds");
    for bed in groups.iter().filter(|g| g.row.study == "validation").flat_map(|g| g.beds.iter()) {
        if let Some(poses) = &bed.poses {
            std::fs::create_dir_all(&beds_dir).with_context(|| format!("creating {}", beds_dir.display()))?;
            let bytes = std::fs::read(poses).with_context(|| format!("{}", poses.display()))?;
            let path = beds_dir.join(format!("{}.csv", bed.id)).display().to_string();
            outputs.push(OutputFile { path, bytes, binary: false, what: "poses CSV".into() });
        }
    }
    pellet_io::write_outputs(&outputs)?;
    let done = collect::distinct_beds(&groups).len();
    let missing = collect::distinct_missing(&groups).len();
    pellet_cli::print_stdout(&format!(
        "paper-report: {done} beds finished, {missing} missing; wrote {}\n",
        out.join("README.md").display()
    ))?;
    Ok(Outcome::Success)
}

/// The missing beds that have a parked partial run, `<out>/parked/<id>.run.mcap`, in the order
/// of the missing list.
fn parked_runs(out: &Path, missing: &[&str]) -> Vec<String> {
    let dir = out.join("parked");
    missing.iter().filter(|id| dir.join(format!("{id}.run.mcap")).is_file()).map(|id| id.to_string()).collect()
}

/// The line after which the report page is written by hand: `paper-report` keeps whatever
/// follows it in the existing page (measured beds outside the study, such as T14).
pub const KEPT_MARKER: &str = "<!-- written by hand below: paper-report keeps this part -->";

/// The rendered page, followed by the hand-written part of the page already at `path`, if any.
fn with_kept_tail(mut page: String, path: &std::path::Path) -> String {
    if let Some(tail) = std::fs::read_to_string(path).ok().and_then(|t| t.find(KEPT_MARKER).map(|i| t[i..].to_string()))
    {
        if !page.ends_with("\n\n") {
            page.push('\n');
        }
        page.push_str(&tail);
    }
    page
}

#[cfg(test)]
mod kept_tail_tests {
    use super::*;

    #[test]
    fn the_hand_written_part_after_the_marker_is_kept() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("README.md");
        // No page yet, or one without the marker: the rendered page alone.
        assert_eq!(with_kept_tail("# New\n".into(), &path), "# New\n");
        std::fs::write(&path, "# Old\n\nold numbers\n").unwrap();
        assert_eq!(with_kept_tail("# New\n".into(), &path), "# New\n");
        // With the marker: the new page, then the marker and what follows it.
        std::fs::write(&path, format!("# Old\n\n{KEPT_MARKER}\n\n## By hand\n")).unwrap();
        let page = with_kept_tail("# New\n".into(), &path);
        assert_eq!(page, format!("# New\n\n{KEPT_MARKER}\n\n## By hand\n"));
        // Written again over itself, it stays the same.
        std::fs::write(&path, &page).unwrap();
        assert_eq!(with_kept_tail("# New\n".into(), &path), page);
    }
}
