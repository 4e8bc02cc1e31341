//! The report directory's text files and the summary on stdout.
//!
//! - `scores.json`: a JSON array, one object per reference: `reference`,
//!   `kind` (`profile` or `bulk`), `valid`, `gated`, `grade`, `notes`; for
//!   profiles `points`, `rmse`, `r2` (null if undefined), `mae`,
//!   `max_abs_error`, `z_min`, `z_max`, `z_unit`, `eps_b`, `eps_b_method`,
//!   `N`; for bulk `simulated`, `predicted`, `relative_error` (signed
//!   fraction, the worst bed), `mre`, `n_definition` and `beds` (each bed's
//!   `source`, `N`, `simulated`, `predicted`, `relative_error`, `valid`).
//! - `scores.csv`: the same, one row per reference (bulk: the worst bed).
//! - `report.md`: inputs, parameters, ε_b choice, tables, gates, plots.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::Result;
use pellet_io::OutputFile;
use pellet_refs::scoring::Score;

use crate::beds::Info;
use crate::gates::{Gate, Violation};

fn num(v: Option<f64>) -> String {
    v.map_or_else(String::new, |v| format!("{v:.6}"))
}

fn text(dir: &Path, name: &str, what: &str, contents: String) -> OutputFile {
    OutputFile {
        path: dir.join(name).display().to_string(),
        bytes: contents.into_bytes(),
        binary: false,
        what: what.into(),
    }
}

/// scores.json, scores.csv and report.md.
pub fn outputs(
    dir: &Path,
    info: &Info,
    scores: &[Score],
    gates: &[Gate],
    violations: &[Violation],
    plots: &[PathBuf],
) -> Result<Vec<OutputFile>> {
    let mut json = serde_json::to_string_pretty(scores)?;
    json.push('\n');
    Ok(vec![
        text(dir, "scores.json", "scores", json),
        text(dir, "scores.csv", "scores", csv(scores)),
        text(dir, "report.md", "report", markdown(info, scores, gates, violations, plots)),
    ])
}

const CSV_HEADER: &str = "reference,kind,grade,valid,gated,points,z_unit,z_min,z_max,rmse,r2,mae,max_abs_error,eps_b,eps_b_method,N,simulated,predicted,relative_error,mre";

fn csv(scores: &[Score]) -> String {
    let mut out = format!("{CSV_HEADER}\n");
    for s in scores {
        let row = match s {
            Score::Profile(p) => format!(
                "{},profile,{},{},{},{},{},{},{},{},{},{},{},{},{},{},,,,",
                p.reference,
                p.grade.map_or(String::new(), |g| format!("{g:?}")),
                p.valid,
                p.gated,
                p.metrics.points,
                p.z_unit.name(),
                num(Some(p.z_min)),
                num(Some(p.z_max)),
                num(Some(p.metrics.rmse)),
                num(p.metrics.r2),
                num(Some(p.metrics.mae)),
                num(Some(p.metrics.max_abs_error)),
                num(p.eps_b),
                p.eps_b_method.as_deref().unwrap_or(""),
                num(p.n),
            ),
            Score::Bulk(b) => {
                let worst = b.beds.iter().find(|x| x.simulated == b.simulated && x.predicted == b.predicted);
                format!(
                    "{},bulk,{:?},{},{},{},,,,,,,,,,{},{},{},{},{}",
                    b.reference,
                    b.grade,
                    b.valid,
                    b.gated,
                    b.beds.len(),
                    num(worst.map(|w| w.n)),
                    num(Some(b.simulated)),
                    num(Some(b.predicted)),
                    num(Some(b.relative_error)),
                    num(Some(b.mre)),
                )
            }
        };
        out += &row;
        out.push('\n');
    }
    out
}

