//! Process-boundary tests of `compare`: the report's numbers against
//! metrics recomputed here from the input files with independent code,
//! exit codes of the gates, and one-line errors (exit 2).

use std::io::Write;
use std::path::Path;
use std::process::{Command, Output, Stdio};

use serde_json::Value;

fn compare(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_compare")).args(args).current_dir(dir).output().expect("run compare")
}

#[track_caller]
fn assert_exit(out: &Output, code: i32) {
    assert_eq!(
        out.status.code(),
        Some(code),
        "stdout: {}\nstderr: {}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

#[track_caller]
fn assert_error(out: &Output, needle: &str) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "stderr: {err}");
    assert!(err.starts_with("compare: error: "), "{err}");
    assert!(err.contains(needle), "stderr lacks {needle:?}: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "not one line: {err}");
}

// ---- independent re-implementations (not pellet_refs) ----

fn de_klerk(z: f64, eb: f64) -> f64 {
    if z <= 0.637 {
        2.14 * z * z - 2.53 * z + 1.0
    } else {
        eb + 0.29 * (-0.6 * z).exp() * (2.3 * std::f64::consts::PI * (z - 0.16)).cos() + 0.15 * (-0.9 * z).exp()
    }
}

/// J0 by its power series (fine to ~1e-9 for x ≤ 25 in f64).
fn j0_series(x: f64) -> f64 {
    let (mut term, mut sum) = (1.0f64, 1.0f64);
    for k in 1..80 {
        term *= -(x * x) / (4.0 * (k * k) as f64);
        sum += term;
    }
    sum
}

fn mueller(z: f64, n: f64) -> f64 {
    let a = if n <= 13.0 { 7.45 - 3.15 / n } else { 7.45 - 11.25 / n };
    let b = 0.315 - 0.725 / n;
    let eb = 0.365 + 0.220 / n;
    eb + (1.0 - eb) * j0_series(a * z) * (-b * z).exp()
}

fn dixon_spheres(n: f64) -> f64 {
    let x = 1.0 / n;
    if x <= 0.5 {
        0.4 + 0.05 * x + 0.412 * x * x
    } else if x <= 0.536 {
        0.528 + 2.464 * (x - 0.5)
    } else {
        1.0 - 0.667 * x.powi(3) / (2.0 * x - 1.0).sqrt()
    }
}

fn foumeny(n: f64) -> f64 {
    0.383 + 0.254 * n.powf(-0.923) / (0.723 * n - 1.0).sqrt()
}

/// (rmse, r2, mae, max) of predicted p against observed o.
fn metrics(o: &[f64], p: &[f64]) -> (f64, f64, f64, f64) {
    let n = o.len() as f64;
    let mean = o.iter().sum::<f64>() / n;
    let ss_res: f64 = o.iter().zip(p).map(|(o, p)| (p - o).powi(2)).sum();
    let ss_tot: f64 = o.iter().map(|o| (o - mean).powi(2)).sum();
    let mae = o.iter().zip(p).map(|(o, p)| (p - o).abs()).sum::<f64>() / n;
    let max = o.iter().zip(p).map(|(o, p)| (p - o).abs()).fold(0.0, f64::max);
    ((ss_res / n).sqrt(), 1.0 - ss_res / ss_tot, mae, max)
}

// ---- fixtures, built here ----

const D: f64 = 60.0;
const DP: f64 = 10.0;

/// A voidprof-style profile of a known function, rounded to 6 decimals as
/// a CSV would be; returns (z, ε) as written.
fn write_profile(path: &Path, phase: f64) -> (Vec<f64>, Vec<f64>) {
    let mut csv = String::from("r_mm,wall_distance_mm,wall_distance_dp,wall_distance_dpv,void_fraction\n");
    let (mut zs, mut es) = (Vec::new(), Vec::new());
    // From the axis outwards, as a profile by r would be written.
    for i in (0..=300).rev() {
        let w = i as f64 * 0.1;
        let z = w / DP;
        let e = 0.4 + 0.6 * (-1.4 * z).exp() * (2.0 * std::f64::consts::PI * z / 0.95 + phase).cos();
        let line = format!("{:.6},{:.6},{:.6},{:.6},{:.6}\n", D / 2.0 - w, w, z, z, e);
        csv += &line;
        let cells: Vec<f64> = line.trim().split(',').map(|c| c.parse().unwrap()).collect();
        zs.push(cells[2]);
        es.push(cells[4]);
    }
    std::fs::write(path, csv).unwrap();
    zs.reverse();
    es.reverse();
    (zs, es)
}

fn write_summary(path: &Path, bulk: f64, d: f64) {
    let s = serde_json::json!({
        "bulk_porosity": bulk, "window_mm": [10.0, 50.0], "pellets": 120, "shape": "sphere",
        "pellet_diameter_mm": DP, "dpv_mm": DP, "tube_diameter_mm": d, "N": d / DP, "N_dpv": d / DP
    });
    std::fs::write(path, s.to_string()).unwrap();
}

fn scores(dir: &Path) -> Vec<Value> {
    let text = std::fs::read_to_string(dir.join("scores.json")).unwrap();
    serde_json::from_str::<Value>(&text).unwrap().as_array().unwrap().clone()
}

fn find<'a>(scores: &'a [Value], reference: &str) -> &'a Value {
    scores.iter().find(|s| s["reference"] == reference).unwrap_or_else(|| panic!("no score for {reference}"))
}

