//! What the pipeline left for each bed in the runs directory
//! (`pipelines/paper.mk`): `<id>.summary.json` and `<id>.profile.csv`
//! (voidprof), `<id>.settle.json` and `<id>.poses.csv` (settle-check),
//! `<id>.{pack,settle,voidprof}.time` ("seconds exit-code", timed.sh).
//! A bed counts as finished when its summary exists. Several directories
//! are searched in order (the committed archive `docs/validation/runs`, then
//! the work directory): the first that holds a bed's summary supplies its
//! whole record, so files of two different runs are never mixed.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use serde_json::Value;

use crate::table::{bed_id, seeds, Row};

/// One finished bed.
#[derive(Clone, Debug)]
pub struct BedResult {
    /// `<config>-s<seed>`.
    pub id: String,
    /// Bulk porosity of voidprof's window.
    pub bulk_porosity: f64,
    /// N = D/dp.
    pub n_dp: f64,
    /// N = D/dpv.
    pub n_dpv: f64,
    /// Pellets in the bed.
    pub pellets: u64,
    /// voidprof's axial window [z0, z1] (mm), if its summary says.
    pub window_mm: Option<[f64; 2]>,
    /// Radial profile: wall distance in dp, in dpv, and ε (wall to axis).
    pub profile: Option<(Vec<f64>, Vec<f64>, Vec<f64>)>,
    /// settle-check's verdict, if its report exists.
    pub settled: Option<bool>,
    /// Simulated time at the chosen frame (s), if known.
    pub sim_time_s: Option<f64>,
    /// Wall time of pack + settle-check + voidprof (s), as far as recorded.
    pub seconds: f64,
    /// Whether pack's time was recorded (records rebuilt from poses have none).
    pub pack_timed: bool,
    /// The settled poses CSV.
    pub poses: Option<PathBuf>,
    /// The source of the `pack` that ran the bed (settle-check's `build`), if recorded.
    pub build: Option<String>,
    /// The time-stepping scheme that ran the bed (settle-check's `stepper`), if recorded.
    pub stepper: Option<String>,
}

/// A row and what exists of its beds.
#[derive(Clone, Debug)]
pub struct Group {
    /// The table row.
    pub row: Row,
    /// Finished beds, by seed.
    pub beds: Vec<BedResult>,
    /// Ids of the beds not finished.
    pub missing: Vec<String>,
}

impl Group {
    /// Bulk porosities of the finished beds.
    pub fn porosities(&self) -> Vec<f64> {
        self.beds.iter().map(|b| b.bulk_porosity).collect()
    }
}

/// Every finished bed once, in table order (a `same_as` row shares its beds with another).
pub fn distinct_beds(groups: &[Group]) -> Vec<&BedResult> {
    let mut seen = std::collections::HashSet::new();
    groups.iter().flat_map(|g| g.beds.iter()).filter(|b| seen.insert(b.id.as_str())).collect()
}

/// Every missing bed's id once, in table order.
pub fn distinct_missing(groups: &[Group]) -> Vec<&str> {
    let mut seen = std::collections::HashSet::new();
    groups.iter().flat_map(|g| g.missing.iter().map(String::as_str)).filter(|id| seen.insert(*id)).collect()
}

/// Reads every row's beds from the first of `runs` that holds each.
pub fn collect(rows: &[Row], runs: &[&Path], repeats: Option<u32>) -> Result<Vec<Group>> {
    let mut groups = Vec::new();
    for row in rows {
        let mut group = Group { row: row.clone(), beds: Vec::new(), missing: Vec::new() };
        for seed in seeds(row, repeats) {
            let id = bed_id(row, seed);
            match read_bed(runs, &id)? {
                Some(bed) => group.beds.push(bed),
                None => group.missing.push(id),
            }
        }
        groups.push(group);
    }
    Ok(groups)
}

fn read_json(path: &Path) -> Result<Value> {
    let text = std::fs::read_to_string(path).with_context(|| format!("{}", path.display()))?;
    serde_json::from_str(&text).with_context(|| format!("{}: not JSON", path.display()))
}

