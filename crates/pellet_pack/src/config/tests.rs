use super::*;

fn base() -> PackOptions {
    PackOptions { pellet: Some("c.pellet".into()), tube_diameter: Some(69.83), count: Some(40), ..Default::default() }
}

#[test]
fn times_between_engine_steps_are_refused_with_the_nearest_allowed() {
    let resolve = |record_every: f64, max_time: f64| {
        PackConfig::resolve(&PackOptions { record_every: Some(record_every), max_time: Some(max_time), ..base() })
    };
    let e = resolve(0.001, 1.0).unwrap_err().0;
    assert!(
        e.contains("--record-every must be a whole number of the 0.005 s engine steps") && e.ends_with("give 0.005"),
        "{e}"
    );
    let e = resolve(0.012, 1.0).unwrap_err().0;
    assert!(e.ends_with("give 0.01 or 0.015"), "{e}");
    let e = resolve(0.01, 0.001).unwrap_err().0;
    assert!(e.starts_with("--max-time") && e.ends_with("give 0.005"), "{e}");
    let c = resolve(0.015, 0.3).unwrap();
    assert_eq!((c.record_every_s, c.max_time_s), (0.015, 0.3));
}

#[test]
fn defaults_are_the_papers_validation_values() {
    let c = PackConfig::resolve(&base()).unwrap();
    assert_eq!((c.density_kg_m3, c.cor, c.friction, c.wall_cor, c.wall_friction), (8030.0, 0.9, 0.1, 0.6, 0.6));
    assert!((c.tube_diameter_m - 0.06983).abs() < 1e-15);
    assert_eq!(c.scheme, LoadingScheme::OneColumn);
    assert!((c.tilt_rad.to_degrees() - 45.0).abs() < 1e-12);
}

#[test]
fn case_file_paths_are_relative_to_the_case_file() {
    let text = "pellet = \"../s.pellet\"\noutput = \"bed.mcap\"\n";
    let o = PackOptions::from_case_file(text, "out/cases/a.toml").unwrap().relative_to_case_file("out/cases/a.toml");
    assert_eq!(o.pellet.as_deref(), Some("out/cases/../s.pellet"));
    assert_eq!(o.output.as_deref(), Some("out/cases/bed.mcap"));
    let o = PackOptions::from_case_file(text, "a.toml").unwrap().relative_to_case_file("a.toml");
    assert_eq!(o.pellet.as_deref(), Some("../s.pellet"));
    let o = PackOptions::from_case_file(text, "-").unwrap().relative_to_case_file("-");
    assert_eq!(o.output.as_deref(), Some("bed.mcap"));
    let abs = "pellet = \"/data/s.pellet\"\noutput = \"-\"\n";
    let o = PackOptions::from_case_file(abs, "x/a.toml").unwrap().relative_to_case_file("x/a.toml");
    assert_eq!((o.pellet.as_deref(), o.output.as_deref()), (Some("/data/s.pellet"), Some("-")));
}

#[test]
fn case_files_parse_and_flags_override_them() {
    let toml =
        "pellet = \"r.pellet\"\ntube-diameter = 40.45\nfill-height = 120\ncor = 0.5\nscheme = \"four-columns\"\n";
    let json =
        r#"{"pellet": "r.pellet", "tube-diameter": 40.45, "fill-height": 120, "cor": 0.5, "scheme": "four-columns"}"#;
    let a = PackOptions::from_case_file(toml, "case.toml").unwrap();
    let b = PackOptions::from_case_file(json, "case.json").unwrap();
    assert_eq!(a, b);
    let flags = PackOptions { cor: Some(0.8), ..Default::default() };
    let c = PackConfig::resolve(&a.overlay(flags)).unwrap();
    assert_eq!(c.cor, 0.8);
    assert_eq!(c.scheme, LoadingScheme::FourColumns);
    assert_eq!(c.amount, Amount::FillHeight(0.12));
    let err = PackOptions::from_case_file("tube-diametr = 3\n", "x.toml").unwrap_err().to_string();
    assert!(err.contains("unknown key `tube-diametr`; did you mean `tube-diameter`?"), "{err}");
}