#[track_caller]
fn close(v: &Value, want: f64, tol: f64) {
    let got = v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"));
    assert!((got - want).abs() <= tol, "{got} vs {want}");
}

#[test]
fn report_numbers_equal_metrics_recomputed_from_the_csvs() {
    let dir = tempfile::tempdir().unwrap();
    let (z, eps) = write_profile(&dir.path().join("profile.csv"), 0.0);
    write_summary(&dir.path().join("summary.json"), 0.425, D);
    let out = compare(
        dir.path(),
        &[
            "profile.csv",
            "--summary",
            "summary.json",
            "--ref",
            "mueller-1992,de-klerk,dixon-1988",
            "--eps-b",
            "0.39",
            "-o",
            "report/",
        ],
    );
    assert_exit(&out, 0);
    let s = scores(&dir.path().join("report"));
    assert_eq!(s.len(), 3);
    let n = D / DP;

    let dk = find(&s, "de-klerk-2003");
    assert_eq!(dk["kind"], "profile");
    assert_eq!((dk["valid"].as_bool(), dk["eps_b_method"].as_str()), (Some(true), Some("given")));
    let pred: Vec<f64> = z.iter().map(|&z| de_klerk(z, 0.39)).collect();
    let (rmse, r2, mae, max) = metrics(&eps, &pred);
    close(&dk["rmse"], rmse, 1e-12);
    close(&dk["r2"], r2, 1e-12);
    close(&dk["mae"], mae, 1e-12);
    close(&dk["max_abs_error"], max, 1e-12);
    assert_eq!((dk["points"].as_u64(), dk["z_min"].as_f64(), dk["z_max"].as_f64()), (Some(301), Some(0.0), Some(3.0)));

    let mu = find(&s, "mueller-1992");
    let pred: Vec<f64> = z.iter().map(|&z| mueller(z, n)).collect();
    let (rmse, r2, mae, max) = metrics(&eps, &pred);
    close(&mu["rmse"], rmse, 1e-8);
    close(&mu["r2"], r2, 1e-7);
    close(&mu["mae"], mae, 1e-8);
    close(&mu["max_abs_error"], max, 1e-8);
    assert_eq!(mu["eps_b_method"], "own");

    let dx = find(&s, "dixon-1988");
    assert_eq!(dx["kind"], "bulk");
    close(&dx["simulated"], 0.425, 0.0);
    close(&dx["predicted"], dixon_spheres(n), 1e-15);
    close(&dx["relative_error"], (0.425 - dixon_spheres(n)) / dixon_spheres(n), 1e-14);
    assert_eq!(dx["valid"], true);

    let report = std::fs::read_to_string(dir.path().join("report/report.md")).unwrap();
    for needle in ["profile.csv", "summary.json", "given: 0.39", "z = (R − r)/dp", "de-klerk-2003"] {
        assert!(report.contains(needle), "report.md lacks {needle:?}");
    }
    for plot in ["profile.png", "porosity_vs_n.png"] {
        let bytes = std::fs::read(dir.path().join("report").join(plot)).unwrap();
        assert_eq!(&bytes[..4], b"\x89PNG", "{plot}");
    }
    assert!(dir.path().join("report/profile.svg").exists() && dir.path().join("report/scores.csv").exists());
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("de-klerk-2003") && stdout.contains("plot: report/profile.png"), "{stdout}");
}