fn read_bed(dirs: &[&Path], id: &str) -> Result<Option<BedResult>> {
    let summary_name = format!("{id}.summary.json");
    let Some(runs) = dirs.iter().find(|d| d.join(&summary_name).exists()) else {
        return Ok(None);
    };
    let summary_path = runs.join(&summary_name);
    let s = read_json(&summary_path)?;
    let num = |k: &str| -> Result<f64> {
        s[k].as_f64().with_context(|| format!("{}: no number {k:?}", summary_path.display()))
    };
    let profile_path = runs.join(format!("{id}.profile.csv"));
    let profile = if profile_path.exists() {
        let text = std::fs::read_to_string(&profile_path).with_context(|| format!("{}", profile_path.display()))?;
        Some(parse_profile(&text, &profile_path.display().to_string())?)
    } else {
        None
    };
    let settle_path = runs.join(format!("{id}.settle.json"));
    let settle = if settle_path.exists() { Some(read_json(&settle_path)?) } else { None };
    let seconds =
        ["pack", "settle", "voidprof"].iter().map(|stage| read_seconds(&runs.join(format!("{id}.{stage}.time")))).sum();
    let pack_timed = runs.join(format!("{id}.pack.time")).exists();
    // The archive keeps no poses of validation beds (the report's beds/
    // holds them), so after the record's own directory look in the others.
    let poses_name = format!("{id}.poses.csv");
    let poses = std::iter::once(runs).chain(dirs).map(|d| d.join(&poses_name)).find(|p| p.exists());
    Ok(Some(BedResult {
        id: id.to_string(),
        bulk_porosity: num("bulk_porosity")?,
        n_dp: num("N")?,
        n_dpv: num("N_dpv")?,
        pellets: s["pellets"].as_u64().unwrap_or(0),
        window_mm: match s["window_mm"].as_array().map(|w| w.iter().map(Value::as_f64).collect::<Vec<_>>()) {
            Some(w) if w.len() == 2 => w[0].zip(w[1]).map(|(z0, z1)| [z0, z1]),
            _ => None,
        },
        profile,
        settled: settle.as_ref().and_then(|v| v["settled"].as_bool()),
        sim_time_s: settle.as_ref().and_then(|v| v["frame_time_s"].as_f64()),
        seconds,
        pack_timed,
        poses,
        build: settle.as_ref().and_then(|v| v["build"].as_str()).map(String::from),
        stepper: settle.as_ref().and_then(|v| v["stepper"].as_str()).map(String::from),
    }))
}

/// The first field of a `.time` file (seconds); 0 when absent or unreadable.
fn read_seconds(path: &Path) -> f64 {
    std::fs::read_to_string(path)
        .ok()
        .and_then(|t| t.split_whitespace().next().and_then(|s| s.parse::<f64>().ok()))
        .filter(|s| s.is_finite() && *s >= 0.0)
        .unwrap_or(0.0)
}

/// voidprof's radial CSV: the columns wall_distance_dp, wall_distance_dpv, void_fraction.
pub fn parse_profile(text: &str, name: &str) -> Result<(Vec<f64>, Vec<f64>, Vec<f64>)> {
    let mut lines = text.lines().filter(|l| !l.trim().is_empty());
    let header: Vec<&str> = lines.next().with_context(|| format!("{name}: empty"))?.split(',').collect();
    let col = |c: &str| header.iter().position(|h| h.trim() == c).with_context(|| format!("{name}: no column {c}"));
    let (a, b, e) = (col("wall_distance_dp")?, col("wall_distance_dpv")?, col("void_fraction")?);
    let (mut zdp, mut zdpv, mut eps) = (Vec::new(), Vec::new(), Vec::new());
    for line in lines {
        let cells: Vec<f64> = line.split(',').map(|c| c.trim().parse::<f64>().unwrap_or(f64::NAN)).collect();
        let get = |i: usize| cells.get(i).copied().filter(|v| v.is_finite());
        match (get(a), get(b), get(e)) {
            (Some(x), Some(y), Some(z)) => {
                zdp.push(x);
                zdpv.push(y);
                eps.push(z);
            }
            _ => bail!("{name}: bad row {line:?}"),
        }
    }
    // voidprof writes from the axis to the wall; the scores want z ascending from the wall.
    if zdp.first() > zdp.last() {
        zdp.reverse();
        zdpv.reverse();
        eps.reverse();
    }
    Ok((zdp, zdpv, eps))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn profiles_are_turned_to_start_at_the_wall() {
        let csv = "r_mm,wall_distance_mm,wall_distance_dp,wall_distance_dpv,void_fraction\n\
                   0,20,2,2,0.3\n10,10,1,1,0.4\n20,0,0,0,1\n";
        let (z, _, e) = parse_profile(csv, "p").unwrap();
        assert_eq!(z, vec![0.0, 1.0, 2.0]);
        assert_eq!(e, vec![1.0, 0.4, 0.3]);
        assert!(parse_profile("void_fraction\n1\n", "p").unwrap_err().to_string().contains("wall_distance_dp"));
    }
}
