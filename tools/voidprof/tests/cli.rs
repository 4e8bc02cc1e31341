//! Process-boundary tests of `voidprof`: outputs, stdin, several beds, exit codes and one-line errors.

use std::f64::consts::PI;
use std::path::Path;
use std::process::{Command, Output, Stdio};

use pellet_analysis::synthetic::{random_placement, simple_cubic};
use pellet_geom::{Bed, Pellet, Resolution, ShapeSpec};
use pellet_io::{PackingFile, Provenance};

const MM: f64 = 1e-3;

fn voidprof(dir: &Path, args: &[&str], stdin: Option<&[u8]>) -> Output {
    use std::io::Write;
    let mut child = Command::new(env!("CARGO_BIN_EXE_voidprof"))
        .args(args)
        .current_dir(dir)
        .stdin(if stdin.is_some() { Stdio::piped() } else { Stdio::null() })
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run voidprof");
    if let Some(data) = stdin {
        child.stdin.take().unwrap().write_all(data).unwrap();
    }
    child.wait_with_output().unwrap()
}

#[track_caller]
fn assert_ok(out: &Output) {
    assert_eq!(out.status.code(), Some(0), "stderr: {}", String::from_utf8_lossy(&out.stderr));
}

#[track_caller]
fn assert_error(out: &Output, needle: &str) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "stderr: {err}");
    assert!(err.starts_with("voidprof: error: "), "{err}");
    assert!(err.contains(needle), "stderr lacks {needle:?}: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "not one line: {err}");
}

fn sphere() -> Pellet {
    Pellet::build(ShapeSpec::Sphere { diameter_mm: 10.0 }, Resolution::default()).unwrap()
}

fn packing_bytes(bed: &Bed) -> Vec<u8> {
    let file = PackingFile {
        length_unit: "m".into(),
        provenance: Provenance { tool: "test".into(), version: "0".into(), args: vec![] },
        time_s: 0.0,
        verdict: None,
        bed: bed.clone(),
    };
    pellet_io::encode_packing(&file).unwrap()
}

/// (r, ε) rows of a radial CSV, after checking the header.
fn rows(csv: &str) -> Vec<Vec<f64>> {
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("r_mm,wall_distance_mm,wall_distance_dp,wall_distance_dpv,void_fraction"));
    lines.map(|l| l.split(',').map(|f| f.parse().unwrap()).collect()).collect()
}

fn integrated(rows: &[Vec<f64>]) -> f64 {
    let r_tube = rows.last().unwrap()[0];
    let sum: f64 = rows.windows(2).map(|w| 0.5 * (w[1][0] - w[0][0]) * (w[0][0] * w[0][4] + w[1][0] * w[1][4])).sum();
    2.0 * sum / (r_tube * r_tube)
}

/// The analytic bulk porosity of the simple-cubic lattice of 10 mm spheres in `bed`.
fn cubic_porosity(bed: &Bed, z0: f64, z1: f64) -> f64 {
    let a = 5.0;
    let above = |z: f64, zc: f64| {
        let h = (a - (z - zc)).clamp(0.0, 2.0 * a);
        PI * h * h * (3.0 * a - h) / 3.0
    };
    let solid: f64 = bed.pellets.iter().map(|p| above(z0, p.position[2] / MM) - above(z1, p.position[2] / MM)).sum();
    let r = 0.5 * bed.tube.diameter / MM;
    1.0 - solid / (PI * r * r * (z1 - z0))
}

