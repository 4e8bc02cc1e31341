//! The Markdown page (`README.md` in the output directory): what finished,
//! what is missing, the figures, and our numbers beside the paper's.

use std::fmt::Write;

use pellet_refs::Shape;

use crate::analysis::{ProfileResult, StudySeries, TubeResult};
use crate::collect::Group;
use crate::stats::mean_std;

/// The paper's maximum relative errors vs Dixon (fractions) and packbed's targets.
pub const PAPER_MRE: [(Shape, f64, f64); 3] =
    [(Shape::Sphere, 0.039, 0.03), (Shape::Cylinder, 0.176, 0.05), (Shape::Ring, 0.066, 0.04)];

/// The paper's Table 2 (cylinders, N = 6.98): scheme 1 and five disturbed variants.
pub const PAPER_TABLE2: (f64, [f64; 5]) = (0.405, [0.410, 0.419, 0.416, 0.420, 0.425]);

/// Everything on the page.
pub struct Page<'a> {
    /// The command that wrote it.
    pub command: String,
    /// Every row with its beds.
    pub groups: &'a [Group],
    /// Validation tubes and MRE per shape.
    pub validation: Vec<(Shape, Vec<TubeResult>, Option<f64>)>,
    /// Mean profiles and scores.
    pub profiles: &'a [ProfileResult],
    /// COR and friction series.
    pub cor: &'a [StudySeries],
    /// Friction series.
    pub friction: &'a [StudySeries],
    /// Figure file names: (caption, file).
    pub figures: Vec<(String, String)>,
    /// Summed wall time of the finished beds (s).
    pub compute_seconds: f64,
    /// The machine.
    pub machine: String,
    /// Missing beds with a parked partial run in `<output>/parked` (`make paper-park`).
    pub parked: Vec<String>,
}

fn pct(x: f64) -> String {
    format!("{:.1} %", 100.0 * x)
}

fn verdict(ok: bool) -> &'static str {
    if ok {
        "met"
    } else {
        "**missed**"
    }
}