fn markdown(info: &Info, scores: &[Score], gates: &[Gate], violations: &[Violation], plots: &[PathBuf]) -> String {
    let mut md = String::from("# compare report\n\n");
    let _ = writeln!(md, "Written by compare {} (packbed).\n", env!("CARGO_PKG_VERSION"));
    let _ = writeln!(md, "Command: `{}`\n", info.command);
    md += "## Inputs\n\n| role | file |\n|---|---|\n";
    for (role, path) in &info.inputs {
        let _ = writeln!(md, "| {role} | `{path}` |");
    }
    md += "\n## Parameters\n\n| parameter | value |\n|---|---|\n";
    for (k, v) in &info.params {
        let _ = writeln!(md, "| {k} | {v} |");
    }
    let _ = writeln!(md, "| ε_b (de Klerk, Cohen & Metzner, Martin, Bey & Eigenberger) | {} |", info.eps_b_mode);
    md += "| ε_b (Mueller) | its own, 0.365 + 0.220/N |\n";
    let profiles: Vec<_> =
        scores.iter().filter_map(|s| if let Score::Profile(p) = s { Some(p) } else { None }).collect();
    if !profiles.is_empty() {
        md += "\n## Radial profile\n\nReference curves evaluated at the profile's wall distances (correlations as \
               predictions of the simulation; for experiments, the simulation interpolated at the data).\n\n";
        md += "| reference | grade | valid | points | z range | RMSE | R² | MAE | max abs error | ε_b |\n";
        md += "|---|---|---|---|---|---|---|---|---|---|\n";
        for p in &profiles {
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {:.3}–{:.3} {} | {:.4} | {} | {:.4} | {:.4} | {} |",
                p.reference,
                p.grade.map_or("data".into(), |g| format!("{g:?}")),
                if p.valid { "yes" } else { "**no**" },
                p.metrics.points,
                p.z_min,
                p.z_max,
                p.z_unit.name(),
                p.metrics.rmse,
                p.metrics.r2.map_or("–".into(), |r| format!("{r:.4}")),
                p.metrics.mae,
                p.metrics.max_abs_error,
                match (p.eps_b, &p.eps_b_method) {
                    (Some(v), Some(m)) => format!("{v:.4} ({m})"),
                    _ => "–".into(),
                },
            );
        }
    }
    let bulks: Vec<_> = scores.iter().filter_map(|s| if let Score::Bulk(b) = s { Some(b) } else { None }).collect();
    if !bulks.is_empty() {
        md += "\n## Bulk porosity\n\nRelative error = (simulated − predicted)/predicted. MRE = the largest |relative \
               error| over the beds inside the correlation's range.\n\n";
        md += "| reference | grade | N definition | valid | simulated | predicted | relative error | MRE | beds |\n";
        md += "|---|---|---|---|---|---|---|---|---|\n";
        for b in &bulks {
            let _ = writeln!(
                md,
                "| {} | {:?} | {} | {} | {:.4} | {:.4} | {:+.2} % | {:.2} % | {} |",
                b.reference,
                b.grade,
                b.n_definition,
                if b.valid { "yes" } else { "**no**" },
                b.simulated,
                b.predicted,
                100.0 * b.relative_error,
                100.0 * b.mre,
                b.beds.len()
            );
        }
        if bulks[0].beds.len() > 1 {
            md += "\nPer bed:\n\n| reference | bed | N | simulated | predicted | relative error | valid |\n|---|---|---|---|---|---|---|\n";
            for b in &bulks {
                for bed in &b.beds {
                    let _ = writeln!(
                        md,
                        "| {} | `{}` | {:.3} | {:.4} | {:.4} | {:+.2} % | {} |",
                        b.reference,
                        bed.source,
                        bed.n,
                        bed.simulated,
                        bed.predicted,
                        100.0 * bed.relative_error,
                        bed.valid
                    );
                }
            }
        }
    }
    let notes: Vec<(String, &String)> = scores
        .iter()
        .flat_map(|s| {
            let (r, n) = match s {
                Score::Profile(p) => (&p.reference, &p.notes),
                Score::Bulk(b) => (&b.reference, &b.notes),
            };
            n.iter().map(move |x| (r.clone(), x))
        })
        .collect();
    if !notes.is_empty() {
        md += "\n## Notes and flags\n\n";
        for (r, n) in notes {
            let _ = writeln!(md, "- {r}: {n}");
        }
    }
    md += "\n## Gates\n\n";
    if gates.is_empty() {
        md += "None given.\n";
    } else {
        for g in gates {
            let _ = writeln!(md, "- fail {} {} = {}", if g.above { "above" } else { "below" }, g.metric, g.limit);
        }
        if violations.is_empty() {
            md += "\nAll gated scores pass (scores outside a validity range or against grade C are not gated).\n";
        } else {
            md += "\n**Failed:**\n\n";
            for v in violations {
                let _ = writeln!(md, "- {v}");
            }
        }
    }
    if !plots.is_empty() {
        md += "\n## Plots\n\n";
        for p in plots {
            let name = p.file_name().map_or(String::new(), |n| n.to_string_lossy().into_owned());
            if name.ends_with(".png") {
                let _ = writeln!(md, "![{name}]({name})\n");
            } else {
                let _ = writeln!(md, "- [{name}]({name})");
            }
        }
    }
    md
}