#[test]
fn a_lattice_packing_gives_the_profile_summary_and_axial_profile() {
    let dir = tempfile::tempdir().unwrap();
    let bed = simple_cubic(&sphere(), 40.0 * MM, 10.0 * MM, 5);
    std::fs::write(dir.path().join("bed.packing"), packing_bytes(&bed)).unwrap();
    let out = voidprof(
        dir.path(),
        &["bed.packing", "--window", "3,41.5", "-o", "p.csv", "--summary", "s.json", "--axial", "a.csv", "--structure"],
        None,
    );
    assert_ok(&out);
    assert!(out.stdout.is_empty());
    let rows = rows(&std::fs::read_to_string(dir.path().join("p.csv")).unwrap());
    let analytic = cubic_porosity(&bed, 3.0, 41.5);
    // The wall row: r = R, wall distance 0, ε = 1; the axis row: r = 0.
    let (first, last) = (&rows[0], rows.last().unwrap());
    assert_eq!((first[0], last[0], last[1], last[4]), (0.0, 20.0, 0.0, 1.0));
    assert!((first[2] - 2.0).abs() < 1e-9, "wall distance in dp: {}", first[2]);
    assert!((rows[rows.len() - 2][1] - 0.2).abs() < 1e-9, "default step dp/50");
    assert!((integrated(&rows) - analytic).abs() < 0.002, "{} vs {analytic}", integrated(&rows));
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("s.json")).unwrap()).unwrap();
    assert!((s["bulk_porosity"].as_f64().unwrap() - analytic).abs() < 0.001);
    assert_eq!(s["window_mm"], serde_json::json!([3.0, 41.5]));
    assert_eq!(s["pellets"], 45);
    assert_eq!(s["shape"], "sphere");
    assert_eq!(s["pellet_diameter_mm"], 10.0);
    assert_eq!(s["tube_diameter_mm"], 40.0);
    assert_eq!(s["N"], 4.0);
    assert!((s["dpv_mm"].as_f64().unwrap() - 10.0).abs() < 0.05);
    assert!((s["N_dpv"].as_f64().unwrap() - 4.0).abs() < 0.02);
    // Touching simple-cubic spheres: 4 neighbours in the layer, up to 2 above and below.
    let c = &s["per_bed"][0]["coordination"];
    assert!(c["mean"].as_f64().unwrap() > 2.0, "{c}");
    assert!(s["per_bed"][0]["orientation"].is_null());
    let axial = std::fs::read_to_string(dir.path().join("a.csv")).unwrap();
    assert!(axial.starts_with("z_mm,z_dp,void_fraction\n"));
    assert_eq!(axial.lines().count(), 1 + 77, "38.5 mm in 0.5 mm bins");
}

#[test]
fn stdin_and_stdout_work_and_match_the_file_run() {
    let dir = tempfile::tempdir().unwrap();
    let bed = simple_cubic(&sphere(), 40.0 * MM, 10.0 * MM, 3);
    let bytes = packing_bytes(&bed);
    std::fs::write(dir.path().join("bed.packing"), &bytes).unwrap();
    let piped = voidprof(dir.path(), &["-", "--window", "0,30"], Some(&bytes));
    assert_ok(&piped);
    let from_file = voidprof(dir.path(), &["bed.packing", "--window", "0,30", "-o", "-"], None);
    assert_ok(&from_file);
    assert_eq!(piped.stdout, from_file.stdout);
    assert!(!piped.stdout.is_empty());
}

#[test]
fn poses_csv_gives_the_same_profile_as_the_packing() {
    let dir = tempfile::tempdir().unwrap();
    let cyl = Pellet::build(ShapeSpec::Cylinder { diameter_mm: 10.0, height_mm: 10.0 }, Resolution::default()).unwrap();
    let bed = random_placement(&cyl, 40.0 * MM, 50.0 * MM, 20, 3);
    std::fs::write(dir.path().join("bed.packing"), packing_bytes(&bed)).unwrap();
    let pellet_file = pellet_io::PelletFile {
        length_unit: "m".into(),
        provenance: Provenance { tool: "test".into(), version: "0".into(), args: vec![] },
        pellet: cyl.clone(),
    };
    std::fs::write(dir.path().join("c.pellet"), pellet_io::encode_pellet(&pellet_file).unwrap()).unwrap();
    let mut csv = String::from("id,x,y,z,qw,qx,qy,qz\n");
    for (i, p) in bed.pellets.iter().enumerate() {
        let [x, y, z] = p.position.map(|c| c / MM);
        let [w, a, b, c] = p.orientation;
        csv += &format!("{i},{x:.12},{y:.12},{z:.12},{w:.15},{a:.15},{b:.15},{c:.15}\n");
    }
    std::fs::write(dir.path().join("bed.csv"), &csv).unwrap();
    let window = ["--window", "5,30", "--summary"];
    let a = voidprof(dir.path(), &[&["bed.packing"][..], &window, &["a.json"]].concat(), None);
    let b = voidprof(
        dir.path(),
        &[&["--poses", "bed.csv", "--pellet", "c.pellet", "--tube-diameter", "40"][..], &window, &["b.json"]].concat(),
        None,
    );
    assert_ok(&a);
    assert_ok(&b);
    let (ra, rb) = (rows(&String::from_utf8_lossy(&a.stdout)), rows(&String::from_utf8_lossy(&b.stdout)));
    assert_eq!(ra.len(), rb.len());
    for (x, y) in ra.iter().zip(&rb) {
        assert!((x[4] - y[4]).abs() < 1e-5, "{x:?} vs {y:?}");
    }
    let read = |name: &str| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(dir.path().join(name)).unwrap()).unwrap()
    };
    let (sa, sb) = (read("a.json"), read("b.json"));
    assert!((sa["bulk_porosity"].as_f64().unwrap() - sb["bulk_porosity"].as_f64().unwrap()).abs() < 1e-6);
    assert_eq!(sb["shape"], "cylinder");
    // A cylinder needs orientations.
    let no_q: String = bed
        .pellets
        .iter()
        .enumerate()
        .map(|(i, p)| format!("{i},{},{},{}\n", p.position[0] / MM, p.position[1] / MM, p.position[2] / MM))
        .collect();
    std::fs::write(dir.path().join("noq.csv"), no_q).unwrap();
    let out = voidprof(dir.path(), &["--poses", "noq.csv", "--pellet", "c.pellet", "--tube-diameter", "40"], None);
    assert_error(&out, "qw,qx,qy,qz");
}