impl Page<'_> {
    /// The page's text.
    pub fn render(&self) -> String {
        let mut o = String::new();
        let _ = writeln!(o, "# Validation against Mohammadzadeh Moghaddam et al. (2018)\n");
        let _ = writeln!(
            o,
            "Written by `{}` (regenerate with `make paper`; see tools/paper-report/README.md).\n",
            self.command
        );
        self.status(&mut o);
        self.comparison(&mut o);
        self.validation_tables(&mut o);
        self.loading(&mut o);
        self.trends(&mut o);
        crate::progress::render(&crate::progress::progress(self.groups), &mut o);
        let _ = writeln!(o, "## Figures\n");
        for (caption, file) in &self.figures {
            let _ = writeln!(o, "![{caption}]({file})\n\n*{caption}*\n");
        }
        let _ = writeln!(o, "## Settled beds\n");
        let _ = writeln!(o, "The settled poses of every finished validation bed are in [`beds/`](beds/) as CSV: `id,x,y,z,qw,qx,qy,qz` (mm, body → world quaternions; tube axis z, floor z = 0), as `settle-check --csv` writes them. `voidprof --poses` reads them back.");
        o
    }

    fn status(&self, o: &mut String) {
        let beds = crate::collect::distinct_beds(self.groups);
        let done = beds.len();
        let missing = crate::collect::distinct_missing(self.groups);
        let unsettled: Vec<&str> = beds.iter().filter(|b| b.settled == Some(false)).map(|b| b.id.as_str()).collect();
        let _ = writeln!(o, "## Status\n");
        let _ = writeln!(o, "- Beds finished: {done} of {}.", done + missing.len());
        if missing.is_empty() {
            let _ = writeln!(o, "- Missing beds: none.");
        } else {
            let _ =
                writeln!(o, "- **Missing beds ({}), not in any number below:** {}.", missing.len(), missing.join(", "));
        }
        if !self.parked.is_empty() {
            let _ = writeln!(
                o,
                "- Parked partial runs (in [`parked/`](parked/), from `make paper-park`; the next `make` of such a bed goes on from its checkpoint): {}.",
                self.parked.join(", ")
            );
        }
        if !unsettled.is_empty() {
            let _ = writeln!(
                o,
                "- **Not settled** at pack's time limit (measured at their last frame): {}.",
                unsettled.join(", ")
            );
        }
        let _ = writeln!(
            o,
            "- Compute time: {:.0} s ({:.2} h) of wall time summed over the finished beds (pack + settle-check + voidprof, one core each; `make -j2` runs two at once).",
            self.compute_seconds,
            self.compute_seconds / 3600.0
        );
        if !missing.is_empty() {
            let (estimate, unknown) = crate::progress::missing_total(&crate::progress::progress(self.groups));
            let _ = writeln!(
                o,
                "- Estimated compute for the missing beds: {estimate:.0} s ({:.1} h), each at the mean of the finished beds of its study, shape and tube (Progress, below); with the finished beds', about {:.0} h for the whole study{}.",
                estimate / 3600.0,
                (estimate + self.compute_seconds) / 3600.0,
                if unknown > 0 { format!("; {unknown} missing beds have no finished bed to go by and are not in it") } else { String::new() }
            );
        }
        let untimed: Vec<&str> = beds.iter().filter(|b| !b.pack_timed).map(|b| b.id.as_str()).collect();
        if !untimed.is_empty() {
            let _ = writeln!(
                o,
                "- Beds whose run times were not kept ({}), left out of the compute time: their records were rebuilt from the settled poses with `voidprof --poses` (see `runs/README.md`): {}.",
                untimed.len(),
                untimed.join(", ")
            );
        }
        let _ = writeln!(o, "- {}", builds_line(&beds));
        // The records do not say which machine ran each bed, and the machines that ran them
        // differ in CPU model (AMD EPYC and Intel Xeon; docs/validation/reproducing.md says which).
        let _ = writeln!(
            o,
            "- Machine: this report was written on {}. The compute time above was measured on the machines that ran each bed, all of this kind (2 logical cores) but not all of one CPU model (see [reproducing.md](reproducing.md), Machines), so it mixes machines.",
            self.machine
        );
        let _ = writeln!(o, "- Engine defaults for every bed (no per-bed tuning): `pack`'s defaults unless the table row sets COR, friction or disturbances; contact model `recommended` (the paper's model does not let a poured bed settle; see docs/engine.md, Contact model).\n");
    }

    fn comparison(&self, o: &mut String) {
        let _ = writeln!(o, "## Our figures beside the paper's\n");
        let _ = writeln!(o, "| quantity | ours | paper | packbed's target | met |");
        let _ = writeln!(o, "|---|---|---|---|---|");
        for (shape, paper, target) in PAPER_MRE {
            let found = self.validation.iter().find(|v| v.0 == shape);
            let mre = found.and_then(|v| v.2);
            // A maximum over some tubes only is a lower bound: say how many.
            let tubes = found.map_or(0, |v| v.1.len());
            let of = self.groups.iter().filter(|g| g.row.study == "validation" && g.row.shape == shape).count();
            let (ours, ok) = match mre {
                Some(m) => (format!("{} ({tubes} of {of} tubes)", pct(m)), verdict(m <= target)),
                None => ("no beds yet".into(), "—"),
            };
            let what = if shape == Shape::Ring { " (ring-envelope estimate, ours, grade C)" } else { "" };
            let _ = writeln!(
                o,
                "| MRE of bulk porosity vs Dixon, {}s{what} | {ours} | {} | ≤ {} | {ok} |",
                shape.name(),
                pct(paper),
                pct(target)
            );
        }
        for p in self.profiles {
            for s in &p.scores {
                let (reference, rmse) = (&s.reference, s.rmse);
                // packbed's profile target is for spheres against de Klerk only.
                let de_klerk_sphere = p.shape == Shape::Sphere && reference == "de-klerk-2003";
                let paper = match p.shape {
                    Shape::Sphere => "R² > 0.85, RMSE < 0.08",
                    _ => "R² > 0.84, RMSE < 0.07 (vs Roshani's data)",
                };
                let target = if de_klerk_sphere { "R² ≥ 0.9, RMSE ≤ 0.05" } else { "—" };
                let ok = match (p.shape, reference.as_str(), s.r2) {
                    (Shape::Sphere, "de-klerk-2003", Some(r2)) => verdict(r2 >= 0.9 && rmse <= 0.05),
                    (Shape::Sphere, "de-klerk-2003", None) => verdict(false),
                    _ => "—",
                };
                let r2s = s.r2.map_or("undefined".into(), |r| format!("{r:.3}"));
                let note = if p.shape == Shape::Sphere {
                    ""
                } else {
                    " (sphere correlation, z/dpv: not the paper's reference)"
                };
                let _ = writeln!(o, "| profile {} N = {:.2} vs {reference}{note}: R², RMSE | {r2s}, {rmse:.4} | {paper} | {target} | {ok} |", p.shape.name(), p.n);
            }
        }
        let _ = writeln!(o, "\nMRE is the paper's measure: the *maximum* over the tubes of |ε_mean − ε_Dixon|/ε_Dixon, ε_mean the mean over seeds of the bulk porosity over the row's voidprof window (z = 0–100 mm for the Table 3 beds). Spheres use N = D/dp, cylinders N = D/dpv (Dixon's own N). Rings: Dixon's hollow-cylinder coefficients are not available here, so rings are scored against the ring-envelope estimate (Dixon's cylinder form for the solid envelope, the hole added as void) — an approximation of ours, not literature. Profiles: ε_b of de Klerk fitted so that the correlation's cross-section mean equals the bed's bulk porosity; Mueller uses its own ε_b(N). Where a target is missed the numbers above say by how much; the beds were not tuned per case.\n");
        let _ = writeln!(o, "Known reasons for misses, to weigh with the numbers: beds listed above as not settled were measured at their last frame; with few seeds (`REPEATS`) the mean carries the spread shown in the per-tube table; and the paper releases its pellets above the tube without giving the tube's length: the table's `release_height_mm` says where each row's pellets enter (the Table 3 beds at 150 mm, the top of a tube as long as the 120 mm bed with pack's 30 mm drop above it; rows without one 30 mm above the bed surface), and in narrow tubes the height of the fall moves the porosity by a few hundredths (the loading table's drop-height rows, same tubes and seeds). Finally, Dixon's correlation is one of several, and they disagree by more than the targets in narrow tubes: the per-tube table gives the range of the grade A and B correlations at each tube's N and says whether our mean lies inside it.\n");
    }

    fn validation_tables(&self, o: &mut String) {
        let _ = writeln!(o, "## Bulk porosity per tube (Table 3 beds)\n");
        let _ = writeln!(
            o,
            "| shape | D (mm) | N = D/dp | N = D/dpv | seeds | ε per seed | ε mean | Dixon | relative error | A/B correlations ε(N): range (count) |"
        );
        let _ = writeln!(o, "|---|---|---|---|---|---|---|---|---|---|");
        for (shape, tubes, _) in &self.validation {
            for t in tubes {
                let seeds: Vec<String> = t.porosity_seeds.iter().map(|p| format!("{p:.4}")).collect();
                let range = match crate::analysis::correlation_range(*shape, t.n, t.n_dpv) {
                    Some((lo, hi, k)) => {
                        let inside = if (lo..=hi).contains(&t.porosity_mean) { "ours inside" } else { "ours outside" };
                        format!("{lo:.4}–{hi:.4} ({k}; {inside})")
                    }
                    None => "—".into(),
                };
                let _ = writeln!(
                    o,
                    "| {} | {} | {:.2} | {:.2} | {} | {} | {:.4} | {:.4} | {:+.1} % | {range} |",
                    shape.name(),
                    t.tube_diameter_mm,
                    t.n,
                    t.n_dpv,
                    seeds.len(),
                    seeds.join(", "),
                    t.porosity_mean,
                    t.dixon,
                    100.0 * (t.porosity_mean - t.dixon) / t.dixon
                );
            }
        }
        let _ = writeln!(o, "\nThe last column: the lowest and highest ε at the tube's N of the shape's bulk correlations of the form ε(N) graded A or B (`pellet_refs`; Dixon is one of them), each at its own N definition and only where its range holds N, and whether our mean lies between them. The correlations disagree among themselves; a miss against Dixon inside that range is within their spread.");
        o.push('\n');
    }

    fn loading(&self, o: &mut String) {
        let _ = writeln!(o, "## Loading schemes (the paper's Table 2)\n");
        let _ = writeln!(o, "| bed | shape | D (mm) | scheme | beds | ε mean ± std | Dixon | paper |");
        let _ = writeln!(o, "|---|---|---|---|---|---|---|---|");
        for g in self.groups.iter().filter(|g| g.row.study == "loading") {
            let paper = if g.row.shape == Shape::Cylinder {
                if g.row.config.ends_with("disturbed") {
                    let v = PAPER_TABLE2.1;
                    format!("{} (mean {:.3})", v.map(|x| format!("{x:.3}")).join(", "), v.iter().sum::<f64>() / 5.0)
                } else {
                    format!("{:.3}", PAPER_TABLE2.0)
                }
            } else {
                "—".into()
            };
            let (eps, dixon) = match (mean_std(&g.porosities()), g.beds.first()) {
                (Some((m, s)), Some(b)) => (
                    mean_and_spread(m, s, g.beds.len()),
                    format!("{:.4}", crate::analysis::dixon(g.row.shape, b.n_dp, b.n_dpv)),
                ),
                _ => ("missing".into(), "—".into()),
            };
            let bed = match &g.row.same_as {
                Some(other) => format!("{} (the beds of {other})", g.row.config),
                None => g.row.config.clone(),
            };
            let _ = writeln!(
                o,
                "| {bed} | {} | {} | {} (`{}`) | {} | {eps} | {dixon} | {paper} |",
                g.row.shape.name(),
                g.row.tube_diameter_mm,
                g.row.label,
                g.row.scheme,
                g.beds.len()
            );
        }
        o.push('\n');
    }

    fn trends(&self, o: &mut String) {
        let _ = writeln!(o, "## COR and friction (the paper's Figs. 10–11)\n");
        let _ = writeln!(o, "The paper found denser beds (lower ε) at higher COR and at lower friction; the friction effect about 1.5 times the COR effect. Slope: least squares of ε over every bed of the series. A value of one bed has no spread, so it shows no ± std.\n");
        let _ = writeln!(o, "| study | series | values (ε mean ± std, beds) | slope dε/dx | as the paper? |");
        let _ = writeln!(o, "|---|---|---|---|---|");
        if self.cor.is_empty() && self.friction.is_empty() {
            let _ = writeln!(o, "| — | no bed of the COR or friction study has finished | | | |");
        }
        for (study, series, paper_sign) in [("COR", self.cor, -1.0), ("friction", self.friction, 1.0)] {
            for s in series {
                let vals: Vec<String> =
                    s.points.iter().map(|p| format!("{}: {} ({})", p.0, mean_and_spread(p.1, p.2, p.3), p.3)).collect();
                let (slope, agree) = match s.slope {
                    Some(k) => (format!("{k:+.4}"), if k * paper_sign > 0.0 { "yes" } else { "**no**" }),
                    None => ("—".into(), "—"),
                };
                let _ = writeln!(o, "| {study} | {} | {} | {slope} | {agree} |", s.label, vals.join("; "));
            }
        }
        o.push('\n');
    }
}

