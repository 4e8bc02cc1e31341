//! Reading compare's inputs: profile CSVs, voidprof summaries, experimental
//! data. Bytes come from `pellet_io::read_input`; this module only parses.
//!
//! A profile CSV has a header row and needs `void_fraction` and one of
//! `wall_distance_dp`, `wall_distance_dpv` or `wall_distance_mm` (the
//! latter then needs the pellet length, from `--dp`/`--dpv` or a summary).
//! Optional: `r_mm` (with `wall_distance_mm` it gives the tube radius) and
//! `void_fraction_std` (a spread, drawn as a band). Other columns are
//! ignored, so voidprof's CSV and foreign ones both work.

use anyhow::{bail, Context, Result};
use serde::Deserialize;

/// A parsed CSV table: numeric columns by header name.
#[derive(Clone, Debug)]
pub struct Table {
    /// Where it came from, for messages.
    pub source: String,
    headers: Vec<String>,
    rows: Vec<Vec<f64>>,
    /// The line number (1-based) of each row, for messages.
    lines: Vec<usize>,
}

impl Table {
    /// Parses comma-separated text with a header row. Blank lines and
    /// lines starting with `#` are skipped; empty cells read as NaN.
    pub fn parse(source: &str, bytes: &[u8]) -> Result<Table> {
        let text = std::str::from_utf8(bytes).with_context(|| format!("{source}: not UTF-8 text"))?;
        let mut lines = text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty() && !l.starts_with('#'));
        let Some((_, header)) = lines.next() else { bail!("{source}: empty file (no header row)") };
        let headers: Vec<String> =
            header.split(',').map(|h| h.trim().trim_matches('"').trim_start_matches('\u{feff}').to_string()).collect();
        let mut rows = Vec::new();
        let mut numbers = Vec::new();
        for (i, line) in lines {
            let cells: Vec<&str> = line.split(',').collect();
            if cells.len() != headers.len() {
                bail!("{source}:{}: {} cells, but the header has {}", i + 1, cells.len(), headers.len());
            }
            let row = cells
                .iter()
                .zip(&headers)
                .map(|(c, h)| {
                    let c = c.trim().trim_matches('"');
                    if c.is_empty() {
                        return Ok(f64::NAN);
                    }
                    c.parse::<f64>().with_context(|| format!("{source}:{}: column {h}: {c:?} is not a number", i + 1))
                })
                .collect::<Result<Vec<f64>>>()?;
            rows.push(row);
            numbers.push(i + 1);
        }
        Ok(Table { source: source.to_string(), headers, rows, lines: numbers })
    }

    /// The column named `name`, if present.
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        let i = self.headers.iter().position(|h| h == name)?;
        Some(self.rows.iter().map(|r| r[i]).collect())
    }

    /// Errors at the first row whose value in `values` (a column of this table) fails `ok`,
    /// naming the line, the column and what the value must be.
    fn check(&self, values: &[f64], column: &str, must: &str, ok: impl Fn(f64) -> bool) -> Result<()> {
        match values.iter().zip(&self.lines).find(|(v, _)| !ok(**v)) {
            Some((v, line)) => bail!("{}:{line}: {column} {v} is not {must}; fix or remove the row", self.source),
            None => Ok(()),
        }
    }

    /// Whether the table has no data rows.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }
}

/// Wall distances of a profile table in units of `unit_name` (`dp` or
/// `dpv`), from the matching column or from `wall_distance_mm / length_mm`.
pub fn wall_distance(table: &Table, unit_name: &str, length_mm: Option<f64>, length_flag: &str) -> Result<Vec<f64>> {
    let in_tube = |v: f64| v.is_finite() && v >= 0.0;
    let must = "a distance from the wall (a number >= 0; the profile lies inside the tube)";
    let column = format!("wall_distance_{unit_name}");
    if let Some(z) = table.column(&column) {
        table.check(&z, &column, must, in_tube)?;
        return Ok(z);
    }
    match (table.column("wall_distance_mm"), length_mm) {
        (Some(mm), Some(len)) => {
            table.check(&mm, "wall_distance_mm", must, in_tube)?;
            Ok(mm.iter().map(|v| v / len).collect())
        }
        (Some(_), None) => bail!(
            "{}: has wall_distance_mm but not wall_distance_{unit_name}; give {length_flag} MM or a --summary",
            table.source
        ),
        (None, _) => bail!(
            "{}: missing column wall_distance_{unit_name} or wall_distance_mm (the header needs one of them and void_fraction)",
            table.source
        ),
    }
}

/// The void fraction column; every row a fraction in [0, 1].
pub fn void_fraction(table: &Table) -> Result<Vec<f64>> {
    let eps =
        table.column("void_fraction").with_context(|| format!("{}: missing column void_fraction", table.source))?;
    table.check(&eps, "void_fraction", "a fraction in [0, 1]", |v| (0.0..=1.0).contains(&v))?;
    Ok(eps)
}