#[test]
fn several_beds_give_the_mean_and_the_spread() {
    let dir = tempfile::tempdir().unwrap();
    let names = ["a.packing", "b.packing", "c.packing"];
    for (seed, name) in names.iter().enumerate() {
        let bed = random_placement(&sphere(), 30.0 * MM, 40.0 * MM, 20, seed as u64);
        std::fs::write(dir.path().join(name), packing_bytes(&bed)).unwrap();
    }
    let out = voidprof(
        dir.path(),
        &[&names[..], &["--window", "2,25", "-o", "mean.csv", "--spread", "spread.csv", "--summary", "s.json"]]
            .concat(),
        None,
    );
    assert_ok(&out);
    let mean = rows(&std::fs::read_to_string(dir.path().join("mean.csv")).unwrap());
    let spread = std::fs::read_to_string(dir.path().join("spread.csv")).unwrap();
    let mut lines = spread.lines();
    assert_eq!(
        lines.next().unwrap(),
        "r_mm,wall_distance_mm,wall_distance_dpv,void_fraction_mean,void_fraction_std,void_fraction_min,void_fraction_max,void_fraction_1,void_fraction_2,void_fraction_3"
    );
    for (line, m) in lines.zip(&mean) {
        let v: Vec<f64> = line.split(',').map(|f| f.parse().unwrap()).collect();
        assert!((v[3] - m[4]).abs() < 2e-6);
        let each = &v[7..];
        assert!((each.iter().sum::<f64>() / 3.0 - v[3]).abs() < 2e-6);
        assert!(v[5] <= v[3] + 1e-9 && v[3] <= v[6] + 1e-9);
    }
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("s.json")).unwrap()).unwrap();
    assert_eq!(s["beds"], 3);
    let each: Vec<f64> = (0..3).map(|k| s["per_bed"][k]["bulk_porosity"].as_f64().unwrap()).collect();
    assert!((s["bulk_porosity"].as_f64().unwrap() - each.iter().sum::<f64>() / 3.0).abs() < 1e-12);
    assert!(s["bulk_porosity_std"].as_f64().unwrap() > 0.0);
}

/// Without --window the window runs from the floor to one pellet diameter below the bed's top:
/// a bed shorter than the paper's 100 mm is measured, not refused.
#[test]
fn the_default_window_fits_a_short_bed() {
    let dir = tempfile::tempdir().unwrap();
    // Three layers of 10 mm spheres: the top is at 30 mm, so the window is 0 to 20 mm.
    let bed = simple_cubic(&sphere(), 40.0 * MM, 10.0 * MM, 3);
    std::fs::write(dir.path().join("bed.packing"), packing_bytes(&bed)).unwrap();
    let out = voidprof(dir.path(), &["bed.packing", "-o", "p.csv", "--summary", "s.json"], None);
    assert_ok(&out);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("window 0.000 to 20.000 mm (default: z = 0 to the bed's top (30.000 mm) minus dp"), "{err}");
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("s.json")).unwrap()).unwrap();
    let w = s["window_mm"].as_array().unwrap();
    assert!(w[0].as_f64().unwrap() == 0.0 && (w[1].as_f64().unwrap() - 20.0).abs() < 1e-9, "{w:?}");
    assert!(s["window_rule"].as_str().unwrap().starts_with("default: z = 0 to the bed's top"), "{s}");
    // The same numbers as the window given by hand, which the summary says was given.
    let given = voidprof(dir.path(), &["bed.packing", "--window", "0,20", "-o", "q.csv", "--summary", "t.json"], None);
    assert_ok(&given);
    let t: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("t.json")).unwrap()).unwrap();
    assert_eq!(t["window_rule"], "given by --window");
    assert_eq!(s["bulk_porosity"], t["bulk_porosity"]);
    let read = |f: &str| std::fs::read_to_string(dir.path().join(f)).unwrap();
    assert_eq!(read("p.csv"), read("q.csv"));
    // A bed under two pellet diameters tall is taken whole.
    let low = simple_cubic(&sphere(), 40.0 * MM, 10.0 * MM, 1);
    std::fs::write(dir.path().join("low.packing"), packing_bytes(&low)).unwrap();
    let out = voidprof(dir.path(), &["low.packing", "--summary", "-", "-o", "/dev/null"], None);
    assert_ok(&out);
    let l: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!((l["window_mm"][1].as_f64().unwrap() - 10.0).abs() < 1e-9, "{l}");
}