/// "mean ± std" of `n` beds; the mean alone for one bed, whose spread is unknown rather than
/// zero.
fn mean_and_spread(mean: f64, std: f64, n: usize) -> String {
    if n > 1 {
        format!("{mean:.4} ± {std:.4}")
    } else {
        format!("{mean:.4}")
    }
}

/// Which `pack` builds ran the finished beds, most beds first: the engine changed while the
/// study ran, and a bed is reproduced bit for bit only by its own build. Then which steppers.
fn builds_line(beds: &[&crate::collect::BedResult]) -> String {
    let counts = crate::progress::merge_builds(beds.iter().map(|b| (b.build.clone(), 1)));
    let parts: Vec<String> = counts
        .iter()
        .map(|(build, n)| {
            let what = build.as_ref().map_or("not recorded (an older `pack`)".to_string(), |b| format!("`{b}`"));
            format!("{what}: {n}")
        })
        .collect();
    let steppers = crate::progress::merge_builds(beds.iter().map(|b| (b.stepper.clone(), 1)));
    let steppers: Vec<String> = steppers
        .iter()
        .map(|(stepper, n)| {
            let what =
                stepper.as_ref().map_or("not recorded (an older `settle-check`)".to_string(), |s| format!("`{s}`"));
            format!("{what}: {n}")
        })
        .collect();
    format!(
        "Engine builds that ran the finished beds (`pack`'s source as recorded in each trajectory; a bed is reproduced bit for bit by its own build): {}. Steppers (`pack --stepper`): {}.",
        parts.join("; "),
        steppers.join("; ")
    )
}

