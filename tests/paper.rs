//! The paper's study: `pipelines/paper.mk` and `paper-report` on a few small real beds.
//! The pipeline runs through make with the test profile's binaries, on a
//! table of 10 mm spheres in a 25 mm tube filled to 20 mm; the report's
//! numbers are recomputed here from the beds' own files.

use std::path::{Path, PathBuf};
use std::process::Command;

use pellet_tests::{bin, Scenario};
use serde_json::Value;

/// Small beds: two seeds of one validation tube, two COR values (one seed),
/// rows that are never run (they must be reported missing), and a loading row
/// whose bed is the validation tube's seed 1 (`same_as`).
const TABLE: &str = "\
config,study,shape,tube_diameter_mm,seeds,fill_height_mm,window_z0_mm,window_z1_mm,scheme,cor,friction,position_jitter,angle_jitter,max_time_s,label,same_as,drop_height_mm,release_height_mm
val-sphere-D25,validation,sphere,25,2,20,0,12,one-column,,,,,6,small Table 3 tube
cor-sphere-D25-c0.3,cor,sphere,25,1,20,0,12,one-column,0.3,0.6,0.8,45,6,COR 0.3
cor-sphere-D25-c0.9,cor,sphere,25,1,20,0,12,one-column,0.9,0.6,0.8,45,6,COR 0.9
mu-sphere-D25-m0.3,friction,sphere,25,2,20,0,12,one-column,0.6,0.3,0.8,45,6,never run
load-sphere-D25-two-columns,loading,sphere,25,1,20,0,12,two-columns,,,,,6,never run,,,40
load-sphere-D25-one-column,loading,sphere,25,1,20,0,12,one-column,,,,,6,scheme 1,val-sphere-D25
load-sphere-D25-drop200,loading,sphere,25,1,20,0,12,one-column,,,,,6,never run,,200
";

fn make(s: &Scenario, targets: &[&str]) -> std::process::Output {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("workspace root").to_path_buf();
    let bin_dir = bin("pack").parent().expect("binary directory").to_path_buf();
    Command::new("make")
        .arg("-f")
        .arg(root.join("pipelines/paper.mk"))
        .arg(format!("BIN={}", bin_dir.display()))
        .args(["OUT=out", "DOCS=docs", "TABLE=beds.csv", "NICE="])
        .args(targets)
        .current_dir(s.path())
        .output()
        .expect("run make (is GNU make installed?)")
}

fn json(path: PathBuf) -> Value {
    serde_json::from_str(&std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display())))
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Dixon (1988) for spheres, x = 1/N, written out again from the refdata
/// description (not the library's code).
fn dixon_spheres(n: f64) -> f64 {
    let x = 1.0 / n;
    if x <= 0.5 {
        0.4 + 0.05 * x + 0.412 * x * x
    } else if x <= 0.536 {
        0.528 + 2.464 * (x - 0.5)
    } else {
        1.0 - 0.667 * x.powi(3) * (2.0 * x - 1.0).powf(-0.5)
    }
}

/// The wall seconds a `timed.sh` file records (its first field).
fn recorded_seconds(path: &Path) -> f64 {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    text.split_whitespace().next().and_then(|t| t.parse().ok()).unwrap_or_else(|| panic!("{}: {text}", path.display()))
}

/// A scenario whose `beds.csv` is the table header and `row`.
fn one_row_table(row: &str) -> Scenario {
    let s = Scenario::new();
    let header = TABLE.lines().next().expect("the table's header");
    std::fs::write(s.file("beds.csv"), format!("{header}\n{row}\n")).unwrap();
    s
}

fn keys(v: &Value) -> Vec<String> {
    let mut k: Vec<String> = v.as_object().expect("object").keys().cloned().collect();
    k.sort();
    k
}