#[test]
fn bad_input_exits_2_with_one_line_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let bed = simple_cubic(&sphere(), 40.0 * MM, 10.0 * MM, 3);
    let bytes = packing_bytes(&bed);
    std::fs::write(dir.path().join("bed.packing"), &bytes).unwrap();
    std::fs::write(dir.path().join("cut.packing"), &bytes[..bytes.len() / 2]).unwrap();
    std::fs::write(dir.path().join("text.packing"), b"not a packing").unwrap();
    let outs = ["-o", "p.csv", "--summary", "s.json"];
    let cases: &[(&[&str], &str)] = &[
        (&["missing.packing"], "missing.packing"),
        (&["cut.packing", "--window", "0,30"], "is truncated (its data ends early)"),
        (&["text.packing"], "not a packbed packing file"),
        (&["bed.packing", "--window", "10,40"], "outside the bed"),
        (&["bed.packing", "--window", "-5,10"], "outside the bed"),
        (&["bed.packing", "--window", "20,10"], "z1 > z0"),
        (&["bed.packing", "--window", "abc"], "--window"),
        (&["bed.packing", "--window", "0,30", "--dr", "0"], "--dr must be in (0, 5] mm (0 to dp / 2"),
        (&["bed.packing", "--window", "0,30", "--dr", "1e300"], "(got 1e300)"),
        (&["bed.packing", "--window", "0,30", "--contact-gap", "3"], "--contact-gap must be in (0, 2] mm"),
        (&["bed.packing", "--window", "0,30", "--arc", "-1"], "--arc"),
        (&["bed.packing", "--window", "0,30", "--dz", "0"], "--dz"),
        (&["bed.packing", "--window", "0,30", "--dr", "1e-7"], "coarsen"),
        (&[], "give a packing file"),
        (&["--poses", "x.csv", "--pellet", "missing.pellet", "--tube-diameter", "0"], "--tube-diameter"),
    ];
    for (args, needle) in cases {
        let out = voidprof(dir.path(), &[*args, &outs[..]].concat(), None);
        assert_error(&out, needle);
    }
    assert!(!dir.path().join("p.csv").exists() && !dir.path().join("s.json").exists());
    // The reason is said once (it was printed twice: the message and its source).
    let missing = String::from_utf8_lossy(&voidprof(dir.path(), &["missing.packing"], None).stderr).to_string();
    assert_eq!(missing.matches("No such file").count(), 1, "{missing}");
    // Usage errors (clap's) are one line too; --help exits 0 and shows examples.
    assert_error(
        &voidprof(dir.path(), &["--no-such-flag"], None),
        "unknown flag '--no-such-flag' (see voidprof --help)",
    );
    let help = voidprof(dir.path(), &["--help"], None);
    assert_ok(&help);
    assert!(String::from_utf8_lossy(&help.stdout).contains("r_mm,wall_distance_mm"));
}

