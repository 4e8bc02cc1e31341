//! The one chart both plots are: series with bands, and styled curves.

use std::path::Path;
use std::sync::Once;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::{register_font, FontStyle};

use crate::{CurveStyle, PlotError, ProfileFrame, ProfileSeries, RefCurve};

/// The font family every text uses; registered once from the embedded
/// DejaVu faces, because the `ab_glyph` backend has no font lookup.
const FAMILY: &str = "sans-serif";
/// The image size without caption lines (pixels).
const SIZE: (u32, u32) = (900, 560);
/// Height of one caption line under the chart (pixels).
const NOTE_LINE: u32 = 22;
/// Characters of a caption line that fit the image's width at its font (about 6.5 pixels each,
/// with room to spare for wide letters); longer lines are wrapped.
const NOTE_CHARS: usize = 120;
/// Room above the plotting area for the `wall` and `axis` labels (pixels).
const FRAME_LABELS: u32 = 22;
/// The colour of the wall and axis lines and of the caption text.
const FRAME_INK: RGBColor = RGBColor(70, 70, 70);
/// An axis beyond the data's far end by more than this fraction of the data's x span is not
/// drawn in the chart (it would squeeze the data) but named at the x axis's end.
const AXIS_REACH: f64 = 0.5;

/// Image formats, from the file extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    /// `.png`
    Png,
    /// `.svg`
    Svg,
}

impl ImageFormat {
    /// The format of `path`, by its extension (case-insensitive).
    pub fn of(path: &Path) -> Option<ImageFormat> {
        match path.extension()?.to_str()?.to_ascii_lowercase().as_str() {
            "png" => Some(ImageFormat::Png),
            "svg" => Some(ImageFormat::Svg),
            _ => None,
        }
    }
}

/// A chart: titles, simulated series and reference curves.
pub struct Chart<'a> {
    /// Caption.
    pub title: &'a str,
    /// x axis label.
    pub x_label: &'a str,
    /// y axis label.
    pub y_label: &'a str,
    /// Simulated series (lines, optional bands).
    pub series: &'a [ProfileSeries],
    /// Reference curves.
    pub references: &'a [RefCurve],
    /// A radial profile's wall, axis and caption lines (`None` for other charts).
    pub frame: Option<&'a ProfileFrame>,
}

fn register_fonts() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The embedded faces are valid TrueType; failure would be a build defect.
        let _ = register_font(FAMILY, FontStyle::Normal, dejavu::sans::regular());
        let _ = register_font(FAMILY, FontStyle::Bold, dejavu::sans::bold());
    });
}

/// Colours for simulated series, then references (distinct on white). The series colours are
/// black and greys first (a profile's one simulated series stays black beside the coloured
/// references), then dark colours that no reference uses, so that a chart of four or more
/// series (porosity against COR: two sphere and two cylinder series) never repeats one.
const SERIES_COLORS: [RGBColor; 6] = [
    RGBColor(0, 0, 0),
    RGBColor(90, 90, 90),
    RGBColor(150, 150, 150),
    RGBColor(128, 0, 0),
    RGBColor(0, 100, 0),
    RGBColor(75, 0, 130),
];
/// A series of at most this many points is drawn with a marker at each point (a study's
/// discrete values), a longer one (a profile) as a line only.
const MARKED_SERIES_MAX_POINTS: usize = 30;
const REF_COLORS: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
    RGBColor(188, 189, 34),
    RGBColor(0, 80, 120),
];

