//! End-to-end chains of the real binaries on tiny inputs.

#[path = "paper.rs"]
mod paper;
#[path = "reliability.rs"]
mod reliability;
#[path = "repository.rs"]
mod repository;
#[path = "stepper_study.rs"]
mod stepper_study;

use std::path::Path;

use pellet_tests::Scenario;

#[test]
fn mkpellet_makes_the_three_paper_pellets_and_info_reads_them() {
    let s = Scenario::new();
    s.run("mkpellet", &["sphere", "--diameter", "10", "-o", "s.pellet"]).success();
    s.run("mkpellet", &["cylinder", "--diameter", "10", "--height", "10", "-o", "c.pellet", "--stl", "c.stl"])
        .success();
    s.run("mkpellet", &["ring", "--outer-diameter", "10", "--inner-diameter", "6", "--height", "10", "-o", "r.pellet"])
        .success();
    s.run("mkpellet", &["ring", "--outer-diameter", "10", "--wall", "2", "--height", "10", "-o", "r2.pellet"])
        .success();
    // --wall 2 is the same ring as --inner-diameter 6: same mesh and properties.
    let a = pellet_io::decode_pellet(&std::fs::read(s.file("r.pellet")).unwrap(), "r").unwrap();
    let b = pellet_io::decode_pellet(&std::fs::read(s.file("r2.pellet")).unwrap(), "r2").unwrap();
    assert_eq!(a.pellet, b.pellet);

    let info = s.run("mkpellet", &["info", "c.pellet", "--json"]);
    info.success();
    let v: serde_json::Value = serde_json::from_str(&info.stdout()).unwrap();
    let exact = std::f64::consts::PI * 25.0 * 10.0;
    assert!((v["volume_mm3"].as_f64().unwrap() / exact - 1.0).abs() < 0.005);
    assert_eq!(v["euler_characteristic"], 2);
    s.run("mkpellet", &["info", "r.pellet"]).success().stdout_has("Euler characteristic 0 (genus 1)");
}

#[test]
fn stl_export_reimports_with_the_same_volume() {
    let s = Scenario::new();
    s.run(
        "mkpellet",
        &["ring", "--outer-diameter", "10", "--wall", "2", "--height", "10", "-o", "r.pellet", "--stl", "r.stl"],
    )
    .success();
    s.run("mkpellet", &["import", "r.stl", "--unit", "mm", "-o", "imported.pellet"]).success();
    let orig = pellet_io::decode_pellet(&std::fs::read(s.file("r.pellet")).unwrap(), "r").unwrap().pellet;
    let back = pellet_io::decode_pellet(&std::fs::read(s.file("imported.pellet")).unwrap(), "i").unwrap().pellet;
    // STL stores f32 millimetres: the volume survives to ~1e-6.
    assert!((back.properties.volume / orig.properties.volume - 1.0).abs() < 1e-5);
    assert_eq!(back.mesh.face_count(), orig.mesh.face_count());
    assert_eq!(back.topology().unwrap().euler_characteristic, 0);
    // A nonconvex import is decomposed into several convex pieces.
    assert!(back.pieces.len() > 1);
}

#[test]
fn the_same_command_gives_the_same_bytes() {
    let s = Scenario::new();
    for name in ["a.pellet", "b.pellet"] {
        s.run("mkpellet", &["trilobe", "--lobe-diameter", "1.6", "--size", "2.9", "--height", "5", "-o", name])
            .success();
    }
    // The provenance records -o, so compare the payloads through a decode/encode.
    let a = std::fs::read(s.file("a.pellet")).unwrap();
    let b = std::fs::read(s.file("b.pellet")).unwrap();
    let (fa, fb) = (pellet_io::decode_pellet(&a, "a").unwrap(), pellet_io::decode_pellet(&b, "b").unwrap());
    assert_eq!(fa.pellet, fb.pellet);
    // And with identical arguments the files are byte-identical.
    s.run("mkpellet", &["sphere", "--diameter", "3", "-o", "x.pellet"]).success();
    let first = std::fs::read(s.file("x.pellet")).unwrap();
    s.run("mkpellet", &["sphere", "--diameter", "3", "-o", "x.pellet"]).success();
    assert_eq!(first, std::fs::read(s.file("x.pellet")).unwrap());
}

