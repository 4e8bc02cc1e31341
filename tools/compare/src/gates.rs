//! `--fail-above` / `--fail-below` quality gates.

use anyhow::{bail, Context, Result};
use pellet_refs::scoring::{Score, METRICS};

/// One gate: a metric and its limit.
#[derive(Clone, Debug, PartialEq)]
pub struct Gate {
    /// Metric name (see [`METRICS`]).
    pub metric: String,
    /// The limit.
    pub limit: f64,
    /// True for `--fail-above` (worse is larger), false for `--fail-below`.
    pub above: bool,
}

/// Parses `rmse=0.08,mre=0.05` (several flags may be given).
pub fn parse(specs: &[String], above: bool) -> Result<Vec<Gate>> {
    let flag = if above { "--fail-above" } else { "--fail-below" };
    let mut gates = Vec::new();
    for item in specs.iter().flat_map(|s| s.split(',')).map(str::trim).filter(|s| !s.is_empty()) {
        let Some((metric, limit)) = item.split_once('=') else {
            bail!("{flag} {item:?}: expected METRIC=LIMIT, e.g. rmse=0.08")
        };
        let metric = metric.trim().to_ascii_lowercase();
        if !METRICS.contains(&metric.as_str()) {
            bail!("{flag}: unknown metric {metric:?} (known: {})", METRICS.join(", "));
        }
        let limit: f64 = limit
            .trim()
            .parse()
            .ok()
            .filter(|v: &f64| v.is_finite())
            .with_context(|| format!("{flag} {item:?}: limit is not a number"))?;
        gates.push(Gate { metric, limit, above });
    }
    Ok(gates)
}

/// A gate a score failed.
#[derive(Clone, Debug, PartialEq)]
pub struct Violation {
    /// The reference scored.
    pub reference: String,
    /// The gate's metric.
    pub metric: String,
    /// The score's value.
    pub value: f64,
    /// The gate's limit.
    pub limit: f64,
    /// Whether the gate was an upper limit.
    pub above: bool,
}

impl std::fmt::Display for Violation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (op, word) = if self.above { (">", "above") } else { ("<", "below") };
        write!(f, "{}: {} = {:.4} {op} {} (fail-{word})", self.reference, self.metric, self.value, self.limit)
    }
}

/// Checks every gated score (valid, not grade C) against every gate that
/// applies to it. Returns the violations and the gates that applied to no
/// score at all.
pub fn check(scores: &[Score], gates: &[Gate]) -> (Vec<Violation>, Vec<Gate>) {
    let mut violations = Vec::new();
    let mut unused = Vec::new();
    for gate in gates {
        let mut applied = false;
        for score in scores.iter().filter(|s| s.is_gated()) {
            let Some(value) = score.metric(&gate.metric) else { continue };
            applied = true;
            let bad = if gate.above { value > gate.limit } else { value < gate.limit };
            if bad {
                violations.push(Violation {
                    reference: score.reference().to_string(),
                    metric: gate.metric.clone(),
                    value,
                    limit: gate.limit,
                    above: gate.above,
                });
            }
        }
        if !applied {
            unused.push(gate.clone());
        }
    }
    (violations, unused)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_lists_and_rejects_unknown_metrics() {
        let g = parse(&["rmse=0.08, mre=0.05".into(), "mae=1".into()], true).unwrap();
        assert_eq!(g.len(), 3);
        assert_eq!(g[1], Gate { metric: "mre".into(), limit: 0.05, above: true });
        assert!(parse(&["rsme=0.1".into()], true).unwrap_err().to_string().contains("unknown metric"));
        assert!(parse(&["rmse".into()], true).is_err());
        assert!(parse(&["rmse=abc".into()], false).unwrap_err().to_string().contains("--fail-below"));
    }
}
