//! The bed table (`pipelines/paper/beds.csv`): one row per configuration,
//! expanded into one bed per seed, exactly as `pipelines/paper/ids.awk`
//! does for Make (ids `<config>-s<seed>`).

use anyhow::{bail, Context, Result};
use pellet_refs::Shape;

/// One row of the table.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// Configuration name, unique.
    pub config: String,
    /// `validation`, `loading`, `cor` or `friction`.
    pub study: String,
    /// Pellet shape.
    pub shape: Shape,
    /// Tube inner diameter (mm).
    pub tube_diameter_mm: f64,
    /// Seeds 1..=seeds (before `--repeats`).
    pub seeds: u32,
    /// Pellet–pellet COR, if the row sets it (else pack's default 0.9).
    pub cor: Option<f64>,
    /// Pellet–pellet friction, if the row sets it (else pack's default 0.1).
    pub friction: Option<f64>,
    /// Loading scheme as pack spells it.
    pub scheme: String,
    /// Free text for tables (e.g. the paper's scheme name).
    pub label: String,
    /// Another row whose beds are this row's, seed for seed, because their cases are the same
    /// (the loading study's scheme 1 is the validation bed of its tube): its beds are run once
    /// and counted once.
    pub same_as: Option<String>,
}

/// The columns the report needs; the others are pack's and Make's.
const NEEDED: [&str; 8] = ["config", "study", "shape", "tube_diameter_mm", "seeds", "scheme", "cor", "friction"];

/// Parses the table (CSV with a header row; `#` lines and blank lines skipped).
pub fn parse(text: &str, name: &str) -> Result<Vec<Row>> {
    let mut lines = text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty() && !l.starts_with('#'));
    let (_, header) = lines.next().with_context(|| format!("{name}: empty table"))?;
    let cols: Vec<&str> = header.split(',').map(str::trim).collect();
    let idx = |c: &str| cols.iter().position(|h| *h == c);
    for c in NEEDED {
        if idx(c).is_none() {
            bail!("{name}: the header lacks the column {c:?}");
        }
    }
    let at = |c: &str| idx(c).unwrap_or(usize::MAX);
    let mut rows: Vec<Row> = Vec::new();
    for (i, line) in lines {
        let cells: Vec<&str> = line.split(',').map(str::trim).collect();
        let cell = |c: &str| cells.get(at(c)).copied().unwrap_or("");
        let line_no = i + 1;
        let num = |c: &str| -> Result<Option<f64>> {
            let v = cell(c);
            if v.is_empty() {
                return Ok(None);
            }
            match v.parse::<f64>() {
                Ok(x) if x.is_finite() => Ok(Some(x)),
                _ => bail!("{name}:{line_no}: {c} is not a number ({v:?})"),
            }
        };
        let shape = Shape::parse(cell("shape"))
            .with_context(|| format!("{name}:{line_no}: unknown shape {:?} (sphere, cylinder, ring)", cell("shape")))?;
        let tube = num("tube_diameter_mm")?
            .filter(|d| *d > 0.0)
            .with_context(|| format!("{name}:{line_no}: tube_diameter_mm must be > 0 mm"))?;
        let seeds = cell("seeds")
            .parse::<u32>()
            .ok()
            .filter(|s| *s >= 1)
            .with_context(|| format!("{name}:{line_no}: seeds must be a whole number ≥ 1"))?;
        let config = cell("config").to_string();
        if config.is_empty() || rows.iter().any(|r| r.config == config) {
            bail!("{name}:{line_no}: config {config:?} is empty or repeated");
        }
        rows.push(Row {
            config,
            study: cell("study").to_string(),
            shape,
            tube_diameter_mm: tube,
            seeds,
            cor: num("cor")?,
            friction: num("friction")?,
            scheme: cell("scheme").to_string(),
            label: cells.get(idx("label").unwrap_or(usize::MAX)).copied().unwrap_or("").to_string(),
            same_as: cells.get(idx("same_as").unwrap_or(usize::MAX)).filter(|c| !c.is_empty()).map(|c| c.to_string()),
        });
    }
    for row in &rows {
        if let Some(other) = &row.same_as {
            let Some(o) = rows.iter().find(|r| &r.config == other) else {
                bail!("{name}: {}: same_as names {other:?}, which is not a row of the table", row.config);
            };
            if o.same_as.is_some()
                || o.shape != row.shape
                || o.tube_diameter_mm != row.tube_diameter_mm
                || o.seeds < row.seeds
            {
                bail!(
                    "{name}: {}: same_as {other:?} must be a row of the same shape and tube with at least {} seeds and no same_as of its own",
                    row.config,
                    row.seeds
                );
            }
        }
    }
    Ok(rows)
}

