//! The report's progress table: for each study, shape and tube, how many of the planned beds
//! have finished, how many of those did not settle, their compute time, and which `pack` builds
//! ran them. The study's beds were made over weeks while the engine changed, so the page must show
//! which parts of it come from which engine, not only one count for the whole study.

use std::fmt::Write;

use crate::collect::Group;

/// One line of the table: every row of the bed table with the same study, shape and tube.
#[derive(Debug, Clone, PartialEq)]
pub struct Progress {
    /// `validation`, `loading`, `cor` or `friction`.
    pub study: String,
    /// Pellet shape name.
    pub shape: &'static str,
    /// Tube inner diameter (mm).
    pub tube_diameter_mm: f64,
    /// Beds of these rows (finished or not).
    pub planned: usize,
    /// Beds finished.
    pub finished: usize,
    /// Finished beds that reached pack's time limit unsettled.
    pub unsettled: usize,
    /// Recorded wall time of the finished beds (s).
    pub seconds: f64,
    /// Finished beds whose run times were kept (the others add nothing to `seconds`).
    pub timed: usize,
    /// Builds that ran the finished beds with their counts, most beds first; `None` for beds
    /// made by a `pack` from before builds were recorded.
    pub builds: Vec<(Option<String>, usize)>,
}

/// The table, in the bed table's order. A `same_as` row is left out: its beds are those of the
/// row it names and are counted there.
pub fn progress(groups: &[Group]) -> Vec<Progress> {
    let mut lines: Vec<Progress> = Vec::new();
    for g in groups.iter().filter(|g| g.row.same_as.is_none()) {
        let (study, shape, d) = (&g.row.study, g.row.shape.name(), g.row.tube_diameter_mm);
        let at = match lines.iter().position(|p| &p.study == study && p.shape == shape && p.tube_diameter_mm == d) {
            Some(i) => i,
            None => {
                lines.push(Progress {
                    study: study.clone(),
                    shape,
                    tube_diameter_mm: d,
                    planned: 0,
                    finished: 0,
                    unsettled: 0,
                    seconds: 0.0,
                    timed: 0,
                    builds: Vec::new(),
                });
                lines.len() - 1
            }
        };
        let p = &mut lines[at];
        p.planned += g.beds.len() + g.missing.len();
        p.finished += g.beds.len();
        p.unsettled += g.beds.iter().filter(|b| b.settled == Some(false)).count();
        p.seconds += g.beds.iter().map(|b| b.seconds).sum::<f64>();
        p.timed += g.beds.iter().filter(|b| b.pack_timed).count();
        let mut builds: Vec<(Option<String>, usize)> = std::mem::take(&mut p.builds);
        builds.extend(g.beds.iter().map(|b| (b.build.clone(), 1)));
        p.builds = merge_builds(builds);
    }
    lines
}

impl Progress {
    /// The compute the line's missing beds would take, each at the mean time of the line's
    /// finished and timed beds (same study, shape and tube): `Some(0)` when none is missing,
    /// `None` when some are but no finished bed gives a time to go by.
    pub fn missing_estimate(&self) -> Option<f64> {
        let missing = self.planned - self.finished;
        if missing == 0 {
            Some(0.0)
        } else if self.timed == 0 {
            None
        } else {
            Some(missing as f64 * self.seconds / self.timed as f64)
        }
    }
}

/// The estimated compute of all missing beds (s) and how many missing beds have no estimate.
pub fn missing_total(lines: &[Progress]) -> (f64, usize) {
    lines.iter().fold((0.0, 0), |(sum, unknown), p| match p.missing_estimate() {
        Some(s) => (sum + s, unknown),
        None => (sum, unknown + p.planned - p.finished),
    })
}

/// How many finished beds each build ran, from `(build, count)` pairs (a build may repeat), most
/// beds first; ties: recorded builds before unrecorded ones, then by name. `None` is a bed made
/// by a `pack` from before builds were recorded. The Status line and this table both count so.
pub fn merge_builds(pairs: impl IntoIterator<Item = (Option<String>, usize)>) -> Vec<(Option<String>, usize)> {
    let mut counts: std::collections::BTreeMap<Option<String>, usize> = std::collections::BTreeMap::new();
    for (build, n) in pairs {
        *counts.entry(build).or_default() += n;
    }
    let mut counts: Vec<(Option<String>, usize)> = counts.into_iter().collect();
    counts.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.is_none().cmp(&b.0.is_none())).then(a.0.cmp(&b.0)));
    counts
}