/// The tube diameter implied by `r_mm + wall_distance_mm` (first row).
pub fn tube_diameter_from_columns(table: &Table) -> Option<f64> {
    let r = table.column("r_mm")?;
    let w = table.column("wall_distance_mm")?;
    let d = 2.0 * (r.first()? + w.first()?);
    (d.is_finite() && d > 0.0).then_some(d)
}

/// The pellet length (mm) implied by `wall_distance_mm / wall_distance_{unit}`
/// (`unit` = `dp` or `dpv`), from the row farthest from the wall, where the
/// CSV's rounding matters least.
pub fn length_from_columns(table: &Table, unit_name: &str) -> Option<f64> {
    let mm = table.column("wall_distance_mm")?;
    let z = table.column(&format!("wall_distance_{unit_name}"))?;
    let (m, z) = mm
        .iter()
        .zip(&z)
        .filter(|(m, z)| m.is_finite() && z.is_finite() && **m > 0.0 && **z > 0.0)
        .max_by(|a, b| a.1.total_cmp(b.1))?;
    Some(m / z)
}

/// A profile's columns: wall distance, void fraction, optional spread.
pub type Rows = (Vec<f64>, Vec<f64>, Option<Vec<f64>>);

/// Sorts (z, ε, spread) rows by z and drops rows with a non-finite z or ε.
pub fn sorted_rows(z: Vec<f64>, eps: Vec<f64>, spread: Option<Vec<f64>>) -> Rows {
    let mut rows: Vec<(f64, f64, f64)> = z
        .into_iter()
        .zip(eps)
        .enumerate()
        .map(|(i, (z, e))| (z, e, spread.as_ref().map_or(0.0, |s| s[i])))
        .filter(|(z, e, _)| z.is_finite() && e.is_finite())
        .collect();
    rows.sort_by(|a, b| a.0.total_cmp(&b.0));
    let has_spread = spread.is_some();
    let z = rows.iter().map(|r| r.0).collect();
    let e = rows.iter().map(|r| r.1).collect();
    let s = has_spread.then(|| rows.iter().map(|r| if r.2.is_finite() { r.2 } else { 0.0 }).collect());
    (z, e, s)
}

/// The fields of a voidprof summary JSON that compare uses; all optional so
/// that hand-written summaries work.
#[derive(Clone, Debug, Default, Deserialize)]
pub struct Summary {
    /// Tube-average porosity.
    pub bulk_porosity: Option<f64>,
    /// Pellet shape name.
    pub shape: Option<String>,
    /// Nominal pellet diameter (mm).
    pub pellet_diameter_mm: Option<f64>,
    /// Volume-equivalent sphere diameter (mm).
    pub dpv_mm: Option<f64>,
    /// Tube diameter (mm).
    pub tube_diameter_mm: Option<f64>,
    /// D/dp.
    #[serde(rename = "N")]
    pub n: Option<f64>,
    /// D/dpv.
    #[serde(rename = "N_dpv")]
    pub n_dpv: Option<f64>,
    /// Rings: inner over outer diameter, if the summary carries it.
    pub ring_di_do: Option<f64>,
    /// Wadell sphericity of the pellets, if the summary carries it.
    pub sphericity: Option<f64>,
    /// Number of pellets.
    pub pellets: Option<u64>,
    /// The axial window the profile was averaged over, [z0, z1] (mm).
    pub window_mm: Option<[f64; 2]>,
    /// How many beds voidprof measured (the profile is their mean).
    pub beds: Option<u64>,
    /// Each bed voidprof measured; compare uses only the source.
    pub per_bed: Option<Vec<SummaryBed>>,
}

/// One bed of a voidprof summary's `per_bed`.
#[derive(Clone, Debug, Default, Deserialize)]
pub struct SummaryBed {
    /// The file the bed was read from.
    pub source: Option<String>,
}