impl Chart<'_> {
    /// Renders to `path`, PNG or SVG by extension, atomically (a temporary
    /// file beside the target, renamed when complete).
    pub fn render(&self, path: &Path) -> Result<(), PlotError> {
        let shown = || path.display().to_string();
        let format = ImageFormat::of(path).ok_or_else(|| PlotError::UnknownFormat { path: shown() })?;
        let (x_range, y_range) = self.ranges().ok_or_else(|| PlotError::Empty { path: shown() })?;
        let draw_err = |reason: String| PlotError::Draw { path: shown(), reason };
        // Checked here: the PNG encoder would report it as a nest of its own error names.
        let dir = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
        if !dir.is_dir() {
            return Err(draw_err(format!(
                "the directory {} does not exist; create it or give another path",
                dir.display()
            )));
        }
        register_fonts();
        let size = (SIZE.0, SIZE.1 + self.notes_height());
        match format {
            ImageFormat::Svg => {
                let mut svg = String::new();
                {
                    let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
                    self.draw(root, x_range, y_range).map_err(draw_err)?;
                }
                write_atomically(path, "svg", |tmp| std::fs::write(tmp, svg.as_bytes()).map_err(|e| e.to_string()))
                    .map_err(draw_err)
            }
            ImageFormat::Png => write_atomically(path, "png", |tmp| {
                // The encoder picks PNG from the temporary name's extension.
                let root = BitMapBackend::new(tmp, size).into_drawing_area();
                self.draw(root, x_range, y_range)
            })
            .map_err(draw_err),
        }
    }

    /// The caption lines, each wrapped at spaces to fit the image's width.
    fn notes(&self) -> Vec<String> {
        self.frame.map_or_else(Vec::new, |f| f.notes.iter().flat_map(|n| wrap(n, NOTE_CHARS)).collect())
    }

    /// The height of the caption lines under the chart (pixels).
    fn notes_height(&self) -> u32 {
        match self.notes().len() {
            0 => 0,
            n => NOTE_LINE * n as u32 + 8,
        }
    }

    fn points(&self) -> impl Iterator<Item = (f64, f64)> + '_ {
        let series = self.series.iter().flat_map(|s| {
            s.x.iter().zip(&s.y).enumerate().flat_map(move |(i, (&x, &y))| {
                let d = s.spread.as_ref().and_then(|sp| sp.get(i)).copied().unwrap_or(0.0);
                [(x, y - d), (x, y + d)]
            })
        });
        let refs = self.references.iter().flat_map(|r| r.points.iter().copied());
        series.chain(refs).filter(|(x, y)| x.is_finite() && y.is_finite())
    }

    fn ranges(&self) -> Option<((f64, f64), (f64, f64))> {
        let (mut x0, mut x1, mut y0, mut y1) = (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
        for (x, y) in self.points() {
            (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
        }
        if !x0.is_finite() {
            return None;
        }
        if let Some(frame) = self.frame {
            let mut marks = vec![frame.wall];
            marks.extend(frame.axis.filter(|&a| axis_within_reach(a, x0, x1)));
            for m in marks.into_iter().filter(|m| m.is_finite()) {
                (x0, x1) = (x0.min(m), x1.max(m));
            }
        }
        let pad = |lo: f64, hi: f64| {
            let span = (hi - lo).max(1e-6);
            (lo - 0.04 * span, hi + 0.04 * span)
        };
        // Void fractions live in [0, 1]: start the axis at 0 only when the data come near it.
        let (ylo, yhi) = pad(y0, y1);
        let x = if x0 >= 0.0 && x0 < 0.2 * (x1 - x0) { (0.0, pad(x0, x1).1) } else { pad(x0, x1) };
        Some((x, (ylo.max(0.0), yhi)))
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: DrawingArea<DB, Shift>,
        (x0, x1): (f64, f64),
        (y0, y1): (f64, f64),
    ) -> Result<(), String>
    where
        DB::ErrorType: 'static,
    {
        let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
        root.fill(&WHITE).map_err(e)?;
        // The chart above, the caption lines (if any) below it.
        let (upper, lower) = root.split_vertically(SIZE.1);
        let titled = upper.margin(14, 14, 14, 14).titled(self.title, (FAMILY, 22)).map_err(e)?;
        let area = titled.margin(if self.frame.is_some() { FRAME_LABELS } else { 0 }, 0, 0, 0);
        let mut chart = ChartBuilder::on(&area)
            .x_label_area_size(46)
            .y_label_area_size(60)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(e)?;
        chart
            .configure_mesh()
            .x_desc(self.x_label)
            .y_desc(self.y_label)
            .label_style((FAMILY, 15))
            .axis_desc_style((FAMILY, 16))
            .light_line_style(RGBColor(235, 235, 235))
            .draw()
            .map_err(e)?;
        for (i, s) in self.series.iter().enumerate() {
            let color = SERIES_COLORS[i % SERIES_COLORS.len()];
            if let Some(spread) = &s.spread {
                // The band: upper edge left to right, lower edge back.
                let upper = s.x.iter().zip(&s.y).zip(spread).map(|((&x, &y), &d)| (x, y + d));
                let lower = s.x.iter().zip(&s.y).zip(spread).rev().map(|((&x, &y), &d)| (x, y - d));
                let outline: Vec<(f64, f64)> = upper.chain(lower).collect();
                chart.draw_series(std::iter::once(Polygon::new(outline, color.mix(0.18).filled()))).map_err(e)?;
            }
            let label = if s.spread.is_some() { format!("{} (± spread)", s.label) } else { s.label.clone() };
            let line = s.x.iter().copied().zip(s.y.iter().copied());
            let marked = s.x.len() <= MARKED_SERIES_MAX_POINTS;
            if marked {
                chart.draw_series(line.clone().map(|p| Circle::new(p, 4, color.filled()))).map_err(e)?;
            }
            chart.draw_series(LineSeries::new(line, color.stroke_width(2))).map_err(e)?.label(label).legend(
                move |(x, y)| {
                    EmptyElement::at((x, y))
                        + Circle::new((11, 0), if marked { 4 } else { 0 }, color.filled())
                        + PathElement::new(vec![(0, 0), (22, 0)], color.stroke_width(2))
                },
            );
        }
        // Palette colours go to the curves without an explicit one, in order.
        let mut next = 0;
        for r in self.references {
            let color = match r.color {
                Some((red, green, blue)) => RGBColor(red, green, blue),
                None => {
                    next += 1;
                    REF_COLORS[(next - 1) % REF_COLORS.len()]
                }
            };
            let pts = r.points.clone();
            let anno = match r.style {
                CurveStyle::Solid => chart.draw_series(LineSeries::new(pts, color.stroke_width(2))).map_err(e)?,
                CurveStyle::Dashed => {
                    chart.draw_series(DashedLineSeries::new(pts, 8, 5, color.stroke_width(2))).map_err(e)?
                }
                CurveStyle::Markers => {
                    chart.draw_series(pts.into_iter().map(|p| Circle::new(p, 4, color.filled()))).map_err(e)?
                }
            };
            let style = r.style;
            anno.label(r.label.clone()).legend(move |(x, y)| match style {
                CurveStyle::Markers => {
                    EmptyElement::at((x, y)) + Circle::new((11, 0), 4, color.filled()) + PathElement::new(vec![], color)
                }
                _ => {
                    EmptyElement::at((x, y))
                        + Circle::new((0, 0), 0, color)
                        + PathElement::new(
                            if style == CurveStyle::Dashed { vec![(0, 0), (8, 0)] } else { vec![(0, 0), (22, 0)] },
                            color.stroke_width(2),
                        )
                }
            });
        }
        if let Some(frame) = self.frame {
            // The wall and the axis, labelled just above the plotting area.
            let (px, py) = chart.plotting_area().get_pixel_range();
            let label = |text: &str, x: i32, anchor: HPos| -> Result<(), String> {
                let style =
                    TextStyle::from((FAMILY, 15).into_font()).color(&FRAME_INK).pos(Pos::new(anchor, VPos::Bottom));
                root.draw_text(text, &style, (x, py.start - 5)).map_err(e)
            };
            // Text at a line runs toward the middle of the chart.
            let toward_middle = |x: i32| if x < (px.start + px.end) / 2 { HPos::Left } else { HPos::Right };
            let inside = |x: f64| x >= x0 && x <= x1;
            if inside(frame.wall) {
                let line = PathElement::new(vec![(frame.wall, y0), (frame.wall, y1)], FRAME_INK.stroke_width(3));
                chart.draw_series(std::iter::once(line)).map_err(e)?;
                let x = chart.backend_coord(&(frame.wall, y1)).0;
                label("wall (r = R)", x, toward_middle(x))?;
            }
            match frame.axis.filter(|&a| inside(a)) {
                Some(a) => {
                    let line = DashedLineSeries::new(vec![(a, y0), (a, y1)], 7, 5, FRAME_INK.stroke_width(2));
                    chart.draw_series(line).map_err(e)?;
                    let x = chart.backend_coord(&(a, y1)).0;
                    label("axis (r = 0)", x, toward_middle(x))?;
                }
                None => {
                    // The axis lies beyond the x axis's end away from the wall (or is not known).
                    let at = frame.axis.map_or(String::new(), |a| format!(" at x = {a:.2}"));
                    if (frame.wall - x0).abs() <= (frame.wall - x1).abs() {
                        label(&format!("axis (r = 0){at} →"), px.end, HPos::Right)?;
                    } else {
                        label(&format!("← axis (r = 0){at}"), px.start, HPos::Left)?;
                    }
                }
            }
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .label_font((FAMILY, 14))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()
            .map_err(e)?;
        let style = TextStyle::from((FAMILY, 15).into_font()).color(&FRAME_INK).pos(Pos::new(HPos::Left, VPos::Top));
        for (i, note) in self.notes().iter().enumerate() {
            lower.draw_text(note, &style, (20, (NOTE_LINE * i as u32) as i32)).map_err(e)?;
        }
        root.present().map_err(e)?;
        Ok(())
    }
}

/// `text` in lines of at most `width` characters, broken at spaces (a longer word stays whole).
fn wrap(text: &str, width: usize) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    let mut line = String::new();
    for word in text.split(' ') {
        if !line.is_empty() && line.chars().count() + 1 + word.chars().count() > width {
            lines.push(std::mem::take(&mut line));
        }
        if !line.is_empty() {
            line.push(' ');
        }
        line.push_str(word);
    }
    lines.push(line);
    lines
}

/// Whether an axis at `axis` is close enough to the data's x range [x0, x1] to be drawn in the
/// chart: within [`AXIS_REACH`] of the span beyond either end.
fn axis_within_reach(axis: f64, x0: f64, x1: f64) -> bool {
    let reach = AXIS_REACH * (x1 - x0).max(1e-6);
    axis >= x0 - reach && axis <= x1 + reach
}

/// Writes through a temporary file `.{name}.packbed-tmp.{ext}` beside
/// `path`, renamed into place only when `write` succeeded.
fn write_atomically(path: &Path, ext: &str, write: impl FnOnce(&Path) -> Result<(), String>) -> Result<(), String> {
    // A device or FIFO is written in place: a rename would replace it.
    if std::fs::metadata(path).is_ok_and(|m| !m.is_file() && !m.is_dir()) {
        return write(path);
    }
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let tmp = dir.join(format!(".{name}.packbed-tmp.{ext}"));
    let result = write(&tmp).and_then(|()| std::fs::rename(&tmp, path).map_err(|e| e.to_string()));
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn series_colours_are_distinct_from_each_other_and_from_the_references() {
        let rgb = |c: &RGBColor| (c.0, c.1, c.2);
        for (i, a) in SERIES_COLORS.iter().enumerate() {
            for b in &SERIES_COLORS[i + 1..] {
                assert_ne!(rgb(a), rgb(b), "two series share a colour");
            }
            assert!(REF_COLORS.iter().all(|r| rgb(r) != rgb(a)), "series colour {:?} is a reference colour", rgb(a));
        }
        assert!(SERIES_COLORS.len() >= 4, "the COR and friction charts draw four series");
    }

    #[test]
    fn long_caption_lines_are_wrapped_at_spaces() {
        assert_eq!(wrap("one two three", 7), ["one two", "three"]);
        assert_eq!(wrap("short", 7), ["short"]);
        assert_eq!(wrap("a longword b", 3), ["a", "longword", "b"]);
        let long = "x ".repeat(100);
        assert!(wrap(long.trim(), NOTE_CHARS).iter().all(|l| l.chars().count() <= NOTE_CHARS));
    }

    #[test]
    fn format_follows_the_extension() {
        assert_eq!(ImageFormat::of(Path::new("a/b.PNG")), Some(ImageFormat::Png));
        assert_eq!(ImageFormat::of(Path::new("b.svg")), Some(ImageFormat::Svg));
        assert_eq!(ImageFormat::of(Path::new("b.pdf")), None);
        assert_eq!(ImageFormat::of(Path::new("b")), None);
    }
}