#[test]
fn fitted_eps_b_makes_the_correlation_mean_equal_the_bulk_porosity() {
    let dir = tempfile::tempdir().unwrap();
    write_profile(&dir.path().join("profile.csv"), 0.0);
    write_summary(&dir.path().join("summary.json"), 0.425, D);
    let out = compare(dir.path(), &["profile.csv", "--summary", "summary.json", "--ref", "de-klerk", "-o", "r"]);
    assert_exit(&out, 0);
    let s = scores(&dir.path().join("r"));
    let dk = find(&s, "de-klerk-2003");
    assert_eq!(dk["eps_b_method"], "fitted");
    let eb = dk["eps_b"].as_f64().unwrap();
    // Cross-section mean of de Klerk with that ε_b, midpoint rule in r.
    let r_tube = D / DP / 2.0;
    let steps = 200_000;
    let (mut num, mut den) = (0.0, 0.0);
    for i in 0..steps {
        let r = (i as f64 + 0.5) * r_tube / steps as f64;
        num += de_klerk(r_tube - r, eb) * r;
        den += r;
    }
    assert!((num / den - 0.425).abs() < 1e-5, "mean {} with ε_b {eb}", num / den);
    let report = std::fs::read_to_string(dir.path().join("r/report.md")).unwrap();
    assert!(report.contains("fitted (the profile's cross-section mean equals the bed's bulk porosity)"));
}

#[test]
fn several_beds_give_the_maximum_relative_error_over_those_in_range() {
    let dir = tempfile::tempdir().unwrap();
    let beds = [("a.json", 0.43, 50.0), ("b.json", 0.40, 100.0), ("c.json", 0.39, 300.0)];
    for (name, eps, d) in beds {
        write_summary(&dir.path().join(name), eps, d);
    }
    let out = compare(
        dir.path(),
        &["--summary", "a.json,b.json", "--summary", "c.json", "--ref", "foumeny,dixon-spheres", "-o", "r"],
    );
    assert_exit(&out, 0);
    let s = scores(&dir.path().join("r"));
    // Foumeny: valid for N ≤ 23.5, so bed c (N = 30) is flagged and left out of the MRE.
    let f = find(&s, "foumeny-1993");
    let rel = |eps: f64, n: f64, f: fn(f64) -> f64| (eps - f(n)) / f(n);
    let want = rel(0.43, 5.0, foumeny).abs().max(rel(0.40, 10.0, foumeny).abs());
    close(&f["mre"], want, 1e-14);
    assert_eq!(f["beds"][2]["valid"], false);
    assert_eq!(f["valid"], true);
    let dx = find(&s, "dixon-1988");
    let want = [rel(0.43, 5.0, dixon_spheres), rel(0.40, 10.0, dixon_spheres), rel(0.39, 30.0, dixon_spheres)]
        .iter()
        .fold(0.0f64, |m, r| m.max(r.abs()));
    close(&dx["mre"], want, 1e-14);
    assert!(dir.path().join("r/porosity_vs_n.svg").exists());
    assert!(!dir.path().join("r/profile.png").exists(), "no profile, no profile plot");
}

#[test]
fn several_packings_are_scored_as_their_mean() {
    let dir = tempfile::tempdir().unwrap();
    let (z, e1) = write_profile(&dir.path().join("p1.csv"), 0.0);
    let (_, e2) = write_profile(&dir.path().join("p2.csv"), 0.3);
    let out = compare(
        dir.path(),
        &[
            "p1.csv",
            "--profile",
            "p2.csv",
            "--dp",
            "10",
            "--tube-diameter",
            "60",
            "--ref",
            "de-klerk",
            "--eps-b",
            "0.4",
            "-o",
            "r",
        ],
    );
    assert_exit(&out, 0);
    let mean: Vec<f64> = e1.iter().zip(&e2).map(|(a, b)| 0.5 * (a + b)).collect();
    let pred: Vec<f64> = z.iter().map(|&z| de_klerk(z, 0.4)).collect();
    let (rmse, ..) = metrics(&mean, &pred);
    close(&find(&scores(&dir.path().join("r")), "de-klerk-2003")["rmse"], rmse, 1e-12);
}