#[test]
fn paper_pipeline_and_report_on_small_beds() {
    let s = Scenario::new();
    std::fs::write(s.file("beds.csv"), TABLE).unwrap();
    let out = make(&s, &["validation", "cor", "report"]);
    let log = format!("{}\n{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "make failed:\n{log}");

    // The report names exactly the beds that were not run.
    let page = std::fs::read_to_string(s.file("docs/README.md")).unwrap();
    for id in [
        "mu-sphere-D25-m0.3-s1",
        "mu-sphere-D25-m0.3-s2",
        "load-sphere-D25-two-columns-s1",
        "load-sphere-D25-drop200-s1",
    ] {
        assert!(page.contains(id), "{id} not listed as missing:\n{page}");
    }
    // The same_as row is the validation bed's seed 1, counted once.
    assert!(page.contains("Beds finished: 4 of 8"), "{page}");
    // Every finished bed's trajectory names the build of the pack that ran it (this one's).
    let builds = page.lines().find(|l| l.starts_with("- Engine builds")).unwrap_or_else(|| panic!("{page}"));
    assert!(builds.ends_with("`: 4.") && (builds.contains("`git ") || builds.contains("`unknown")), "{builds}");
    // The progress table: rows pooled per study and tube, the same_as row left to the bed it names.
    for line in [
        "| validation | sphere | 25 | 2 of 2 | ",
        "| cor | sphere | 25 | 2 of 2 | ",
        "| friction | sphere | 25 | 0 of 2 | — | 0 | no finished bed to go by | — |",
        "| loading | sphere | 25 | 0 of 2 | — | 0 | no finished bed to go by | — |",
    ] {
        assert!(page.contains(line), "no progress line {line}:\n{page}");
    }
    // A row's drop and release heights reach its case file; rows without them keep pack's
    // defaults.
    let cases = ["out/cases/load-sphere-D25-drop200-s1.toml", "out/cases/load-sphere-D25-two-columns-s1.toml"];
    let case = make(&s, &cases);
    assert!(case.status.success(), "{}", String::from_utf8_lossy(&case.stderr));
    let dropped = std::fs::read_to_string(s.file(cases[0])).unwrap();
    assert!(dropped.contains("\ndrop-height = 200\n") && !dropped.contains("release-height"), "{dropped}");
    let poured = std::fs::read_to_string(s.file(cases[1])).unwrap();
    assert!(poured.contains("\nrelease-height = 40\n") && !poured.contains("drop-height"), "{poured}");
    let val = std::fs::read_to_string(s.file("out/cases/val-sphere-D25-s1.toml")).unwrap();
    assert!(!val.contains("drop-height") && !val.contains("release-height"), "{val}");
    let scheme1 = page.lines().find(|l| l.starts_with("| load-sphere-D25-one-column (the beds of val-sphere-D25)"));
    let v1 = json(s.file("out/runs/val-sphere-D25-s1.summary.json"))["bulk_porosity"].as_f64().unwrap();
    // One bed: its value, with no spread.
    assert!(
        scheme1.is_some_and(|l| l.contains(&format!("| 1 | {v1:.4} |")) && !l.contains('±')),
        "{scheme1:?} {v1}\n{page}"
    );
    assert!(!page.contains("val-sphere-D25-s1,") && !page.contains("cor-sphere-D25-c0.3-s1,"), "{page}");

    // summary.json: exactly the schema paper-report documents.
    let sum = json(s.file("docs/summary.json"));
    assert_eq!(keys(&sum), ["compute_seconds", "machine", "profiles", "shapes"]);
    assert_eq!(keys(&sum["shapes"]), ["cylinder", "ring", "sphere"]);
    for shape in ["cylinder", "ring"] {
        assert_eq!(sum["shapes"][shape]["mre_dixon"], Value::Null);
        assert_eq!(sum["shapes"][shape]["beds"].as_array().unwrap().len(), 0);
    }
    let sphere = &sum["shapes"]["sphere"];
    assert_eq!(keys(sphere), ["beds", "mre_dixon"]);
    let beds = sphere["beds"].as_array().unwrap();
    assert_eq!(beds.len(), 1, "only the validation tube counts: {beds:?}");
    let bed = &beds[0];
    assert_eq!(keys(bed), ["N", "N_dpv", "dixon", "porosity_mean", "porosity_seeds", "tube_diameter_mm"]);

    // The values, recomputed from voidprof's per-bed summaries.
    let seeds: Vec<f64> = (1..=2)
        .map(|k| json(s.file(&format!("out/runs/val-sphere-D25-s{k}.summary.json")))["bulk_porosity"].as_f64().unwrap())
        .collect();
    let reported: Vec<f64> = bed["porosity_seeds"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    assert_eq!(reported, seeds);
    let mean = (seeds[0] + seeds[1]) / 2.0;
    assert!((bed["porosity_mean"].as_f64().unwrap() - mean).abs() < 1e-12);
    let n = bed["N"].as_f64().unwrap();
    assert!((n - 2.5).abs() < 1e-9, "N = D/dp = 25/10, got {n}");
    let dixon = dixon_spheres(n);
    assert!((bed["dixon"].as_f64().unwrap() - dixon).abs() < 1e-9);
    let mre = ((mean - dixon) / dixon).abs();
    assert!((sphere["mre_dixon"].as_f64().unwrap() - mre).abs() < 1e-12, "MRE {mre}");
    let row = format!("{:.1} % (1 of 1 tubes)", 100.0 * mre);
    assert!(page.contains(&row), "the page lacks the MRE {row}:\n{page}");

    // Compute time: the sum of the recorded stage times of the finished beds.
    let mut seconds = 0.0;
    for id in ["val-sphere-D25-s1", "val-sphere-D25-s2", "cor-sphere-D25-c0.3-s1", "cor-sphere-D25-c0.9-s1"] {
        for stage in ["pack", "settle", "voidprof"] {
            seconds += recorded_seconds(&s.file(&format!("out/runs/{id}.{stage}.time")));
        }
    }
    let reported = sum["compute_seconds"].as_f64().unwrap();
    assert!(seconds > 0.0 && (reported - seconds).abs() < 1e-6, "{reported} vs {seconds}");
    assert!(!sum["machine"].as_str().unwrap().is_empty());

    // Profiles: the sphere tube against de Klerk and Mueller, sane scores.
    let profiles = sum["profiles"].as_array().unwrap();
    let refs: Vec<&str> = profiles.iter().map(|p| p["reference"].as_str().unwrap()).collect();
    assert_eq!(refs, ["de-klerk-2003", "mueller-1992"]);
    for p in profiles {
        assert_eq!(keys(p), ["N", "r2", "reference", "rmse", "shape"]);
        assert_eq!(p["shape"], "sphere");
        let rmse = p["rmse"].as_f64().unwrap();
        assert!(rmse > 0.0 && rmse < 1.0, "{p}");
        assert!(p["r2"].as_f64().is_none_or(|r2| r2 <= 1.0), "{p}");
    }

    // Settled poses of the validation beds only, byte for byte.
    for k in 1..=2 {
        let copied = std::fs::read(s.file(&format!("docs/beds/val-sphere-D25-s{k}.csv"))).unwrap();
        assert_eq!(copied, std::fs::read(s.file(&format!("out/runs/val-sphere-D25-s{k}.poses.csv"))).unwrap());
    }
    assert!(!s.file("docs/beds/cor-sphere-D25-c0.3-s1.csv").exists());

    // Figures, as PNG.
    for png in ["porosity_vs_n_sphere.png", "profile_val-sphere-D25.png", "porosity_vs_cor.png"] {
        let bytes = std::fs::read(s.file(&format!("docs/{png}"))).unwrap_or_else(|e| panic!("{png}: {e}"));
        assert!(bytes.starts_with(b"\x89PNG"), "{png} is not a PNG");
        assert!(page.contains(png), "the page does not show {png}");
    }

    // Files are the targets: a second run has nothing to do.
    let again = make(&s, &["-q", "validation", "cor"]);
    assert!(again.status.success(), "make -q says beds are out of date");

    // The archive keeps each bed's record byte for byte (the poses only of
    // beds the report does not keep in beds/), so without out/ nothing is
    // re-run and the report comes out the same.
    for id in ["val-sphere-D25-s1", "val-sphere-D25-s2", "cor-sphere-D25-c0.3-s1", "cor-sphere-D25-c0.9-s1"] {
        for file in ["summary.json", "profile.csv", "settle.json", "pack.time", "settle.time", "voidprof.time"] {
            let kept =
                std::fs::read(s.file(&format!("docs/runs/{id}.{file}"))).unwrap_or_else(|e| panic!("{id}.{file}: {e}"));
            assert_eq!(kept, std::fs::read(s.file(&format!("out/runs/{id}.{file}"))).unwrap(), "{id}.{file}");
        }
        assert_eq!(s.file(&format!("docs/runs/{id}.poses.csv")).exists(), id.starts_with("cor-"), "{id}.poses.csv");
    }
    let before = std::fs::read(s.file("docs/summary.json")).unwrap();
    let beds_before = std::fs::read(s.file("docs/beds/val-sphere-D25-s1.csv")).unwrap();
    std::fs::remove_dir_all(s.file("out")).unwrap();
    let again = make(&s, &["-q", "validation", "cor"]);
    assert!(again.status.success(), "without out/, make -q says archived beds are out of date");
    let report = make(&s, &["report"]);
    assert!(report.status.success(), "report from the archive alone: {}", String::from_utf8_lossy(&report.stderr));
    assert_eq!(std::fs::read(s.file("docs/summary.json")).unwrap(), before, "summary.json changed");
    assert_eq!(std::fs::read(s.file("docs/beds/val-sphere-D25-s1.csv")).unwrap(), beds_before);
    assert!(std::fs::read_to_string(s.file("docs/README.md")).unwrap().contains("Beds finished: 4 of 8"));

    // --repeats 1 counts seed 1 only.
    s.run("paper-report", &["--table", "beds.csv", "--runs", "docs/runs", "--repeats", "1", "-o", "r1"]).success();
    let r1 = json(s.file("r1/summary.json"));
    assert_eq!(r1["shapes"]["sphere"]["beds"][0]["porosity_seeds"].as_array().unwrap().len(), 1);

    // Bad input: one line, exit 2.
    std::fs::write(s.file("bad.csv"), "config,study\nx,validation\n").unwrap();
    s.run("paper-report", &["--table", "bad.csv", "--runs", "docs/runs", "-o", "r2"]).fails_with("lacks the column");
    s.run("paper-report", &["--table", "beds.csv", "--runs", "docs/runs", "--runs", "nowhere", "-o", "r2"])
        .fails_with("--runs nowhere: not a directory");
}

/// A bed whose make is interrupted (SIGTERM to make and everything under it, as when a machine
/// or its time slot stops) is continued by the next make from pack's checkpoint: the trajectory
/// equals an uninterrupted run's, and pack.time adds up both legs.
#[test]
fn an_interrupted_paper_bed_is_resumed_by_the_next_make() {
    use std::os::unix::process::CommandExt;
    let s = one_row_table("val-sphere-D25,validation,sphere,25,1,120,0,40,one-column,,,,,8,taller tube");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("workspace root").to_path_buf();
    let bin_dir = bin("pack").parent().expect("binary directory").to_path_buf();
    let id = "val-sphere-D25-s1";
    let mut child = Command::new("make")
        .arg("-f")
        .arg(root.join("pipelines/paper.mk"))
        .arg(format!("BIN={}", bin_dir.display()))
        .args(["OUT=out", "DOCS=docs", "TABLE=beds.csv", "NICE="])
        .arg(format!("out/runs/{id}.mcap"))
        .current_dir(s.path())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .process_group(0)
        .spawn()
        .expect("run make");
    // Once pack is writing, stop the whole group.
    let part = s.file(&format!("out/runs/{id}.run.mcap.part"));
    let start = std::time::Instant::now();
    while !part.exists() && start.elapsed().as_secs() < 60 {
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    std::thread::sleep(std::time::Duration::from_millis(300));
    let group = format!("-{}", child.id());
    assert!(Command::new("kill").args(["-TERM", "--", &group]).status().unwrap().success());
    assert!(!child.wait().unwrap().success(), "the interrupted make must fail");
    // pack finishes its step and closes the run; timed.sh then records the leg.
    let time_file = s.file(&format!("out/runs/{id}.pack.time"));
    let start = std::time::Instant::now();
    while !time_file.exists() && start.elapsed().as_secs() < 60 {
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let first_leg = recorded_seconds(&time_file);
    let interrupted =
        pellet_io::read_trajectory(&std::fs::read(s.file(&format!("out/runs/{id}.run.mcap"))).unwrap(), "i")
            .expect("pack closed the interrupted run");
    let t_stop = interrupted.frames.last().unwrap().time_s;
    assert!(interrupted.checkpoint.is_some());

    let out = make(&s, &[&format!("out/runs/{id}.mcap")]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let total = recorded_seconds(&s.file(&format!("out/runs/{id}.pack.time")));
    assert!(total > first_leg, "pack.time {total} s must add the first leg's {first_leg} s");
    s.run("pack", &["--case", &format!("out/cases/{id}.toml"), "-o", "straight.mcap", "--quiet"]);
    let read = |name: &str| pellet_io::read_trajectory(&std::fs::read(s.file(name)).unwrap(), name).unwrap();
    let (resumed, straight) = (read(&format!("out/runs/{id}.mcap")), read("straight.mcap"));
    assert!(resumed.frames.last().unwrap().time_s > t_stop, "the run went on after t = {t_stop}");
    assert_eq!(resumed.frames, straight.frames);
    assert_eq!(resumed.energy, straight.energy);
}

/// A bed stopped in one clone is parked (`make park`: a small copy of its checkpoint, with its
/// pack time, under the committed docs) and finished by the next make in a clone without `out/`:
/// its trajectory after the parked frame equals an uninterrupted run's, pack.time adds up both
/// legs, and the parked files are gone once the bed's record is written.
#[test]
fn a_parked_paper_bed_is_finished_by_the_next_make_elsewhere() {
    let s = one_row_table("val-sphere-D25,validation,sphere,25,1,20,0,12,one-column,,,,,6,small tube");
    let id = "val-sphere-D25-s1";
    let case = format!("out/cases/{id}.toml");
    let pellets = ["out/sphere.pellet", "out/cylinder.pellet", "out/ring.pellet"];
    let out = make(&s, &[&[case.as_str()][..], &pellets[..]].concat());
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    // The first leg, stopped at 0.4 s, as the recipe's pack and timed.sh leave it.
    let run = format!("out/runs/{id}.run.mcap");
    std::fs::create_dir_all(s.file("out/runs")).unwrap();
    s.run("pack", &["--case", &case, "-o", &run, "--quiet", "--max-time", "0.4"]);
    std::fs::write(s.file(&format!("out/runs/{id}.pack.time")), "1.500 2\n").unwrap();

    let out = make(&s, &["park"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let parked = s.file(&format!("docs/parked/{id}.run.mcap"));
    let read = |p: &Path| pellet_io::read_trajectory(&std::fs::read(p).unwrap(), "t").unwrap();
    let kept = read(&parked).frames;
    assert_eq!(kept.len(), 1);
    assert!(std::fs::metadata(&parked).unwrap().len() < std::fs::metadata(s.file(&run)).unwrap().len());
    assert_eq!(std::fs::read_to_string(s.file(&format!("docs/parked/{id}.pack.time"))).unwrap(), "1.500 2\n");
    // The report lists the bed as missing and parked (no bed has a record yet).
    std::fs::create_dir_all(s.file("docs/runs")).unwrap();
    let out = make(&s, &["report"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let page = std::fs::read_to_string(s.file("docs/README.md")).unwrap();
    let parked_line = page.lines().find(|l| l.starts_with("- Parked partial runs")).unwrap_or_else(|| panic!("{page}"));
    assert!(parked_line.ends_with(&format!(": {id}.")), "{parked_line}");

    // Another clone: no out/, the committed docs only.
    std::fs::remove_dir_all(s.file("out")).unwrap();
    let out = make(&s, &[&format!("docs/runs/{id}.summary.json")]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(!parked.exists() && !s.file(&format!("docs/parked/{id}.pack.time")).exists());
    assert!(make(&s, &["report"]).status.success());
    assert!(!std::fs::read_to_string(s.file("docs/README.md")).unwrap().contains("Parked partial runs"));
    let total = recorded_seconds(&s.file(&format!("docs/runs/{id}.pack.time")));
    assert!(total > 1.5, "pack.time {total} s must add the parked leg's 1.5 s");
    s.run("pack", &["--case", &case, "-o", "straight.mcap", "--quiet"]);
    let (resumed, straight) = (read(&s.file(&format!("out/runs/{id}.mcap"))), read(&s.file("straight.mcap")));
    let after: Vec<_> = straight.frames.iter().filter(|f| f.time_s >= kept[0].time_s).cloned().collect();
    assert!(resumed.frames == after, "the finished bed's frames differ from an uninterrupted run's");
    assert!(resumed.energy == straight.energy, "the finished bed's energy records differ");
    assert!(resumed.run["build"].starts_with(&straight.run["build"]), "{}", resumed.run["build"]);
}

/// `STEPPER=acceleration` writes the stepper into every bed's case file, so the beds are the
/// paper's force-level formulation's; without it the case files name none (pack's default).
#[test]
fn the_paper_study_runs_with_the_stepper_it_is_given() {
    let s = one_row_table("val-sphere-D25,validation,sphere,25,1,20,0,12,one-column,,,,,6,small tube");
    let case = "out/cases/val-sphere-D25-s1.toml";
    let out = make(&s, &[case, "out/sphere.pellet"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let default = std::fs::read_to_string(s.file(case)).unwrap();
    assert!(!default.contains("stepper"), "{default}");
    let out = make(&s, &[case, "STEPPER=acceleration"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let chosen = std::fs::read_to_string(s.file(case)).unwrap();
    assert!(chosen.starts_with(&default) && chosen.ends_with("stepper = \"acceleration\"\n"), "{chosen}");
    // pack reads it: the run's recorded configuration names the stepper.
    let run = s.file("bed.mcap");
    s.run("pack", &["--case", case, "-o", run.to_str().unwrap(), "--quiet", "--max-time", "0.05"]);
    let traj = pellet_io::read_trajectory(&std::fs::read(&run).unwrap(), "bed.mcap").unwrap();
    let config: Value = serde_json::from_str(traj.run.get("config").expect("the run's configuration")).unwrap();
    assert_eq!(config["stepper"], "acceleration", "{config}");
}
