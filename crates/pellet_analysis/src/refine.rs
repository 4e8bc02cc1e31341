//! Adaptive refinement in θ where the line length jumps.
//!
//! Uniform lines in θ are the periodic trapezoid rule, which is very
//! accurate for smooth L(θ) but locates a jump (a vertical pellet face: a
//! standing cylinder's side, a lying cylinder's end) only to within one
//! line spacing; in a lattice the errors of many pellets add up. Where two
//! neighbouring lines differ by more than a tolerance, the gap between them
//! is bisected (up to [`MAX_DEPTH`] times, only where the difference
//! persists) and integrated by the trapezoid rule on the finer points. The
//! caller adds the difference to the uniform estimate, as extra weights on
//! the two end lines (negative) and on the new lines.

use pellet_geom::math::Real;

use crate::line::LineCaster;
use crate::profile::union_in_window;

/// Bisection levels: a jump is then located to 1/64 of the line spacing.
pub const MAX_DEPTH: u32 = 6;

/// One line added by the refinement: its extra weight (radians), its
/// length in the window and its merged intervals.
pub(crate) struct Added {
    pub weight: Real,
    pub length: Real,
    pub intervals: Vec<(Real, Real)>,
}

/// A new line: its angle, its length in the window and its merged intervals.
type Point = (Real, Real, Vec<(Real, Real)>);

/// Evaluates new lines on one circle against the pellets near it.
pub(crate) struct Refiner<'a> {
    pub casters: Vec<&'a LineCaster>,
    pub window: (Real, Real),
    /// Length difference (m) between neighbouring lines that triggers refinement.
    pub tolerance: Real,
    scratch: Vec<(Real, Real)>,
}

impl<'a> Refiner<'a> {
    pub fn new(casters: Vec<&'a LineCaster>, window: (Real, Real), tolerance: Real) -> Self {
        Refiner { casters, window, tolerance, scratch: Vec::new() }
    }

    /// The merged intervals and total length of the line at angle `theta` on circle `r`.
    fn line(&mut self, r: Real, theta: Real) -> (Real, Vec<(Real, Real)>) {
        let (x, y) = (r * theta.cos(), r * theta.sin());
        self.scratch.clear();
        for caster in &self.casters {
            let (c, f) = (caster.centre(), caster.footprint());
            if (x - c.x).powi(2) + (y - c.y).powi(2) <= f * f {
                caster.intervals(x, y, &mut self.scratch);
            }
        }
        let mut merged = Vec::new();
        union_in_window(&mut self.scratch, self.window, &mut merged);
        (merged.iter().map(|(a, b)| b - a).sum(), merged)
    }

    /// Refines the gap from `theta` to `theta + h` whose end lines have
    /// lengths `start` and `end`. Returns the extra weights (radians) of the
    /// two end lines and the added lines.
    pub fn gap(&mut self, r: Real, theta: Real, h: Real, start: Real, end: Real) -> (Real, Real, Vec<Added>) {
        let mut points: Vec<Point> = Vec::new();
        self.split(r, (theta, start), (theta + h, end), 0, &mut points);
        if points.is_empty() {
            return (0.0, 0.0, Vec::new());
        }
        let mut times = Vec::with_capacity(points.len() + 2);
        times.push(theta);
        times.extend(points.iter().map(|p| p.0));
        times.push(theta + h);
        let m = times.len() - 1;
        let first = 0.5 * (times[1] - times[0]) - 0.5 * h;
        let last = 0.5 * (times[m] - times[m - 1]) - 0.5 * h;
        let added = points
            .into_iter()
            .enumerate()
            .map(|(j, (_, length, intervals))| Added { weight: 0.5 * (times[j + 2] - times[j]), length, intervals })
            .collect();
        (first, last, added)
    }

    fn split(&mut self, r: Real, a: (Real, Real), b: (Real, Real), depth: u32, points: &mut Vec<Point>) {
        if depth >= MAX_DEPTH || (a.1 - b.1).abs() <= self.tolerance {
            return;
        }
        let t = 0.5 * (a.0 + b.0);
        let (length, merged) = self.line(r, t);
        self.split(r, a, (t, length), depth + 1, points);
        points.push((t, length, merged));
        self.split(r, (t, length), b, depth + 1, points);
    }
}