#[test]
fn experimental_points_are_scored_against_the_interpolated_simulation() {
    let dir = tempfile::tempdir().unwrap();
    let (z, eps) = write_profile(&dir.path().join("profile.csv"), 0.0);
    // Half-way between samples, and one point beyond the profile (z = 3.5).
    std::fs::write(dir.path().join("exp.csv"), "wall_distance_mm,void_fraction\n0.55,0.9\n10.05,0.5\n35,0.4\n")
        .unwrap();
    let out = compare(dir.path(), &["profile.csv", "--dp", "10", "--exp", "exp.csv", "--ref", "", "-o", "r"]);
    assert_exit(&out, 0);
    let s = scores(&dir.path().join("r"));
    let e = find(&s, "exp:exp.csv");
    let interp = |x: f64| {
        let i = z.iter().position(|&v| v > x).unwrap();
        eps[i - 1] + (eps[i] - eps[i - 1]) * (x - z[i - 1]) / (z[i] - z[i - 1])
    };
    let (rmse, _, mae, max) = metrics(&[0.9, 0.5], &[interp(0.055), interp(1.005)]);
    close(&e["rmse"], rmse, 1e-12);
    close(&e["mae"], mae, 1e-12);
    close(&e["max_abs_error"], max, 1e-12);
    assert_eq!(e["points"], 2);
    assert!(e["notes"][0].as_str().unwrap().contains("1 of 3 data points outside"));
}

#[test]
fn gates_exit_1_when_a_gated_score_is_worse() {
    let dir = tempfile::tempdir().unwrap();
    write_profile(&dir.path().join("profile.csv"), 0.0);
    write_summary(&dir.path().join("summary.json"), 0.425, D);
    let base = ["profile.csv", "--summary", "summary.json", "--no-plots", "-o", "r"];
    let run = |extra: &[&str]| compare(dir.path(), &[&base[..], extra].concat());
    let out = run(&["--ref", "de-klerk,dixon", "--fail-above", "rmse=0.001"]);
    assert_exit(&out, 1);
    assert!(String::from_utf8_lossy(&out.stdout).contains("FAIL de-klerk-2003: rmse"));
    assert!(std::fs::read_to_string(dir.path().join("r/report.md")).unwrap().contains("**Failed:**"));
    assert_exit(&run(&["--ref", "de-klerk,dixon", "--fail-above", "rmse=1,mre=0.5"]), 0);
    assert_exit(&run(&["--ref", "dixon", "--fail-above", "mre=0.001"]), 1);
    assert_exit(&run(&["--ref", "de-klerk", "--fail-below", "r2=0.999"]), 1);
    // Grade C correlations are shown but never gated.
    assert_exit(&run(&["--ref", "martin-1978,zou-yu", "--fail-above", "rmse=0,mre=0"]), 0);
    // Out of range: flagged, not gated (Foumeny at N = 30).
    write_summary(&dir.path().join("wide.json"), 0.2, 300.0);
    let out =
        compare(dir.path(), &["--summary", "wide.json", "--ref", "foumeny", "--fail-above", "mre=0.01", "-o", "w"]);
    assert_exit(&out, 0);
    assert_eq!(find(&scores(&dir.path().join("w")), "foumeny-1993")["valid"], false);
}

#[test]
fn profile_from_stdin_and_a_foreign_csv_in_mm() {
    let dir = tempfile::tempdir().unwrap();
    let csv =
        "wall_distance_mm,void_fraction,void_fraction_std\n0,1,0\n2,0.6,0.02\n5,0.25,0.03\n10,0.55,0.02\n20,0.4,0.01\n";
    let mut child = Command::new(env!("CARGO_BIN_EXE_compare"))
        .args(["-", "--dp", "10", "--tube-diameter", "50", "--ref", "de-klerk,mueller", "-o", "r"])
        .current_dir(dir.path())
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    child.stdin.take().unwrap().write_all(csv.as_bytes()).unwrap();
    let out = child.wait_with_output().unwrap();
    assert_exit(&out, 0);
    let s = scores(&dir.path().join("r"));
    assert_eq!(find(&s, "mueller-1992")["N"], 5.0);
    assert_eq!(find(&s, "de-klerk-2003")["z_max"], 2.0);
    let report = std::fs::read_to_string(dir.path().join("r/report.md")).unwrap();
    assert!(report.contains("| simulated profile | `stdin` |"), "{report}");
}

#[test]
fn list_refs_names_every_reference() {
    let out = compare(Path::new("."), &["--list-refs"]);
    assert_exit(&out, 0);
    let text = String::from_utf8_lossy(&out.stdout);
    for name in ["de-klerk-2003", "mueller-1992", "dixon-1988", "dixon-spheres", "foumeny-1993", "ring-envelope-dixon"]
    {
        assert!(text.contains(name), "{name}");
    }
}

