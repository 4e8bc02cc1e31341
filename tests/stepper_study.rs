//! The steppers' equivalence study: `pipelines/stepper-study.mk` as a dry run (which beds it
//! would pack, and how), and its report on made-up records whose numbers are worked out here.

use std::path::{Path, PathBuf};
use std::process::Command;

use pellet_tests::{bin, Scenario};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("workspace root").to_path_buf()
}

/// `make -n` of the study's beds in a scratch directory, with the given variables.
fn dry_run(s: &Scenario, vars: &[&str]) -> String {
    let bin_dir = bin("pack").parent().expect("binary directory").to_path_buf();
    let out = Command::new("make")
        .arg("-n")
        .arg("-f")
        .arg(root().join("pipelines/stepper-study.mk"))
        .arg(format!("BIN={}", bin_dir.display()))
        .args(["OUT=out", "DOCS=docs"])
        .args(vars)
        .arg("beds")
        .current_dir(s.path())
        .output()
        .expect("run make (is GNU make installed?)");
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(out.status.success(), "make -n failed:\n{stdout}\n{}", String::from_utf8_lossy(&out.stderr));
    stdout
}

/// The beds whose `pack` a dry run would start, in order.
fn packed(plan: &str) -> Vec<String> {
    plan.lines()
        .filter(|l| l.contains("/pack --case"))
        .map(|l| {
            let case = l.split("--case ").nth(1).expect("a case file").split_whitespace().next().unwrap();
            case.trim_start_matches("out/cases/").trim_end_matches(".toml").to_string()
        })
        .collect()
}

#[test]
fn stepper_study_dry_run_packs_the_chosen_beds_with_the_velocity_stepper() {
    let s = Scenario::new();
    let plan = dry_run(&s, &["SEEDS=2", "TUBES=val-sphere-D41 val-cylinder-D35.49", "SPHERE690_SEEDS=1"]);
    assert_eq!(
        packed(&plan),
        [
            "val-sphere-D41-s1",
            "val-sphere-D41-s2",
            "val-cylinder-D35.49-s1",
            "val-cylinder-D35.49-s2",
            "sph690-batch-s1"
        ]
    );
    // Every stage runs niced; the case files come from the paper's table with the stepper
    // added, or from the study's own table; the records go to docs/stepper-study.
    assert!(plan
        .lines()
        .filter(|l| l.contains("/pack --case"))
        .all(|l| l.contains(" nice ") && l.contains("--resume")));
    assert!(plan.contains("pipelines/paper/case.awk") && plan.contains("stepper = \"velocity\""), "{plan}");
    assert!(plan.contains("pipelines/stepper-study/case.awk"), "{plan}");
    assert!(plan.contains("docs/stepper-study/sph690-batch-s1.summary.json"), "{plan}");

    // The default: the nine validation tubes × 6 seeds and 20 seeds of the 690-sphere bed.
    let all = packed(&dry_run(&s, &[]));
    assert_eq!(all.len(), 9 * 6 + 20, "{all:?}");
    assert!(all.iter().any(|id| id.starts_with("val-sphere-D31")));
    assert!(all.iter().all(|id| !id.starts_with("val-sphere-D39.6")));
    // SPHERE690_SEEDS empty: none of that bed.
    assert!(packed(&dry_run(&s, &["SEEDS=1", "SPHERE690_SEEDS="])).iter().all(|id| !id.starts_with("sph690")));

    // A bed with a record is not run again, even without its run directory.
    std::fs::create_dir_all(s.file("docs/stepper-study")).unwrap();
    std::fs::write(s.file("docs/stepper-study/val-sphere-D41-s1.summary.json"), "{}").unwrap();
    let again = packed(&dry_run(&s, &["SEEDS=2", "TUBES=val-sphere-D41", "SPHERE690_SEEDS="]));
    assert_eq!(again, ["val-sphere-D41-s2"]);
}