/// Runs voidprof with its stdout closed, as `voidprof … >&-` does; `Stdio::null()` would be
/// an open stdout.
fn voidprof_stdout_closed(dir: &Path, args: &[&str]) -> Output {
    Command::new("sh")
        .args(["-c", r#""$0" "$@" >&-"#, env!("CARGO_BIN_EXE_voidprof")])
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run voidprof through sh")
}

#[test]
fn two_outputs_naming_one_file_are_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let bed = simple_cubic(&sphere(), 40.0 * MM, 10.0 * MM, 3);
    std::fs::write(dir.path().join("bed.packing"), packing_bytes(&bed)).unwrap();
    std::fs::create_dir(dir.path().join("sub")).unwrap();
    std::fs::write(dir.path().join("old.csv"), b"old").unwrap();
    std::os::unix::fs::symlink("old.csv", dir.path().join("link.csv")).unwrap();
    let cases: &[(&[&str], &str)] = &[
        (&["-o", "x", "--axial", "x"], "-o and --axial both name x; give each output its own file"),
        (&["-o", "x", "--summary", "./x"], "-o x and --summary ./x are the same file"),
        (&["-o", "p.csv", "--axial", "sub/../x", "--spread", "x"], "--axial sub/../x and --spread x"),
        (&["-o", "p.csv", "--spread", "link.csv", "--summary", "old.csv"], "--summary old.csv and --spread link.csv"),
        (&["--axial", "-"], "-o and --axial both name - (stdout)"),
        (&["-o", "p.csv", "--plot", "a.svg", "--plot", "./a.svg"], "--plot a.svg and --plot ./a.svg"),
    ];
    for (flags, needle) in cases {
        let args: Vec<&str> = ["bed.packing", "--window", "0,20"].iter().chain(flags.iter()).copied().collect();
        let out = voidprof(dir.path(), &args, None);
        assert_error(&out, needle);
        assert!(out.stdout.is_empty(), "{flags:?}: something was written to stdout");
        for name in ["x", "p.csv", "a.svg"] {
            assert!(!dir.path().join(name).exists(), "{flags:?}: {name} was written");
        }
        assert_eq!(std::fs::read(dir.path().join("old.csv")).unwrap(), b"old");
    }
}

#[test]
fn a_closed_stdout_is_an_error_not_a_silent_success() {
    let dir = tempfile::tempdir().unwrap();
    let bed = simple_cubic(&sphere(), 40.0 * MM, 10.0 * MM, 3);
    std::fs::write(dir.path().join("bed.packing"), packing_bytes(&bed)).unwrap();
    let out = voidprof_stdout_closed(dir.path(), &["bed.packing", "--window", "0,20", "--summary", "s.json"]);
    assert_error(&out, "cannot write to standard output: it is closed");
    // Nothing is written when one of the outputs cannot be.
    assert!(!dir.path().join("s.json").exists());
    // With the profile in a file, stdout is not needed.
    let out = voidprof_stdout_closed(dir.path(), &["bed.packing", "--window", "0,20", "-o", "p.csv"]);
    assert_ok(&out);
    assert!(dir.path().join("p.csv").exists());
}

#[test]
fn the_plot_marks_wall_and_axis_and_states_the_window_and_the_beds() {
    let dir = tempfile::tempdir().unwrap();
    let bed = simple_cubic(&sphere(), 40.0 * MM, 10.0 * MM, 3);
    std::fs::write(dir.path().join("bed.packing"), packing_bytes(&bed)).unwrap();
    std::fs::write(dir.path().join("other.packing"), packing_bytes(&bed)).unwrap();
    // The SVG's text, XML entities undone.
    let svg = |name: &str| std::fs::read_to_string(dir.path().join(name)).unwrap().replace("&apos;", "'");
    // One bed, the window given.
    let out = voidprof(dir.path(), &["bed.packing", "--window", "2.5,25", "-o", "p.csv", "--plot", "one.svg"], None);
    assert_ok(&out);
    let one = svg("one.svg");
    for needle in [
        "wall (r = R)",
        "axis (r = 0)",
        "ε averaged over the axial window z = 2.5–25 mm (given by --window)",
        "one bed (bed.packing): a single sample; beds packed with another seed differ",
        "N = D/dp = 4.00",
    ] {
        assert!(one.contains(needle), "one.svg lacks {needle:?}");
    }
    // The axis lies in the chart (x = R/dp = 2, the profile's far end): no arrow beyond it.
    assert!(!one.contains('→'));
    // Two beds, the default window (the bed's top, 30 mm, minus dp): a mean with its band.
    let out = voidprof(dir.path(), &["bed.packing", "other.packing", "-o", "p.csv", "--plot", "two.svg"], None);
    assert_ok(&out);
    let two = svg("two.svg");
    for needle in [
        "wall (r = R)",
        "axis (r = 0)",
        "ε averaged over the axial window z = 0–20 mm (voidprof's default window)",
        "mean of 2 beds; the band is ± 1 standard deviation over them",
    ] {
        assert!(two.contains(needle), "two.svg lacks {needle:?}");
    }
    assert!(!two.contains("one bed"));
}