#[test]
fn pellet_file_streams_through_stdout_and_stdin() {
    let s = Scenario::new();
    let made = s.run("mkpellet", &["sphere", "--diameter", "4"]);
    made.success();
    assert!(made.output.stdout.starts_with(b"PBPELLET"));
    s.run_with_stdin("mkpellet", &["info", "-"], Some(&made.output.stdout)).success().stdout_has("sphere");
}

#[test]
fn mkpellet_then_voidprof_measures_a_bed_given_as_packing_and_as_poses() {
    let s = Scenario::new();
    s.run("mkpellet", &["ring", "--outer-diameter", "10", "--wall", "2", "--height", "10", "-o", "r.pellet"]).success();
    let ring = pellet_io::decode_pellet(&std::fs::read(s.file("r.pellet")).unwrap(), "r").unwrap();
    // Until settle-check lands: a random non-overlapping bed built in code.
    let bed = pellet_analysis::synthetic::random_placement(&ring.pellet, 0.040, 0.050, 25, 5);
    let packing = pellet_io::PackingFile {
        length_unit: "m".into(),
        provenance: ring.provenance.clone(),
        time_s: 0.0,
        verdict: None,
        bed: bed.clone(),
    };
    std::fs::write(s.file("bed.packing"), pellet_io::encode_packing(&packing).unwrap()).unwrap();
    let mut csv = String::from("# written by the test\nid,x,y,z,qw,qx,qy,qz\n");
    for (i, p) in bed.pellets.iter().enumerate() {
        let [x, y, z] = p.position.map(|c| c * 1e3);
        let [w, a, b, c] = p.orientation;
        csv += &format!("{i},{x:.12},{y:.12},{z:.12},{w:.15},{a:.15},{b:.15},{c:.15}\n");
    }
    std::fs::write(s.file("bed.csv"), csv).unwrap();
    s.run("voidprof", &["bed.packing", "--window", "5,35", "-o", "a.csv", "--summary", "a.json", "--structure"])
        .success();
    s.run(
        "voidprof",
        &["--poses", "bed.csv", "--pellet", "r.pellet", "--tube-diameter", "40", "--window", "5,35", "-o", "b.csv"],
    )
    .success();
    let a = std::fs::read_to_string(s.file("a.csv")).unwrap();
    assert!(a.starts_with("r_mm,wall_distance_mm,wall_distance_dp,wall_distance_dpv,void_fraction\n"));
    let b = std::fs::read_to_string(s.file("b.csv")).unwrap();
    assert_eq!(a.lines().count(), b.lines().count());
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(s.file("a.json")).unwrap()).unwrap();
    assert_eq!(v["shape"], "ring");
    assert_eq!(v["pellets"], bed.pellets.len());
    let bulk = v["bulk_porosity"].as_f64().unwrap();
    assert!((v["profile_porosity"].as_f64().unwrap() - bulk).abs() < 0.002);
    assert!(bulk > 0.5 && bulk < 1.0, "{bulk}");
    // A ring's dpv is below its outer diameter: N_dpv > N.
    assert!(v["N_dpv"].as_f64().unwrap() > v["N"].as_f64().unwrap());
    assert_eq!(v["per_bed"][0]["orientation"]["edges_deg"].as_array().unwrap().len(), 10);
}

/// J0 by its power series (accurate to ~1e-9 for x ≤ 25).
fn j0_series(x: f64) -> f64 {
    let (mut term, mut sum) = (1.0f64, 1.0f64);
    for k in 1..80 {
        term *= -(x * x) / (4.0 * (k * k) as f64);
        sum += term;
    }
    sum
}