/// pack's default of a flag, from its `--help` ("[default: 0.0125; ...").
fn pack_default(flag: &str) -> f64 {
    let help = Command::new(bin("pack")).arg("--help").output().expect("run pack --help");
    let help = String::from_utf8_lossy(&help.stdout).replace('\n', " ");
    let after = help.split(&format!("--{flag} <")).nth(1).unwrap_or_else(|| panic!("--{flag} in {help}"));
    let value = after.split("[default: ").nth(1).expect("a default").split(';').next().unwrap();
    value.parse().unwrap_or_else(|e| panic!("--{flag} default {value}: {e}"))
}

#[test]
fn stepper_study_arms_pack_the_failing_tubes_at_a_smaller_step() {
    let s = Scenario::new();
    // The force-level stepper at a quarter of its substep, by default the configurations whose
    // porosities differed, no 690-sphere beds; runs and records in the arm's own directories.
    let plan = dry_run(&s, &["ARM=force-quarter", "SEEDS=2"]);
    let ids: Vec<String> = plan
        .lines()
        .filter(|l| l.contains("/pack --case"))
        .map(|l| l.split("--case out/force-quarter/cases/").nth(1).expect("the arm's case").to_string())
        .map(|rest| rest.split(".toml").next().unwrap().to_string())
        .collect();
    assert_eq!(ids, ["val-sphere-D61-s1", "val-sphere-D61-s2", "val-ring-D40.45-s1", "val-ring-D40.45-s2"]);
    assert!(plan.contains("'stepper = \"acceleration\"\\nsubstep-scale = 0.25'"), "{plan}");
    assert!(plan.contains("docs/stepper-study/force-quarter/val-ring-D40.45-s2.summary.json"), "{plan}");
    assert!(!plan.contains("stepper = \"velocity\""), "{plan}");

    // The velocity-level stepper at half of pack's own default step.
    let plan = dry_run(&s, &["ARM=velocity-half", "SEEDS=1", "TUBES=val-ring-D60.18"]);
    let keys = format!(
        "'stepper = \"velocity\"\\nstep-travel = {}\\nmax-step = {}'",
        pack_default("step-travel") / 2.0,
        pack_default("max-step") / 2.0
    );
    assert!(plan.contains(&keys), "{keys} not in\n{plan}");
    assert!(plan.contains("--case out/velocity-half/cases/val-ring-D60.18-s1.toml"), "{plan}");
    assert!(plan.contains("docs/stepper-study/velocity-half/val-ring-D60.18-s1.summary.json"), "{plan}");

    // An arm that does not exist is an error that names the arms that do.
    let out = Command::new("make")
        .args(["-n", "-f"])
        .arg(root().join("pipelines/stepper-study.mk"))
        .args(["ARM=eighth", "beds"])
        .current_dir(s.path())
        .output()
        .expect("run make");
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("ARM=eighth: unknown arm; use velocity-half or force-quarter"), "{err}");
}

/// A record: a summary with the bed's bulk porosity and a two-point profile.
fn record(dir: &Path, id: &str, porosity: f64, profile: [f64; 2], pack_s: f64) {
    std::fs::create_dir_all(dir).unwrap();
    std::fs::write(dir.join(format!("{id}.summary.json")), format!("{{\"bulk_porosity\": {porosity}}}")).unwrap();
    std::fs::write(
        dir.join(format!("{id}.profile.csv")),
        format!(
            "r_mm,wall_distance_mm,wall_distance_dp,wall_distance_dpv,void_fraction\n20,0.5,0.05,0.05,{}\n15,5.5,0.55,0.55,{}\n",
            profile[0], profile[1]
        ),
    )
    .unwrap();
    std::fs::write(dir.join(format!("{id}.settle.json")), "{\"settled\": true, \"build\": \"abc\"}").unwrap();
    std::fs::write(dir.join(format!("{id}.pack.time")), format!("{pack_s} 0\n")).unwrap();
}