/// The scores as an aligned plain-text table (`--table`), one row per score: `rmse` and `r2`
/// of a profile, `simulated` and `predicted` bulk porosity and their relative `error_%` (signed,
/// (sim − pred)/pred in %, the worst bed) of a bulk correlation; void fractions and porosities
/// are dimensionless fractions; `-` where a column does not apply.
pub fn table(scores: &[Score]) -> String {
    let head = ["reference", "kind", "grade", "rmse", "r2", "simulated", "predicted", "error_%", "note"];
    let mut rows: Vec<Vec<String>> = vec![head.map(String::from).to_vec()];
    let dash = || "-".to_string();
    for s in scores {
        let note = match s {
            Score::Profile(p) if !p.valid => "outside range",
            Score::Bulk(b) if !b.valid => "outside range",
            _ if !s.is_gated() => "grade C, not gated",
            _ => "",
        };
        rows.push(match s {
            Score::Profile(p) => vec![
                p.reference.clone(),
                "profile".into(),
                p.grade.map_or_else(dash, |g| format!("{g:?}")),
                format!("{:.4}", p.metrics.rmse),
                p.metrics.r2.map_or_else(dash, |r| format!("{r:.3}")),
                dash(),
                dash(),
                dash(),
                note.into(),
            ],
            Score::Bulk(b) => vec![
                b.reference.clone(),
                "bulk".into(),
                format!("{:?}", b.grade),
                dash(),
                dash(),
                format!("{:.4}", b.simulated),
                format!("{:.4}", b.predicted),
                format!("{:+.2}", 100.0 * b.relative_error),
                note.into(),
            ],
        });
    }
    let widths: Vec<usize> =
        (0..head.len()).map(|c| rows.iter().map(|r| r[c].chars().count()).max().unwrap_or(0)).collect();
    let mut out = String::new();
    for row in &rows {
        let mut line = String::new();
        for (c, cell) in row.iter().enumerate() {
            let w = widths[c];
            match c {
                0..=2 => {
                    let _ = write!(line, "{cell:<w$}  ");
                }
                3..=7 => {
                    let _ = write!(line, "{cell:>w$}  ");
                }
                _ => line += cell,
            }
        }
        out += line.trim_end();
        out.push('\n');
    }
    out
}

/// What compare prints on stdout: one line per score (or, with `--table -`, the table), the
/// gates, the files.
pub fn stdout_summary(
    scores: &[Score],
    as_table: bool,
    violations: &[Violation],
    dir: &Path,
    plots: &[PathBuf],
) -> String {
    let mut out = String::new();
    if as_table {
        out += &table(scores);
    }
    for s in scores.iter().filter(|_| !as_table) {
        let flag = match s {
            Score::Profile(p) if !p.valid => "  [outside range]",
            Score::Bulk(b) if !b.valid => "  [outside range]",
            _ if !s.is_gated() => "  [grade C, not gated]",
            _ => "",
        };
        let line = match s {
            Score::Profile(p) => format!(
                "{:<32} profile  rmse {:.4}  r2 {}  mae {:.4}  max {:.4}  ({} points){flag}",
                p.reference,
                p.metrics.rmse,
                p.metrics.r2.map_or("–".into(), |r| format!("{r:.3}")),
                p.metrics.mae,
                p.metrics.max_abs_error,
                p.metrics.points
            ),
            Score::Bulk(b) => format!(
                "{:<32} bulk     simulated {:.4}  predicted {:.4}  relative error {:+.2} %  MRE {:.2} %{flag}",
                b.reference,
                b.simulated,
                b.predicted,
                100.0 * b.relative_error,
                100.0 * b.mre
            ),
        };
        out += &line;
        out.push('\n');
    }
    for v in violations {
        let _ = writeln!(out, "FAIL {v}");
    }
    let _ = writeln!(out, "report: {}", dir.join("report.md").display());
    for p in plots.iter().filter(|p| p.extension().is_some_and(|e| e == "png")) {
        let _ = writeln!(out, "plot: {}", p.display());
    }
    out
}