#[test]
fn voidprof_then_compare_scores_a_sphere_bed_with_numbers_recomputed_from_the_csvs() {
    let s = Scenario::new();
    s.run("mkpellet", &["sphere", "--diameter", "10", "-o", "s.pellet"]).success();
    let sphere = pellet_io::decode_pellet(&std::fs::read(s.file("s.pellet")).unwrap(), "s").unwrap();
    // A close-packed sphere bed in a 45 mm tube (N = 4.5), built in code.
    let bed = pellet_analysis::synthetic::close_packed_spheres(&sphere.pellet, 0.045, 0.0101, 60);
    let packing = pellet_io::PackingFile {
        length_unit: "m".into(),
        provenance: sphere.provenance,
        time_s: 0.0,
        verdict: None,
        bed,
    };
    std::fs::write(s.file("bed.packing"), pellet_io::encode_packing(&packing).unwrap()).unwrap();
    s.run(
        "voidprof",
        &["bed.packing", "--window", "0,30", "-o", "profile.csv", "--summary", "summary.json", "--plot", "p.png"],
    )
    .success();
    assert_eq!(&std::fs::read(s.file("p.png")).unwrap()[..4], b"\x89PNG");
    s.run(
        "compare",
        &["--profile", "profile.csv", "--summary", "summary.json", "--ref", "mueller-1992,dixon-1988", "-o", "report/"],
    )
    .success();
    for file in ["scores.json", "report.md", "profile.png", "profile.svg"] {
        assert!(s.file("report").join(file).exists(), "report/{file} missing");
    }
    let scores: Vec<serde_json::Value> =
        serde_json::from_str(&std::fs::read_to_string(s.file("report/scores.json")).unwrap()).unwrap();
    let find = |name: &str| scores.iter().find(|v| v["reference"] == name).unwrap_or_else(|| panic!("{name}"));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(s.file("summary.json")).unwrap()).unwrap();
    let n = summary["N"].as_f64().unwrap();
    assert!((n - 4.5).abs() < 1e-9);

    // Dixon (1988), spheres: the relative error of the bulk porosity.
    let bulk = summary["bulk_porosity"].as_f64().unwrap();
    let x = 1.0 / n;
    let dixon = 0.4 + 0.05 * x + 0.412 * x * x;
    let dx = find("dixon-1988");
    assert!((dx["simulated"].as_f64().unwrap() - bulk).abs() < 1e-12);
    assert!((dx["predicted"].as_f64().unwrap() - dixon).abs() < 1e-12);
    assert!((dx["relative_error"].as_f64().unwrap() - (bulk - dixon) / dixon).abs() < 1e-12);

    // Mueller (1992) over the points the report says it scored.
    let mu = find("mueller-1992");
    let (z_min, z_max) = (mu["z_min"].as_f64().unwrap(), mu["z_max"].as_f64().unwrap());
    let a = 7.45 - 3.15 / n;
    let b = 0.315 - 0.725 / n;
    let eb = 0.365 + 0.220 / n;
    let csv = std::fs::read_to_string(s.file("profile.csv")).unwrap();
    let (mut obs, mut pred) = (Vec::new(), Vec::new());
    for line in csv.lines().skip(1) {
        let cols: Vec<f64> = line.split(',').map(|c| c.parse().unwrap()).collect();
        let (z, eps) = (cols[2], cols[4]);
        if z >= z_min - 1e-12 && z <= z_max + 1e-12 {
            obs.push(eps);
            pred.push(eb + (1.0 - eb) * j0_series(a * z) * (-b * z).exp());
        }
    }
    assert_eq!(mu["points"].as_u64(), Some(obs.len() as u64));
    let rmse = (obs.iter().zip(&pred).map(|(o, p)| (p - o).powi(2)).sum::<f64>() / obs.len() as f64).sqrt();
    assert!((mu["rmse"].as_f64().unwrap() - rmse).abs() < 1e-8, "{} vs {rmse}", mu["rmse"]);
}

const BED: &[&str] = &["--pellet", "s.pellet", "--tube-diameter", "40", "--count", "20", "--quiet"];

fn bed_args<'a>(seed: &'a str, out: &'a str) -> Vec<&'a str> {
    let mut a = BED.to_vec();
    a.extend(["--seed", seed, "-o", out]);
    a
}