/// The report on the records in `v` (velocity) and `f` (force-level) of the scenario, with
/// `args` (options, then configurations) added; its text.
fn report(s: &Scenario, args: &[&str]) -> String {
    let out = Command::new("python3")
        .arg(root().join("pipelines/stepper-study/report.py"))
        .arg("--table")
        .arg(root().join("pipelines/paper/beds.csv"))
        .arg("--study-table")
        .arg(root().join("pipelines/stepper-study/beds.csv"))
        .args(["--velocity", "v", "--reference", "f", "-o", "report.md"])
        .args(args)
        .current_dir(s.path())
        .output()
        .expect("run python3");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    std::fs::read_to_string(s.file("report.md")).unwrap()
}

#[test]
fn stepper_study_report_compares_the_means_and_profiles() {
    let s = Scenario::new();
    let (v, f) = (s.file("v"), s.file("f"));
    // Spheres D = 41 mm: velocity 0.44, 0.46 (mean 0.45, s.e. 0.01), force-level 0.45, 0.47, 0.49
    // (mean 0.47, s.e. 0.02/√3 = 0.011547): difference −0.02 in √(0.01² + 0.011547²) =
    // 0.015275, −1.31 s.e.: pass. Profiles: means (0.9, 0.3) and (0.9, 0.36): RMSE 0.06/√2 =
    // 0.0424: fail. The seeds' scatter: squares 2 · 0.01² over 2 points and 2 + 3 − 2 degrees
    // of freedom, times 1/2 + 1/3: √(0.0001 / 3 · 5/6) = 0.0053.
    record(&v, "val-sphere-D41-s1", 0.44, [0.9, 0.3], 10.0);
    record(&v, "val-sphere-D41-s2", 0.46, [0.9, 0.3], 20.0);
    record(&f, "val-sphere-D41-s1", 0.45, [0.9, 0.35], 100.0);
    record(&f, "val-sphere-D41-s2", 0.47, [0.9, 0.36], 100.0);
    record(&f, "val-sphere-D41-s3", 0.49, [0.9, 0.37], 100.0);
    // Cylinders D = 35.49 mm: velocity 0.50, 0.54 (s.e. 0.02) against 0.45, 0.45 (s.e. 0):
    // +0.07 in 0.02, +3.5 s.e.: fail; equal profiles.
    record(&v, "val-cylinder-D35.49-s1", 0.50, [1.0, 0.4], 5.0);
    record(&v, "val-cylinder-D35.49-s2", 0.54, [1.0, 0.4], 5.0);
    record(&f, "val-cylinder-D35.49-s1", 0.45, [1.0, 0.4], 50.0);
    record(&f, "val-cylinder-D35.49-s2", 0.45, [1.0, 0.4], 50.0);
    // The 690-sphere bed: one bed against the study table's reference.
    record(&v, "sph690-batch-s1", 0.43, [1.0, 0.4], 3.0);

    let report = report(&s, &["val-sphere-D41", "val-cylinder-D35.49", "val-ring-D40.45", "sph690-batch"]);
    let row = |config: &str| -> String {
        report
            .lines()
            .find(|l| l.starts_with(&format!("| `{config}`")))
            .unwrap_or_else(|| panic!("{report}"))
            .to_string()
    };
    let sphere = row("val-sphere-D41");
    assert!(sphere.contains("spheres, N = 4.1 (D = 41 mm)"), "{sphere}");
    assert!(sphere.contains("| 0.4500 ± 0.0100 (2) | 0.4700 ± 0.0115 (3) | -0.0200 (-1.31) | pass |"), "{sphere}");
    assert!(sphere.contains("| 0.0424 (0.0053) | **fail** | 15 / 100 |"), "{sphere}");
    let cylinder = row("val-cylinder-D35.49");
    assert!(cylinder.contains("cylinders, N = 3.55"), "{cylinder}");
    assert!(cylinder.contains("| +0.0700 (+3.50) | **fail** | 0.0000 (0.0000) | pass |"), "{cylinder}");
    let ring = row("val-ring-D40.45");
    assert!(ring.contains("rings, N = 4.05") && ring.contains("| — | — | — | — | — |"), "{ring}");
    let batch = row("sph690-batch");
    assert!(batch.contains("| 0.4300 (1) | 0.4291 ± 0.0005 (20; docs/engine.md) | +0.0009 | — (n < 2) |"), "{batch}");
    assert!(
        report.contains("**2 of 2 compared configurations fail:** val-sphere-D41, val-cylinder-D35.49."),
        "{report}"
    );
    assert!(!report.contains("## Step halving"), "{report}");
}