#[test]
fn bad_input_is_a_one_line_error_with_exit_2_and_no_report() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path();
    write_profile(&p.join("ok.csv"), 0.0);
    std::fs::write(p.join("nocol.csv"), "wall_distance_dp,eps\n0,1\n").unwrap();
    std::fs::write(p.join("nowall.csv"), "r_mm,void_fraction\n0,1\n").unwrap();
    std::fs::write(p.join("empty.csv"), "wall_distance_dp,void_fraction\n").unwrap();
    std::fs::write(p.join("blank.csv"), "").unwrap();
    std::fs::write(p.join("text.csv"), "wall_distance_dp,void_fraction\n0,abc\n").unwrap();
    std::fs::write(p.join("bad.json"), "{not json").unwrap();
    std::fs::write(p.join("zonly.csv"), "wall_distance_dp,void_fraction\n0,1\n0.5,0.3\n1,0.5\n").unwrap();
    let cases: &[(&[&str], &str)] = &[
        (&["nocol.csv", "--ref", "de-klerk", "--eps-b", "0.4"], "nocol.csv: missing column void_fraction"),
        (&["nowall.csv", "--ref", "de-klerk", "--eps-b", "0.4"], "missing column wall_distance_dp"),
        (&["empty.csv", "--ref", "de-klerk"], "empty.csv: empty profile"),
        (&["blank.csv", "--ref", "de-klerk"], "blank.csv: empty file"),
        (&["text.csv"], "text.csv:2: column void_fraction: \"abc\" is not a number"),
        (&["ok.csv", "--ref", "de-klerk,nosuch-1999", "--eps-b", "0.4"], "unknown reference \"nosuch-1999\""),
        (&["missing.csv"], "missing.csv"),
        (&["ok.csv", "--summary", "bad.json"], "bad.json: not a voidprof summary"),
        // Without the mm columns nothing gives N or the bulk porosity.
        (&["zonly.csv", "--ref", "mueller"], "mueller-1992 needs N"),
        (&["zonly.csv", "--ref", "de-klerk"], "needs the bed's bulk porosity"),
        (&["--summary", "bad.json", "--fail-above", "rsme=0.1"], "unknown metric \"rsme\""),
        (&["ok.csv", "--dp", "-3"], "--dp must be in (0, 10000] mm (got -3)"),
        (&["ok.csv", "--dp", "1e300"], "--dp must be in (0, 10000] mm (got 1e300)"),
        (&["ok.csv", "--dp", "10", "--sphericity", "5"], "--sphericity must lie in (0, 1] (got 5)"),
        (&[], "nothing to compare"),
    ];
    for (args, needle) in cases {
        let out_dir = p.join("out");
        let out = compare(p, &[*args, &["-o", "out"]].concat());
        assert_error(&out, needle);
        assert!(!out_dir.join("scores.json").exists(), "{args:?} wrote a report");
    }
    // A usage error (clap's) is one line too, naming what is missing.
    assert_error(&compare(p, &["ok.csv"]), "missing --output (see compare --help)");
}

fn dixon_cylinders(n: f64) -> f64 {
    let x = 1.0 / n;
    if x <= 0.6 {
        0.36 + 0.10 * x + 0.70 * x * x
    } else if x <= 0.7 {
        0.677 - 9.0 * (x - 0.625).powi(2)
    } else {
        1.0 - 0.763 * x * x
    }
}