#[test]
fn mkpellet_pack_settle_check_settle_a_small_sphere_bed_reproducibly() {
    let s = Scenario::new();
    s.run("mkpellet", &["sphere", "--diameter", "10", "-o", "s.pellet"]).success();
    s.run("pack", &bed_args("1", "bed.mcap")).success().stdout_has("settled at");
    let check = s.run("settle-check", &["bed.mcap", "-o", "bed.packing", "--json"]);
    check.success();
    let verdict: serde_json::Value = serde_json::from_str(&check.stdout()).unwrap();
    assert_eq!(verdict["settled"], true);
    assert_eq!(verdict["pellets"], 20);
    // The archive: the expected channels, metadata and attachments.
    let bytes = std::fs::read(s.file("bed.mcap")).unwrap();
    let t = pellet_io::read_trajectory(&bytes, "bed.mcap").unwrap();
    assert!(t.truncated.is_none());
    assert_eq!(t.run["seed"], "1");
    assert!(t.run["config"].contains("\"contact_model\":\"recommended\""), "{}", t.run["config"]);
    assert_eq!(t.pellet_files.len(), 1);
    assert!(!t.frames.is_empty() && !t.energy.is_empty());
    // Every pellet inside the tube and above the floor, penetrating less than 1 % of dp.
    let packing = pellet_io::decode_packing(&std::fs::read(s.file("bed.packing")).unwrap(), "bed").unwrap();
    for p in &packing.bed.pellets {
        let [x, y, z] = p.position;
        assert!(x.hypot(y) <= 0.015 + 1e-4 && z >= 0.005 - 1e-4, "{:?}", p.position);
    }
    let worst = t.energy.iter().map(|e| e.max_penetration_m).fold(0.0, f64::max);
    assert!(worst < 0.01 * 0.010, "max penetration {worst} m");
    // bedexport hands the settled bed on: every pellet's mesh in the STL,
    // and voxels whose porosity agrees with voidprof's exact bulk porosity.
    s.run("bedexport", &["bed.packing", "--stl", "bed.stl", "--voxels", "bed.raw", "--voxels-per-dp", "20"])
        .success()
        .stdout_has("pellets: 20 of 20");
    let faces = packing.bed.pellet_types[0].mesh.face_count();
    assert_eq!(std::fs::metadata(s.file("bed.stl")).unwrap().len() as usize, 84 + 50 * 20 * faces);
    let header: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(s.file("bed.raw.json")).unwrap()).unwrap();
    let z = &header["z_range"];
    let window = format!("{},{}", z[0].as_f64().unwrap(), z[1].as_f64().unwrap());
    s.run("voidprof", &["bed.packing", "--window", &window, "-o", "p.csv", "--summary", "v.json"]).success();
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(s.file("v.json")).unwrap()).unwrap();
    let (voxel, exact) = (header["porosity"].as_f64().unwrap(), v["bulk_porosity"].as_f64().unwrap());
    assert!((voxel - exact).abs() < 0.005, "voxel porosity {voxel} vs voidprof {exact}");
    // The same seed gives the same bytes; another seed another bed.
    let again = Scenario::new();
    std::fs::copy(s.file("s.pellet"), again.file("s.pellet")).unwrap();
    again.run("pack", &bed_args("1", "bed.mcap")).success();
    assert!(std::fs::read(again.file("bed.mcap")).unwrap() == bytes, "same seed, different bytes");
    again.run("pack", &bed_args("2", "other.mcap")).success();
    let other = pellet_io::read_trajectory(&std::fs::read(again.file("other.mcap")).unwrap(), "o").unwrap();
    assert_ne!(other.frames.last().unwrap().positions, t.frames.last().unwrap().positions);
}

#[test]
fn an_interrupted_pack_leaves_a_readable_trajectory() {
    let s = Scenario::new();
    s.run("mkpellet", &["sphere", "--diameter", "10", "-o", "s.pellet"]).success();
    // SIGTERM: pack closes the archive cleanly under its final name.
    let child = std::process::Command::new(pellet_tests::bin("pack"))
        .args(["--pellet", "s.pellet", "--tube-diameter", "40", "--count", "500", "--quiet", "-o", "t.mcap"])
        .current_dir(s.path())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(1500));
    let killed = std::process::Command::new("kill").args(["-TERM", &child.id().to_string()]).status().unwrap();
    assert!(killed.success());
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("interrupted at t ="), "{err}");
    let t = pellet_io::read_trajectory(&std::fs::read(s.file("t.mcap")).unwrap(), "t.mcap").unwrap();
    assert!(t.truncated.is_none() && !t.energy.is_empty());
    // SIGKILL: the .part file stays, readable up to its last complete chunk.
    let mut child = std::process::Command::new(pellet_tests::bin("pack"))
        .args(["--pellet", "s.pellet", "--tube-diameter", "40", "--count", "500", "--quiet", "-o", "k.mcap"])
        .current_dir(s.path())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(1500));
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(!s.file("k.mcap").exists());
    let part = std::fs::read(s.file("k.mcap.part")).unwrap();
    let t = pellet_io::read_trajectory(&part, "k.mcap.part").unwrap();
    assert_eq!(t.pellet_files.len(), 1);
}