/// Parses a summary JSON object.
pub fn parse_summary(source: &str, bytes: &[u8]) -> Result<Summary> {
    let s: Summary =
        serde_json::from_slice(bytes).with_context(|| format!("{source}: not a voidprof summary (JSON object)"))?;
    let fraction = |v: f64| (0.0..=1.0).contains(&v);
    let positive = |v: f64| v.is_finite() && v > 0.0;
    type Check<'a> = (&'a str, Option<f64>, &'a str, &'a dyn Fn(f64) -> bool);
    let checks: [Check; 8] = [
        ("bulk_porosity", s.bulk_porosity, "a fraction in [0, 1]", &fraction),
        ("pellet_diameter_mm", s.pellet_diameter_mm, "a length > 0", &positive),
        ("dpv_mm", s.dpv_mm, "a length > 0", &positive),
        ("tube_diameter_mm", s.tube_diameter_mm, "a length > 0", &positive),
        ("N", s.n, "a ratio > 0", &positive),
        ("N_dpv", s.n_dpv, "a ratio > 0", &positive),
        ("ring_di_do", s.ring_di_do, "a ratio in (0, 1)", &|v| v > 0.0 && v < 1.0),
        ("sphericity", s.sphericity, "in (0, 1]", &|v| v > 0.0 && v <= 1.0),
    ];
    if checks.iter().all(|c| c.1.is_none()) && s.shape.is_none() && s.pellets.is_none() {
        bail!("{source}: holds none of a voidprof summary's fields (bulk_porosity, N, shape, …); give the --summary voidprof wrote");
    }
    for (name, value, must, ok) in checks {
        if let Some(v) = value.filter(|v| !ok(*v)) {
            bail!("{source}: {name} {v} is not {must}");
        }
    }
    if let Some([z0, z1]) = s.window_mm {
        if !(z0.is_finite() && z1.is_finite() && z0 < z1) {
            bail!("{source}: window_mm [{z0}, {z1}] is not an axial window (two heights in mm, z0 < z1)");
        }
    }
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn voidprof_header_parses_and_sorts() {
        let csv = "r_mm,wall_distance_mm,wall_distance_dp,wall_distance_dpv,void_fraction\n\
                   24,1,0.1,0.1,0.7\n25,0,0,0,1\n";
        let t = Table::parse("p.csv", csv.as_bytes()).unwrap();
        assert_eq!(tube_diameter_from_columns(&t), Some(50.0));
        assert_eq!(length_from_columns(&t, "dp"), Some(10.0));
        let z = wall_distance(&t, "dp", None, "--dp").unwrap();
        let (z, e, s) = sorted_rows(z, void_fraction(&t).unwrap(), None);
        assert_eq!((z, e, s), (vec![0.0, 0.1], vec![1.0, 0.7], None));
    }

    #[test]
    fn foreign_csv_with_mm_needs_the_pellet_length() {
        let t = Table::parse("f.csv", b"wall_distance_mm,void_fraction,extra\n0,1,x\n").unwrap_err();
        assert!(t.to_string().contains("column extra"), "{t}");
        let t = Table::parse("f.csv", b"wall_distance_mm,void_fraction\n0,1\n5,0.3\n").unwrap();
        assert_eq!(wall_distance(&t, "dp", Some(10.0), "--dp").unwrap(), vec![0.0, 0.5]);
        let e = wall_distance(&t, "dp", None, "--dp").unwrap_err().to_string();
        assert!(e.contains("give --dp"), "{e}");
    }

    #[test]
    fn missing_columns_and_empty_files_are_named() {
        let t = Table::parse("g.csv", b"z,eps\n0,1\n").unwrap();
        assert!(wall_distance(&t, "dp", None, "--dp").unwrap_err().to_string().contains("missing column"));
        assert!(void_fraction(&t).unwrap_err().to_string().contains("missing column void_fraction"));
        assert!(Table::parse("h.csv", b"").unwrap_err().to_string().contains("empty file"));
    }

    #[test]
    fn impossible_rows_and_summaries_are_errors_naming_them() {
        let csv = |rows: &str| format!("wall_distance_dp,void_fraction\n0,1\n{rows}");
        for (rows, needle) in [
            ("0.1,1.7\n", "p.csv:3: void_fraction 1.7 is not a fraction in [0, 1]"),
            ("0.1,-0.5\n", "p.csv:3: void_fraction -0.5"),
            ("0.1,0.4\n0.2,NaN\n", "p.csv:4: void_fraction NaN"),
            ("0.1,\n", "p.csv:3: void_fraction NaN"),
            ("nan,0.4\n", "p.csv:3: wall_distance_dp NaN"),
            ("-1,0.4\n", "p.csv:3: wall_distance_dp -1"),
        ] {
            let t = Table::parse("p.csv", csv(rows).as_bytes()).unwrap();
            let e = wall_distance(&t, "dp", None, "--dp").and_then(|_| void_fraction(&t)).unwrap_err().to_string();
            assert!(e.contains(needle), "{rows:?}: {e}");
        }
        for (json, needle) in [
            ("{}", "none of a voidprof summary's fields"),
            (r#"{"extra": 1}"#, "none of"),
            (r#"{"bulk_porosity": 1.2}"#, "bulk_porosity 1.2 is not a fraction"),
            (r#"{"N": -3}"#, "N -3 is not a ratio > 0"),
            (r#"{"N": 3, "window_mm": [25, 0]}"#, "window_mm [25, 0] is not an axial window"),
        ] {
            let e = parse_summary("s.json", json.as_bytes()).unwrap_err().to_string();
            assert!(e.contains(needle), "{json}: {e}");
        }
    }

    #[test]
    fn summary_fields_are_optional() {
        let s = parse_summary("s.json", br#"{"bulk_porosity":0.41,"N":6.0,"shape":"sphere","extra":[1]}"#).unwrap();
        assert_eq!((s.bulk_porosity, s.n, s.shape.as_deref()), (Some(0.41), Some(6.0), Some("sphere")));
        assert!(parse_summary("s.json", b"[1]").is_err());
        let s = parse_summary(
            "s.json",
            br#"{"N":4.0,"window_mm":[0,25],"beds":1,"per_bed":[{"source":"bed.packing","bulk_porosity":0.4}]}"#,
        )
        .unwrap();
        assert_eq!((s.window_mm, s.beds), (Some([0.0, 25.0]), Some(1)));
        assert_eq!(s.per_bed.unwrap()[0].source.as_deref(), Some("bed.packing"));
    }
}