#[test]
fn cylinders_and_rings_use_each_correlations_own_n() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path();
    // Equilateral cylinder d = h = 10 mm: dpv = (1.5 d² h)^(1/3).
    let dpv = (1.5f64 * 1000.0).cbrt();
    let d = 60.0;
    let s = serde_json::json!({
        "bulk_porosity": 0.40, "shape": "cylinder", "pellet_diameter_mm": 10.0, "dpv_mm": dpv,
        "tube_diameter_mm": d, "N": d / 10.0, "N_dpv": d / dpv
    });
    std::fs::write(p.join("cyl.json"), s.to_string()).unwrap();
    let out = compare(p, &["--summary", "cyl.json", "--ref", "dixon,foumeny,pushnov", "-o", "c"]);
    assert_exit(&out, 0);
    let sc = scores(&p.join("c"));
    let dx = find(&sc, "dixon-1988");
    close(&dx["beds"][0]["N"], d / dpv, 1e-12);
    close(&dx["predicted"], dixon_cylinders(d / dpv), 1e-14);
    assert_eq!((dx["n_definition"].as_str(), dx["valid"].as_bool()), (Some("N = D/dpv"), Some(true)));
    // A sphere correlation on a cylinder bed: computed, flagged.
    let f = find(&sc, "foumeny-1993");
    assert_eq!(f["valid"], false);
    assert!(f["notes"][0].as_str().unwrap().contains("correlation for spheres, bed of cylinders"));
    close(&find(&sc, "pushnov-2006")["predicted"], 0.9198 / 36.0 + 0.3414, 1e-14);

    // Rings 10/5 × 10 mm: the envelope estimate uses N of the envelope cylinder.
    let ring_dpv = dpv * (0.75f64).cbrt();
    let s = serde_json::json!({
        "bulk_porosity": 0.6, "shape": "ring", "pellet_diameter_mm": 10.0, "dpv_mm": ring_dpv,
        "tube_diameter_mm": d, "N": 6.0, "N_dpv": d / ring_dpv
    });
    std::fs::write(p.join("ring.json"), s.to_string()).unwrap();
    let out = compare(p, &["--summary", "ring.json", "--ref", "ring-envelope", "-o", "r"]);
    assert_error(
        &out,
        "ring-envelope-dixon needs N = D/dpv(envelope cylinder) for ring.json (give N_dpv and the rings' di/do)",
    );
    let out = compare(p, &["--summary", "ring.json", "--ring-di-do", "0.5", "-o", "r"]);
    assert_exit(&out, 0);
    let sc = scores(&p.join("r"));
    let ring = find(&sc, "ring-envelope-dixon");
    close(&ring["beds"][0]["N"], d / dpv, 1e-9);
    close(&ring["predicted"], 1.0 - (1.0 - dixon_cylinders(d / dpv)) * 0.75, 1e-9);
    assert!(p.join("r/porosity_vs_n.png").exists());
}

#[test]
fn a_voidprof_profile_alone_is_enough() {
    // D from r_mm + wall_distance_mm, dp from wall_distance_mm / wall_distance_dp,
    // bulk porosity from the profile's cross-section mean.
    let dir = tempfile::tempdir().unwrap();
    let (z, eps) = write_profile(&dir.path().join("profile.csv"), 0.0);
    let out = compare(dir.path(), &["profile.csv", "--ref", "dixon-spheres,de-klerk,mueller-1992", "-o", "report/"]);
    assert_exit(&out, 0);
    let s = scores(&dir.path().join("report"));
    close(&find(&s, "mueller-1992")["N"], 6.0, 1e-9);
    // Area-weighted trapezoid over r = R − z·dp, in dp units (R = 3).
    let (mut num, mut den) = (0.0, 0.0);
    for i in 1..z.len() {
        let (r0, r1) = (3.0 - z[i - 1], 3.0 - z[i]);
        num += 0.5 * (eps[i - 1] * r0 + eps[i] * r1) * (r0 - r1);
        den += 0.5 * (r0 + r1) * (r0 - r1);
    }
    close(&find(&s, "dixon-1988")["simulated"], num / den, 1e-12);
    assert_eq!(find(&s, "de-klerk-2003")["eps_b_method"], "fitted");
    let report = std::fs::read_to_string(dir.path().join("report/report.md")).unwrap();
    assert!(report.contains("the profile's cross-section mean"), "{report}");
}

#[test]
fn default_references_the_inputs_cannot_feed_are_skipped_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    // No mm columns: N unknown, so Mueller (which needs N) is skipped; ε_b given.
    std::fs::write(dir.path().join("z.csv"), "wall_distance_dp,void_fraction\n0,1\n0.5,0.25\n1,0.55\n2,0.4\n").unwrap();
    let out = compare(dir.path(), &["z.csv", "--eps-b", "0.39", "-o", "r"]);
    assert_exit(&out, 0);
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("compare: warning: skipped mueller-1992: mueller-1992 needs N")
    );
    let s = scores(&dir.path().join("r"));
    assert!(s.iter().any(|x| x["reference"] == "de-klerk-2003"));
    assert!(!s.iter().any(|x| x["reference"] == "mueller-1992"));
    assert_error(&compare(dir.path(), &["z.csv", "-o", "-"]), "-o takes a directory");
}