#[test]
fn pack_fills_to_a_height() {
    let s = Scenario::new();
    s.run("mkpellet", &["sphere", "--diameter", "10", "-o", "s.pellet"]).success();
    s.run("pack", &["--pellet", "s.pellet", "--tube-diameter", "40", "--fill-height", "18", "--quiet", "-o", "f.mcap"])
        .success();
    s.run("settle-check", &["f.mcap", "--csv", "f.csv"]).success();
    let csv = std::fs::read_to_string(s.file("f.csv")).unwrap();
    let tops: Vec<f64> =
        csv.lines().skip(1).map(|l| l.split(',').nth(3).unwrap().parse::<f64>().unwrap() + 5.0).collect();
    let top = tops.iter().copied().fold(0.0, f64::max);
    // Feeding stops once resting pellets reach 18 mm; those still falling then
    // land on top, so the surface ends at most about one diameter higher.
    assert!((18.0..=18.0 + 12.0).contains(&top), "bed top {top} mm with {} pellets", tops.len());
    assert!(tops.len() >= 4, "{} pellets", tops.len());
}

/// The quick-start block of README.md (the ```sh block after `<!-- quick-start`), as written.
fn readme_quick_start() -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../README.md");
    let readme = std::fs::read_to_string(&path).unwrap();
    let start = readme.find("<!-- quick-start").expect("README.md has no <!-- quick-start --> marker");
    let mut lines = readme[start..].lines().skip(1);
    assert_eq!(lines.next(), Some("```sh"), "the quick-start marker must precede a ```sh block");
    let block: Vec<&str> = lines.take_while(|l| *l != "```").collect();
    assert!(!block.is_empty(), "empty quick-start block");
    block.join("\n") + "\n"
}

/// The README's quick start runs verbatim in an empty directory with the tools on PATH, every
/// command succeeds, and every file its commands name as an output is written.
#[test]
fn the_readme_quick_start_runs_as_written() {
    let block = readme_quick_start();
    let s = Scenario::new();
    let bin_dir = pellet_tests::bin("pack").parent().unwrap().to_path_buf();
    let path = std::env::join_paths(
        std::iter::once(bin_dir).chain(std::env::split_paths(&std::env::var_os("PATH").unwrap_or_default())),
    )
    .unwrap();
    let out = std::process::Command::new("bash")
        .args(["-e", "-u", "-o", "pipefail", "-c", &block])
        .current_dir(s.path())
        .env("PATH", path)
        .stdin(std::process::Stdio::null())
        .output()
        .expect("run bash");
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert_eq!(out.status.code(), Some(0), "quick start failed:\n{block}\nstdout:\n{stdout}\nstderr:\n{stderr}");
    // Every output the block names (-o, --csv, --summary, --plot), and what the README says
    // pack, settle-check and compare write and print.
    let words: Vec<&str> = block.split_whitespace().collect();
    let mut outputs: Vec<String> = words
        .windows(2)
        .filter(|w| ["-o", "--csv", "--summary", "--plot"].contains(&w[0]))
        .map(|w| w[1].to_string())
        .collect();
    assert!(outputs.len() >= 8, "{outputs:?}");
    outputs.extend(["report/scores.csv", "report/scores.json", "report/report.md"].map(String::from));
    for file in &outputs {
        let path = s.file(file);
        assert!(path.exists(), "the quick start did not write {file}");
        assert!(path.is_dir() || std::fs::metadata(&path).unwrap().len() > 0, "{file} is empty");
    }
    assert!(stdout.contains("settled at"), "{stdout}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(s.file("summary.json")).unwrap()).unwrap();
    let porosity = summary["bulk_porosity"].as_f64().unwrap();
    assert!((0.35..0.6).contains(&porosity), "bulk porosity {porosity}");
    assert!(summary["window_rule"].as_str().unwrap().starts_with("default"), "{summary}");
}