/// The seeds a row runs: 1..=min(seeds, repeats).
pub fn seeds(row: &Row, repeats: Option<u32>) -> Vec<u32> {
    (1..=repeats.map_or(row.seeds, |r| r.min(row.seeds))).collect()
}

/// A bed's id: `<config>-s<seed>`, with the config of `same_as` if the row has one.
pub fn bed_id(row: &Row, seed: u32) -> String {
    format!("{}-s{seed}", row.same_as.as_deref().unwrap_or(&row.config))
}

#[cfg(test)]
mod tests {
    use super::*;

    const TABLE: &str = "config,study,shape,tube_diameter_mm,seeds,fill_height_mm,scheme,cor,friction,label\n\
        # a comment\n\
        a,validation,sphere,31,3,120,one-column,,,Table 3\n\
        b,cor,cylinder,35.49,6,120,one-column,0.05,0.6,COR 0.05\n";

    #[test]
    fn rows_parse_and_seeds_follow_repeats() {
        let rows = parse(TABLE, "t").unwrap();
        assert_eq!(rows.len(), 2);
        assert_eq!(rows[1].shape, Shape::Cylinder);
        assert_eq!((rows[1].cor, rows[0].cor), (Some(0.05), None));
        assert_eq!(seeds(&rows[0], None), vec![1, 2, 3]);
        assert_eq!(seeds(&rows[1], Some(2)), vec![1, 2]);
        assert_eq!(seeds(&rows[0], Some(9)), vec![1, 2, 3]);
        assert_eq!(bed_id(&rows[1], 4), "b-s4");
    }

    #[test]
    fn bad_rows_name_the_line() {
        let bad = TABLE.replace("35.49", "x");
        assert!(parse(&bad, "t").unwrap_err().to_string().contains("t:4: tube_diameter_mm"));
        let dup = TABLE.replace("b,cor", "a,cor");
        assert!(parse(&dup, "t").unwrap_err().to_string().contains("repeated"));
        assert!(parse("config,study\n", "t").unwrap_err().to_string().contains("lacks the column"));
    }

    #[test]
    fn same_as_rows_name_the_other_rows_beds() {
        let table = "config,study,shape,tube_diameter_mm,seeds,scheme,cor,friction,label,same_as\n\
            v,validation,sphere,31,3,one-column,,,Table 3,\n\
            l,loading,sphere,31,1,one-column,,,scheme 1,v\n";
        let rows = parse(table, "t").unwrap();
        assert_eq!((rows[0].same_as.as_deref(), rows[1].same_as.as_deref()), (None, Some("v")));
        assert_eq!((bed_id(&rows[0], 1), bed_id(&rows[1], 1)), ("v-s1".to_string(), "v-s1".to_string()));
        for (from, to) in [
            ("scheme 1,v", "scheme 1,w"),
            ("l,loading,sphere,31", "l,loading,sphere,32"),
            ("l,loading,sphere,31,1", "l,loading,sphere,31,4"),
        ] {
            let bad = table.replace(from, to);
            assert!(parse(&bad, "t").unwrap_err().to_string().contains("same_as"), "{bad}");
        }
    }
}
