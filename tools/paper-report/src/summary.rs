//! `summary.json`, in exactly this schema (the study's tests and scripts read it):
//!
//! ```text
//! {"shapes": {"sphere"|"cylinder"|"ring": {"mre_dixon": fraction,
//!    "beds": [{"tube_diameter_mm", "N", "N_dpv", "porosity_seeds": [...],
//!              "porosity_mean", "dixon"}]}},
//!  "profiles": [{"shape", "N", "reference", "rmse", "r2"}],
//!  "compute_seconds", "machine"}
//! ```
//!
//! N is D/dp (the paper's), N_dpv is D/dpv. `mre_dixon` is the maximum
//! over the finished tubes of |porosity_mean − dixon|/dixon, `null` while
//! no tube of the shape has finished; `r2` is `null` where undefined.
//! For rings `dixon` is the ring-envelope estimate (see the report).

use serde_json::{json, Value};

use crate::analysis::{ProfileResult, TubeResult};

/// The summary object.
pub fn summary(
    shapes: &[(&str, &[TubeResult], Option<f64>)],
    profiles: &[ProfileResult],
    compute_seconds: f64,
    machine: &str,
) -> Value {
    let mut by_shape = serde_json::Map::new();
    for (name, tubes, mre) in shapes {
        let beds: Vec<Value> = tubes
            .iter()
            .map(|t| {
                json!({
                    "tube_diameter_mm": t.tube_diameter_mm,
                    "N": t.n,
                    "N_dpv": t.n_dpv,
                    "porosity_seeds": t.porosity_seeds,
                    "porosity_mean": t.porosity_mean,
                    "dixon": t.dixon,
                })
            })
            .collect();
        by_shape.insert(name.to_string(), json!({ "mre_dixon": mre, "beds": beds }));
    }
    let profiles: Vec<Value> = profiles
        .iter()
        .flat_map(|p| {
            p.scores.iter().map(move |s| {
                json!({ "shape": p.shape.name(), "N": p.n, "reference": s.reference, "rmse": s.rmse, "r2": s.r2 })
            })
        })
        .collect();
    json!({
        "shapes": by_shape,
        "profiles": profiles,
        "compute_seconds": compute_seconds,
        "machine": machine,
    })
}

/// This machine: CPU model, logical cores, OS and architecture.
pub fn machine() -> String {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|t| {
            t.lines()
                .find(|l| l.starts_with("model name"))
                .map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into());
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    format!("{cpu}, {cores} logical cores, {} {}", std::env::consts::OS, std::env::consts::ARCH)
}