#[test]
fn a_run_without_engine_settings_runs_the_engine_defaults() {
    let engine = |o: PackOptions| crate::driver::engine_params(&PackConfig::resolve(&o).unwrap());
    assert_eq!(engine(base()), EngineParams::default());
    let force_level = EngineParams { stepper: Stepper::Acceleration, ..EngineParams::default() };
    assert_eq!(engine(PackOptions { stepper: Some(Stepper::Acceleration), ..base() }), force_level);
}

#[test]
fn resting_band_and_clamp_rule_reach_the_engine() {
    use pellet_sim::FrictionClamp;
    let engine = |o: PackOptions| crate::driver::engine_params(&PackConfig::resolve(&o).unwrap());
    // Defaults: εp = εf = 5e-3 m/s, the engine's substep cap, each model's own rule.
    let rec = engine(base());
    assert_eq!((rec.eps_p, rec.acceleration.eps_f, rec.acceleration.dt_cap), (5e-3, 5e-3, 2.5e-4));
    assert_eq!(rec.acceleration.friction_clamp, FrictionClamp::Stick);
    let paper = engine(PackOptions { contact_model: Some(ContactModel::Paper), ..base() });
    assert_eq!(paper.acceleration.friction_clamp, FrictionClamp::Zero);
    // A narrower band lowers the cap to εp / 2g; a wider one keeps the engine's.
    let narrow = engine(PackOptions { resting_band: Some(2.5e-3), ..base() });
    assert_eq!((narrow.eps_p, narrow.acceleration.eps_f), (2.5e-3, 2.5e-3));
    let cap = narrow.acceleration.dt_cap;
    assert!((cap - 2.5e-3 / (2.0 * 9.81)).abs() < 1e-15, "{cap}");
    assert_eq!(engine(PackOptions { resting_band: Some(1e-2), ..base() }).acceleration.dt_cap, 2.5e-4);
    let zero = engine(PackOptions { friction_clamp: Some(ClampRule::Zero), ..base() });
    assert_eq!(zero.acceleration.friction_clamp, FrictionClamp::Zero);
    assert!(
        zero.acceleration.static_friction && zero.acceleration.velocity_bias,
        "the rest of the recommended model stays"
    );
    // The substep scale shrinks the slip per substep and the cap alike.
    let half = engine(PackOptions { substep_scale: Some(0.5), ..base() });
    assert_eq!((half.acceleration.slip_fraction, half.acceleration.dt_cap), (0.1, 1.25e-4));
    assert_eq!(rec.acceleration.slip_fraction, 0.2);
}

#[test]
fn out_of_range_values_name_the_flag_and_range() {
    for (o, needle) in [
        (PackOptions { cor: Some(1.5), ..base() }, "--cor must be in [0, 1]"),
        (PackOptions { wall_cor: Some(-0.1), ..base() }, "--wall-cor"),
        (PackOptions { tube_diameter: Some(-3.0), ..base() }, "--tube-diameter must be in (0"),
        (PackOptions { tube_diameter: Some(1e300), ..base() }, "--tube-diameter must be in (0, 10000] mm"),
        (PackOptions { count: None, fill_height: Some(1e12), ..base() }, "--fill-height must be in (0, 10000] mm"),
        (PackOptions { density: Some(f64::NAN), ..base() }, "--density"),
        (PackOptions { fill_height: Some(100.0), ..base() }, "either --count or --fill-height"),
        (PackOptions { count: None, ..base() }, "give --count N or --fill-height MM"),
        (PackOptions { count: Some(4_000_000_000), ..base() }, "--count must be in [1, 1000000]"),
        (PackOptions { pellet: None, ..base() }, "--pellet is required"),
        (PackOptions { resting_band: Some(0.0), ..base() }, "--resting-band must be in [0.0001, 0.1] m/s"),
        (PackOptions { threads: Some(0), ..base() }, "--threads must be in [1, 1024] (got 0)"),
        (PackOptions { release_height: Some(0.0), ..base() }, "--release-height must be in (0, 10000] mm"),
        (
            PackOptions { release_height: Some(150.0), scheme: Some(LoadingScheme::Batch), ..base() },
            "--release-height is where pellets poured one at a time enter",
        ),
    ] {
        let err = PackConfig::resolve(&o).unwrap_err().to_string();
        assert!(err.contains(needle), "{err}");
    }
}
