//! Renders both charts to PNG and SVG in a temporary directory.

use pellet_plot::{plot_porosity_vs_n, plot_profile, CurveStyle, PlotError, ProfileSeries, RefCurve};

fn profile_inputs() -> (Vec<ProfileSeries>, Vec<RefCurve>) {
    let z: Vec<f64> = (0..=300).map(|i| i as f64 * 0.01).collect();
    let eps: Vec<f64> = z.iter().map(|&z| 0.4 + 0.6 * (-1.5 * z).exp() * (6.3 * z).cos()).collect();
    let spread = vec![0.03; z.len()];
    let sim = ProfileSeries::new("simulated (3 packings)", z.clone(), eps).with_spread(spread);
    let line: Vec<(f64, f64)> = z.iter().map(|&z| (z, 0.39 + 0.61 * (-1.2 * z).exp() * (6.5 * z).cos())).collect();
    let dashed: Vec<(f64, f64)> = line.iter().map(|&(z, e)| (z, e + 0.02)).collect();
    let exp: Vec<(f64, f64)> = (0..15).map(|i| (i as f64 * 0.2, 0.42)).collect();
    let refs = vec![
        RefCurve::new("solid ref", line, CurveStyle::Solid),
        RefCurve::new("dashed ref (grade C)", dashed, CurveStyle::Dashed),
        RefCurve::new("experiment", exp, CurveStyle::Markers),
    ];
    (vec![sim], refs)
}

#[test]
fn profile_renders_to_png_and_svg_with_embedded_text() {
    let dir = tempfile::tempdir().unwrap();
    let (series, refs) = profile_inputs();
    for name in ["p.png", "p.svg"] {
        let path = dir.path().join(name);
        plot_profile(&path, "ε(z), N = 6", &series, &refs).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        assert!(bytes.len() > 5000, "{name}: {} bytes", bytes.len());
        if name.ends_with(".png") {
            assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
        } else {
            let text = String::from_utf8(bytes).unwrap();
            assert!(text.contains("<svg") && text.contains("solid ref") && text.contains("(R − r)/dp"));
        }
    }
    // No temporary file is left behind.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
}

#[test]
fn porosity_vs_n_renders() {
    let dir = tempfile::tempdir().unwrap();
    let curve: Vec<(f64, f64)> =
        (4..=100).map(|i| i as f64 * 0.25).map(|n| (n, 0.39 + 1.74 / (n + 1.14).powi(2))).collect();
    let beds = vec![(5.0, 0.43), (8.0, 0.41)];
    let curves =
        [RefCurve::new("Benyahia", curve, CurveStyle::Solid), RefCurve::new("beds", beds, CurveStyle::Markers)];
    let path = dir.path().join("n.png");
    plot_porosity_vs_n(&path, "bulk porosity", "N = D/dp", &curves).unwrap();
    assert!(std::fs::metadata(&path).unwrap().len() > 3000);
}

#[test]
fn bad_extension_and_empty_data_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    let (series, refs) = profile_inputs();
    let err = plot_profile(&dir.path().join("p.pdf"), "t", &series, &refs).unwrap_err();
    assert!(matches!(err, PlotError::UnknownFormat { .. }), "{err}");
    let err = plot_profile(&dir.path().join("p.png"), "t", &[], &[]).unwrap_err();
    assert!(matches!(err, PlotError::Empty { .. }), "{err}");
    let err = plot_profile(&dir.path().join("missing/dir/p.svg"), "t", &series, &refs).unwrap_err();
    assert!(matches!(err, PlotError::Draw { .. }), "{err}");
}