#[test]
fn the_sphericity_form_needs_phi_and_flags_spheres() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path();
    write_summary(&p.join("s.json"), 0.42, 60.0);
    let out = compare(p, &["--summary", "s.json", "--ref", "benyahia-oneill-sphericity", "-o", "s"]);
    assert_exit(&out, 0);
    let want = 0.1504 + 0.2024 / 1.0 + 1.0814 / (6.0f64 + 0.1226).powi(2);
    let sc = scores(&p.join("s"));
    let sph = find(&sc, "benyahia-oneill-2005-sphericity");
    close(&sph["predicted"], want, 1e-14);
    // φ = 1 lies outside its range (0.42 < φ < 1): computed, flagged.
    assert_eq!(sph["valid"], false);
    let dpv = (1.5f64 * 1000.0).cbrt();
    let cyl = serde_json::json!({"bulk_porosity": 0.4, "shape": "cylinder", "N": 6.0, "N_dpv": 60.0 / dpv});
    std::fs::write(p.join("c.json"), cyl.to_string()).unwrap();
    let args = ["--summary", "c.json", "--ref", "benyahia-oneill-2005-sphericity", "-o", "c"];
    assert_error(&compare(p, &args), "needs the sphericity φ of the pellets in c.json");
    let out = compare(p, &[&args[..], &["--sphericity", "0.874"]].concat());
    assert_exit(&out, 0);
    let want = 0.1504 + 0.2024 / 0.874 + 1.0814 / (60.0 / dpv + 0.1226).powi(2);
    close(&find(&scores(&p.join("c")), "benyahia-oneill-2005-sphericity")["predicted"], want, 1e-14);
    let out = compare(p, &[&args[..], &["--sphericity", "0.3"]].concat());
    assert_exit(&out, 0);
    assert_eq!(find(&scores(&p.join("c")), "benyahia-oneill-2005-sphericity")["valid"], false);
}

#[test]
fn same_inputs_give_identical_outputs() {
    let run = || {
        let dir = tempfile::tempdir().unwrap();
        write_profile(&dir.path().join("profile.csv"), 0.0);
        write_summary(&dir.path().join("summary.json"), 0.425, D);
        assert_exit(&compare(dir.path(), &["profile.csv", "--summary", "summary.json", "-o", "r"]), 0);
        ["scores.json", "scores.csv", "report.md", "profile.svg", "profile.png", "porosity_vs_n.svg"]
            .map(|f| std::fs::read(dir.path().join("r").join(f)).unwrap())
    };
    assert!(run() == run(), "outputs differ between two identical runs");
}

#[test]
fn a_closed_stdout_is_an_error_not_a_silent_success() {
    let dir = tempfile::tempdir().unwrap();
    // `>&-` closes stdout; `Stdio::null()` would be an open one.
    let out = Command::new("sh")
        .args(["-c", r#""$0" "$@" >&-"#, env!("CARGO_BIN_EXE_compare"), "--list-refs"])
        .current_dir(dir.path())
        .output()
        .expect("run compare through sh");
    assert_error(&out, "cannot write to standard output: it is closed");
    let discarded = Command::new(env!("CARGO_BIN_EXE_compare")).arg("--list-refs").stdout(Stdio::null()).status();
    assert_eq!(discarded.unwrap().code(), Some(0));
}

#[test]
fn the_table_is_aligned_and_says_what_the_json_says() {
    let dir = tempfile::tempdir().unwrap();
    write_profile(&dir.path().join("profile.csv"), 0.0);
    write_summary(&dir.path().join("summary.json"), 0.425, D);
    let args =
        ["profile.csv", "--summary", "summary.json", "--ref", "mueller-1992,de-klerk,martin,dixon-1988", "-o", "r"];
    let out = compare(dir.path(), &[&args[..], &["--table", "scores.txt"]].concat());
    assert_exit(&out, 0);
    let text = std::fs::read_to_string(dir.path().join("scores.txt")).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 5, "{text}");
    let head = lines[0];
    for col in ["reference", "kind", "grade", "rmse", "r2", "simulated", "predicted", "error_%", "note"] {
        assert!(head.split_whitespace().any(|w| w == col), "{head}");
    }
    // Aligned: every row's kind starts where the header's does, right-aligned numbers end where
    // their header ends.
    let (kind_at, rmse_end) = (head.find("kind").unwrap(), head.find("rmse").unwrap() + 4);
    for line in &lines[1..] {
        assert!(line[kind_at..].starts_with("profile") || line[kind_at..].starts_with("bulk"), "{text}");
        assert!(line[..rmse_end].ends_with(|c: char| c.is_ascii_digit() || c == '-'), "{text}");
        assert_eq!(line, &line.trim_end(), "trailing blanks: {text}");
    }
    let s = scores(&dir.path().join("r"));
    let row = |name: &str| lines.iter().find(|l| l.starts_with(name)).unwrap_or_else(|| panic!("{name}: {text}"));
    let dk = row("de-klerk-2003");
    assert!(dk.contains(&format!("{:.4}", find(&s, "de-klerk-2003")["rmse"].as_f64().unwrap())), "{dk}");
    assert!(row("martin-1978").ends_with("grade C, not gated"), "{text}");
    let dx = find(&s, "dixon-1988");
    let cells: Vec<&str> = row("dixon-1988").split_whitespace().collect();
    assert_eq!(cells[1..5], ["bulk", "A", "-", "-"], "{text}");
    assert_eq!(cells[5], format!("{:.4}", dx["simulated"].as_f64().unwrap()));
    assert_eq!(cells[7], format!("{:+.2}", 100.0 * dx["relative_error"].as_f64().unwrap()));
    // On stdout, in place of the line per score; a clash with the report's own files is refused.
    let out = compare(dir.path(), &[&args[..], &["--table", "-"]].concat());
    assert_exit(&out, 0);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.starts_with(&text) && stdout.contains("report: r/report.md"), "{stdout}");
    assert_error(&compare(dir.path(), &[&args[..], &["--table", "r/scores.csv"]].concat()), "scores.csv");
}