/// Writes the table as a Markdown section.
pub fn render(lines: &[Progress], o: &mut String) {
    let _ = writeln!(o, "## Progress by study and tube\n");
    let _ = writeln!(o, "Which beds have finished and which `pack` build ran them (`git <commit>` of the build's source; \"older\" = a `pack` from before builds were recorded). A bed is reproduced bit for bit only by its own build.\n");
    let _ = writeln!(
        o,
        "The estimate for the missing beds takes each at the mean compute of the finished beds of its line.\n"
    );
    let _ = writeln!(
        o,
        "| study | shape | D (mm) | finished | not settled | compute (s) | missing beds, estimated (s) | builds |"
    );
    let _ = writeln!(o, "|---|---|---|---|---|---|---|---|");
    for p in lines {
        let builds: Vec<String> = p
            .builds
            .iter()
            .map(|(build, n)| match build {
                Some(b) => format!("`{}` {n}", b.strip_prefix("git ").unwrap_or(b)),
                None => format!("older {n}"),
            })
            .collect();
        let builds = if builds.is_empty() { "—".to_string() } else { builds.join(", ") };
        let unsettled = if p.unsettled == 0 { "—".to_string() } else { p.unsettled.to_string() };
        let estimate = match (p.planned - p.finished, p.missing_estimate()) {
            (0, _) => "—".to_string(),
            (_, Some(s)) => format!("{s:.0}"),
            (_, None) => "no finished bed to go by".to_string(),
        };
        let _ = writeln!(
            o,
            "| {} | {} | {} | {} of {} | {unsettled} | {:.0} | {estimate} | {builds} |",
            p.study, p.shape, p.tube_diameter_mm, p.finished, p.planned, p.seconds
        );
    }
    o.push('\n');
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::collect::BedResult;
    use crate::table::Row;
    use pellet_refs::Shape;

    fn bed(id: &str, build: Option<&str>, settled: bool, seconds: f64) -> BedResult {
        BedResult {
            id: id.into(),
            bulk_porosity: 0.4,
            n_dp: 4.0,
            n_dpv: 4.0,
            pellets: 1,
            window_mm: None,
            profile: None,
            settled: Some(settled),
            sim_time_s: None,
            seconds,
            pack_timed: true,
            poses: None,
            build: build.map(String::from),
            stepper: None,
        }
    }

    fn group(
        config: &str,
        study: &str,
        d: f64,
        same_as: Option<&str>,
        beds: Vec<BedResult>,
        missing: &[&str],
    ) -> Group {
        Group {
            row: Row {
                config: config.into(),
                study: study.into(),
                shape: Shape::Sphere,
                tube_diameter_mm: d,
                seeds: (beds.len() + missing.len()) as u32,
                cor: None,
                friction: None,
                scheme: "one-column".into(),
                label: String::new(),
                same_as: same_as.map(String::from),
            },
            beds,
            missing: missing.iter().map(|m| m.to_string()).collect(),
        }
    }

    /// A missing bed is estimated from its line's timed beds only; a line with none has no
    /// estimate, and its missing beds are counted as such.
    #[test]
    fn missing_beds_are_estimated_from_the_timed_beds_of_their_line() {
        let mut untimed = bed("u1", None, true, 0.0);
        untimed.pack_timed = false;
        let groups = [
            group("cor-61", "cor", 61.0, None, vec![bed("t1", None, true, 100.0), untimed], &["m1", "m2"]),
            group("cor-79", "cor", 79.9, None, vec![], &["m3"]),
        ];
        let lines = progress(&groups);
        assert_eq!(lines[0].missing_estimate(), Some(200.0));
        assert_eq!(lines[1].missing_estimate(), None);
        assert_eq!(missing_total(&lines), (200.0, 1));
        let mut page = String::new();
        render(&lines, &mut page);
        assert!(page.contains("| 0 of 1 | — | 0 | no finished bed to go by |"), "{page}");
    }

    /// Rows of one study and tube are pooled, a `same_as` row is not counted twice, and each
    /// line counts its own builds, unsettled beds and time.
    #[test]
    fn rows_of_a_tube_are_pooled_and_shared_beds_counted_once() {
        let groups = [
            group("val-31", "validation", 31.0, None, vec![bed("v1", Some("git a"), true, 3600.0)], &["v2"]),
            group("cor-31-c0.05", "cor", 31.0, None, vec![bed("c1", None, true, 1800.0)], &[]),
            group(
                "cor-31-c0.95",
                "cor",
                31.0,
                None,
                vec![bed("d1", Some("git b"), false, 900.0), bed("d2", Some("git b"), true, 900.0)],
                &["d3"],
            ),
            group("load-31", "loading", 31.0, Some("val-31"), vec![bed("v1", Some("git a"), true, 3600.0)], &["v2"]),
        ];
        let lines = progress(&groups);
        assert_eq!(lines.len(), 2, "{lines:?}");
        assert_eq!((lines[0].finished, lines[0].planned, lines[0].unsettled), (1, 2, 0));
        let cor = &lines[1];
        assert_eq!((cor.study.as_str(), cor.finished, cor.planned, cor.unsettled), ("cor", 3, 4, 1));
        assert_eq!(cor.seconds, 3600.0);
        assert_eq!(cor.builds, vec![(Some("git b".to_string()), 2), (None, 1)]);
        let mut page = String::new();
        render(&lines, &mut page);
        assert!(page.contains("| cor | sphere | 31 | 3 of 4 | 1 | 3600 | 1200 | `b` 2, older 1 |"), "{page}");
        assert!(page.contains("| validation | sphere | 31 | 1 of 2 | — | 3600 | 3600 | `a` 1 |"), "{page}");
        assert_eq!(missing_total(&lines), (4800.0, 0));
    }
}