#[cfg(test)]
mod tests {
    use super::{builds_line, mean_and_spread};
    use crate::collect::BedResult;

    fn bed(build: Option<&str>) -> BedResult {
        BedResult {
            id: "b".into(),
            bulk_porosity: 0.4,
            n_dp: 4.0,
            n_dpv: 4.0,
            pellets: 1,
            window_mm: None,
            profile: None,
            settled: Some(true),
            sim_time_s: None,
            seconds: 0.0,
            pack_timed: true,
            poses: None,
            build: build.map(String::from),
            stepper: None,
        }
    }

    #[test]
    fn the_builds_are_counted_most_beds_first() {
        let beds = [bed(Some("git b")), bed(None), bed(Some("git a")), bed(Some("git b"))];
        let refs: Vec<&BedResult> = beds.iter().collect();
        let line = builds_line(&refs);
        assert!(line.contains(": `git b`: 2; `git a`: 1; not recorded (an older `pack`): 1."), "{line}");
        assert!(line.ends_with("Steppers (`pack --stepper`): not recorded (an older `settle-check`): 4."), "{line}");
    }

    #[test]
    fn one_bed_shows_its_value_without_a_spread() {
        assert_eq!(mean_and_spread(0.46694, 0.0, 1), "0.4669");
        assert_eq!(mean_and_spread(0.4669, 0.0123, 3), "0.4669 ± 0.0123");
        assert_eq!(mean_and_spread(0.4669, 0.0, 2), "0.4669 ± 0.0000");
    }
}