/// The text of an SVG, XML entities undone.
fn svg_text(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap().replace("&apos;", "'").replace("&quot;", "\"").replace("&amp;", "&")
}

#[test]
fn the_profile_plot_marks_wall_and_axis_and_states_the_window_and_the_beds() {
    let dir = tempfile::tempdir().unwrap();
    write_profile(&dir.path().join("profile.csv"), 0.0);
    write_profile(&dir.path().join("other.csv"), 0.3);
    let mut s = serde_json::json!({
        "bulk_porosity": 0.425, "window_mm": [0.0, 25.0], "beds": 1, "per_bed": [{"source": "out/bed.packing"}],
        "shape": "sphere", "pellet_diameter_mm": DP, "dpv_mm": DP, "tube_diameter_mm": D, "N": D / DP, "N_dpv": D / DP
    });
    std::fs::write(dir.path().join("summary.json"), s.to_string()).unwrap();
    // One bed, as the default pipeline: its window and that it is a single sample.
    let out = compare(dir.path(), &["profile.csv", "--summary", "summary.json", "--ref", "de-klerk", "-o", "r"]);
    assert_exit(&out, 0);
    let one = svg_text(&dir.path().join("r/profile.svg"));
    for needle in [
        "wall (r = R)",
        "axis (r = 0)",
        "ε averaged over the axial window z = 0–25 mm (summary.json)",
        "one bed (out/bed.packing): a single sample; beds packed with another seed differ",
    ] {
        assert!(one.contains(needle), "profile.svg lacks {needle:?}");
    }
    // The axis, at N/2 = 3, is the profile's far end: drawn in the chart, not named beyond it.
    assert!(!one.contains('→'));

    // Two profiles and no summary: their spread, and neither window nor axis known.
    let out = compare(dir.path(), &["profile.csv", "other.csv", "--dp", "10", "--ref", "de-klerk", "-o", "r2"]);
    assert_exit(&out, 0);
    let two = svg_text(&dir.path().join("r2/profile.svg"));
    for needle in [
        "wall (r = R)",
        "mean of 2 profiles; the band is ± 1 standard deviation over them",
        "axial window not known: no voidprof summary with window_mm describes this profile",
    ] {
        assert!(two.contains(needle), "profile.svg lacks {needle:?}");
    }

    // A summary of several beds whose profile CSV carries no spread says so.
    s["beds"] = 3.into();
    std::fs::write(dir.path().join("summary.json"), s.to_string()).unwrap();
    let out = compare(dir.path(), &["profile.csv", "--summary", "summary.json", "--ref", "de-klerk", "-o", "r3"]);
    assert_exit(&out, 0);
    let three = svg_text(&dir.path().join("r3/profile.svg"));
    assert!(three.contains("mean of 3 beds (voidprof summary); their spread is not in the profile CSV"), "{three}");
}