#[test]
fn stepper_study_report_decides_a_failing_configuration_by_step_halving() {
    let s = Scenario::new();
    let (v, f, half, quarter) = (s.file("v"), s.file("f"), s.file("half"), s.file("quarter"));
    // Cylinders D = 35.49 mm: velocity 0.50, 0.54 (mean 0.52, s.e. 0.02) against force-level
    // 0.45, 0.45: +3.5 s.e., fail. At a quarter of the substep the force-level beds are 0.49,
    // 0.51 (mean 0.50, s.e. 0.01): −0.02 in √(0.02² + 0.01²) = 0.02236, −0.89 s.e.; at half the
    // step the velocity beds are 0.51, 0.53 (mean 0.52): +0.00. Passes by step halving.
    // Spheres D = 41 mm: velocity 0.44, 0.46 (s.e. 0.01) against 0.40, 0.40: +5.0 s.e., fail;
    // the force-level beds at a quarter of the substep, 0.40 and 0.42 (mean 0.41, s.e. 0.01),
    // still differ by −0.04 in 0.01414, −2.83 s.e.: not decided, still a fail.
    let beds = [
        (&v, "val-cylinder-D35.49", [0.50, 0.54]),
        (&f, "val-cylinder-D35.49", [0.45, 0.45]),
        (&quarter, "val-cylinder-D35.49", [0.49, 0.51]),
        (&half, "val-cylinder-D35.49", [0.51, 0.53]),
        (&v, "val-sphere-D41", [0.44, 0.46]),
        (&f, "val-sphere-D41", [0.40, 0.40]),
        (&quarter, "val-sphere-D41", [0.40, 0.42]),
    ];
    for (dir, config, porosities) in beds {
        for (seed, e) in porosities.into_iter().enumerate() {
            record(dir, &format!("{config}-s{}", seed + 1), e, [1.0, 0.4], 5.0);
        }
    }
    let report =
        report(&s, &["--velocity-half", "half", "--force-quarter", "quarter", "val-cylinder-D35.49", "val-sphere-D41"]);
    let rows: Vec<&str> = report.lines().filter(|l| l.starts_with("| `val-cylinder-D35.49`")).collect();
    assert_eq!(rows.len(), 2, "{report}");
    assert!(rows[0].contains("| +0.0700 (+3.50) | pass (step halving) |"), "{}", rows[0]);
    assert!(
        rows[1].contains("| 0.5200 ± 0.0200 (2) | 0.5200 ± 0.0100 (2) (+0.00) | 0.4500 ± 0.0000 (2) (-3.50) | 0.5000 ± 0.0100 (2) (-0.89) | 0.0000 |"),
        "{}",
        rows[1]
    );
    assert!(rows[1].contains("porosity: the force-level beds come to the velocity-level ones"), "{}", rows[1]);
    let sphere: Vec<&str> = report.lines().filter(|l| l.starts_with("| `val-sphere-D41`")).collect();
    assert!(sphere[0].contains("| +0.0500 (+5.00) | **fail** |"), "{}", sphere[0]);
    assert!(sphere[1].contains("(-2.83)") && sphere[1].contains("porosity: not decided"), "{}", sphere[1]);
    assert!(report.contains("**1 of 2 compared configurations fail:** val-sphere-D41."), "{report}");
    assert!(report.contains("Decided by the step halving (below): val-cylinder-D35.49."), "{report}");
}
