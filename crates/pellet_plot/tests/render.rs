//! Renders both charts to PNG and SVG in a temporary directory.

use std::path::Path;

use pellet_plot::{
    plot_porosity_vs_n, plot_profile, single_bed_note, window_note, CurveStyle, PlotError, ProfileFrame, ProfileSeries,
    RefCurve,
};

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

/// The profile of `profile_inputs` spans (R − r)/dp = 0–3: the axis of N = 6.
fn frame() -> ProfileFrame {
    ProfileFrame::wall_distance(Some(3.0)).with_note(window_note(0.0, 25.0)).with_note(single_bed_note("seed 1"))
}

fn svg_of(path: &Path) -> String {
    String::from_utf8(std::fs::read(path).unwrap()).unwrap()
}

/// The texts of an SVG's `<text …>…</text>` elements with their x position (pixels).
fn texts(svg: &str) -> Vec<(f64, String)> {
    svg.split("<text")
        .skip(1)
        .filter_map(|t| {
            let x = t.split("x=\"").nth(1)?.split('"').next()?.parse().ok()?;
            let body = t.split_once('>')?.1.split("</text>").next()?;
            Some((
                x,
                body.trim()
                    .replace("&lt;", "<")
                    .replace("&gt;", ">")
                    .replace("&apos;", "'")
                    .replace("&quot;", "\"")
                    .replace("&amp;", "&"),
            ))
        })
        .collect()
}

/// The (width, height) of a PNG, from its header.
fn png_size(bytes: &[u8]) -> (u32, u32) {
    let be = |b: &[u8]| u32::from_be_bytes([b[0], b[1], b[2], b[3]]);
    (be(&bytes[16..20]), be(&bytes[20..24]))
}

#[test]
fn profile_renders_to_png_and_svg_with_embedded_text() {
    let dir = tempfile::tempdir().unwrap();
    let (series, refs) = profile_inputs();
    for name in ["p.png", "p.svg"] {
        let path = dir.path().join(name);
        plot_profile(&path, "ε(z), N = 6", &frame(), &series, &refs).unwrap();
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
    let err = plot_profile(&dir.path().join("p.pdf"), "t", &frame(), &series, &refs).unwrap_err();
    assert!(matches!(err, PlotError::UnknownFormat { .. }), "{err}");
    let err = plot_profile(&dir.path().join("p.png"), "t", &frame(), &[], &[]).unwrap_err();
    assert!(matches!(err, PlotError::Empty { .. }), "{err}");
    let err = plot_profile(&dir.path().join("missing/dir/p.svg"), "t", &frame(), &series, &refs).unwrap_err();
    assert!(matches!(err, PlotError::Draw { .. }), "{err}");
}

#[test]
fn a_profile_marks_the_wall_and_the_axis_and_states_its_caption() {
    let dir = tempfile::tempdir().unwrap();
    let (series, refs) = profile_inputs();
    let path = dir.path().join("p.svg");
    plot_profile(&path, "ε(z), N = 6", &frame(), &series, &refs).unwrap();
    let texts = texts(&svg_of(&path));
    let at = |needle: &str| {
        texts.iter().find(|(_, t)| t == needle).unwrap_or_else(|| panic!("no text {needle:?} in {texts:?}")).0
    };
    // The wall label sits at the left end of the x axis (x = 0), the axis label at its right
    // end (x = 3, the data's far end): the axis is in the chart, not named beyond it.
    let (wall, axis) = (at("wall (r = R)"), at("axis (r = 0)"));
    assert!(wall < 150.0 && axis > 750.0, "wall at {wall} px, axis at {axis} px");
    at("ε averaged over the axial window z = 0–25 mm");
    at("one bed (seed 1): a single sample; beds packed with another seed differ, and their spread is not shown");
    assert!(!texts.iter().any(|(_, t)| t.contains('→')), "the axis is in the chart: no arrow toward it");

    // Two caption lines make the image taller than a chart without any.
    let png = dir.path().join("p.png");
    plot_profile(&png, "t", &frame(), &series, &refs).unwrap();
    let bare = dir.path().join("bare.png");
    plot_profile(&bare, "t", &ProfileFrame::wall_distance(Some(3.0)), &series, &refs).unwrap();
    let (with, without) = (png_size(&std::fs::read(&png).unwrap()), png_size(&std::fs::read(&bare).unwrap()));
    assert_eq!(with.0, without.0);
    assert!(with.1 >= without.1 + 2 * 20, "{with:?} vs {without:?}");
}

#[test]
fn an_axis_beyond_the_data_or_unknown_is_named_at_the_far_end() {
    let dir = tempfile::tempdir().unwrap();
    let (series, refs) = profile_inputs();
    let path = dir.path().join("p.svg");
    // N = 40: the axis at x = 20, far beyond the profile's x = 3.
    plot_profile(&path, "t", &ProfileFrame::wall_distance(Some(20.0)), &series, &refs).unwrap();
    let svg = svg_of(&path);
    assert!(svg.contains("axis (r = 0) at x = 20.00 →") && svg.contains("wall (r = R)"), "{svg}");
    plot_profile(&path, "t", &ProfileFrame::wall_distance(None), &series, &refs).unwrap();
    let svg = svg_of(&path);
    assert!(svg.contains("axis (r = 0) →") && !svg.contains("at x ="), "{svg}");
    // x = r/R: the axis at 0, the wall at 1; an unknown axis lies away from the wall.
    let x: Vec<f64> = (0..=10).map(|i| i as f64 / 10.0).collect();
    let s = ProfileSeries::new("s", x.clone(), x.iter().map(|v| 0.4 + 0.5 * v).collect());
    let r_over_r = ProfileFrame { wall: 1.0, axis: None, notes: vec![] };
    plot_profile(&path, "t", &r_over_r, std::slice::from_ref(&s), &[]).unwrap();
    assert!(svg_of(&path).contains("← axis (r = 0)"));
}

#[test]
fn other_charts_carry_no_wall_or_axis() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("n.svg");
    let curves = [RefCurve::new("beds", vec![(5.0, 0.43), (8.0, 0.41)], CurveStyle::Markers)];
    plot_porosity_vs_n(&path, "bulk porosity", "N = D/dp", &curves).unwrap();
    let svg = svg_of(&path);
    assert!(svg.contains("bulk porosity") && !svg.contains("wall") && !svg.contains("axis (r"), "{svg}");
}

#[test]
fn captions_state_lengths_in_mm() {
    assert_eq!(window_note(0.0, 25.0), "ε averaged over the axial window z = 0–25 mm");
    assert_eq!(window_note(3.5, 29.123), "ε averaged over the axial window z = 3.5–29.12 mm");
    assert_eq!(pellet_plot::format_mm(-0.001), "0");
    assert_eq!(pellet_plot::format_mm(100.0), "100");
    assert_eq!(pellet_plot::spread_note(3, "seeds"), "mean of 3 seeds; the band is ± 1 standard deviation over them");
    assert!(single_bed_note("").starts_with("one bed: a single sample"));
}
