//! Radial and axial void fraction of a bed, from vertical lines.
//!
//! The solid part of the cylinder surface of radius r between z0 and z1 is
//! S_int(r) = ∫ r·L(θ) dθ, with L(θ) the length of the vertical line
//! (r cos θ, r sin θ, z) inside the union of pellets, clipped to the window.
//! L is exact (closed-form or mesh crossings, union of intervals so that
//! overlapping pellets count once); only θ is sampled, uniformly with about
//! one line per `arc_step` of circumference, and refined by bisection where
//! neighbouring lines differ by more than [`REFINE_TOLERANCE`] × dp (jumps
//! from vertical pellet faces; see [`crate::refine`]). The same lines, weighted by
//! the radial trapezoid rule, give the axial profile ε(z) averaged over
//! bins, so that the radial and the axial profile integrate to the same
//! solid volume.

use pellet_geom::math::Real;
use pellet_geom::Bed;

use crate::line::{Geometry, LineCaster};
use crate::refine::Refiner;
use crate::{bed_top, reference_diameters, AnalysisError};

/// Largest number of lines one profile may use (memory and time guard).
pub const MAX_LINES: usize = 50_000_000;

/// Difference in line length between neighbouring lines, as a fraction of
/// dp, above which the gap between them is refined (see [`crate::refine`]).
pub const REFINE_TOLERANCE: Real = 0.1;

/// Fewest lines on a circle. A vertical pellet face (a standing cylinder's
/// side, a lying one's end) makes the line length jump with θ, and a jump
/// is located only to within one line spacing: near the axis, where
/// circles are short, the spacing must still be a small fraction of 2π.
pub const MIN_LINES: usize = 1000;

/// What to measure and how finely. Lengths in metres; `None` takes the default.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProfileParams {
    /// Axial window `(z0, z1)` (m), with 0 ≤ z0 < z1 ≤ top of the bed.
    pub window: (Real, Real),
    /// Radial step (m) [default: dp/50]. The grid runs from the wall inward
    /// in equal steps, so the wall region is resolved at this step.
    pub radial_step: Option<Real>,
    /// Spacing of the lines along each circle (m) [default: dp/250], with
    /// at least [`MIN_LINES`] lines on every circle but the axis.
    pub arc_step: Option<Real>,
    /// Axial bin height of ε(z) (m) [default: dp/20].
    pub axial_step: Option<Real>,
    /// Closed forms where available, or always the mesh.
    pub geometry: Geometry,
}

impl ProfileParams {
    /// The default resolution over `window` (m).
    pub fn new(window: (Real, Real)) -> ProfileParams {
        ProfileParams { window, radial_step: None, arc_step: None, axial_step: None, geometry: Geometry::Auto }
    }
}

/// Fraction of the cylinder surface r, z0 ≤ z ≤ z1 outside every pellet.
#[derive(Clone, Debug, PartialEq)]
pub struct VoidProfile {
    /// Tube radius R (m).
    pub tube_radius: Real,
    /// The window (m).
    pub window: (Real, Real),
    /// Radii from the axis (m), ascending from 0 to R.
    pub radius: Vec<Real>,
    /// ε(r) at each radius; 1 at the wall by definition (pellets touch it
    /// along lines or points, which have no area).
    pub void_fraction: Vec<Real>,
    /// Lines sampled on each circle.
    pub lines: Vec<usize>,
    /// The axial profile over the same window.
    pub axial: AxialProfile,
    /// The resolution used (m): radial step, arc step, axial step.
    pub steps: (Real, Real, Real),
}

/// ε(z): void fraction of the tube cross-section, averaged over z bins.
#[derive(Clone, Debug, PartialEq)]
pub struct AxialProfile {
    /// Bin edges (m), ascending from z0 to z1.
    pub edges: Vec<Real>,
    /// ε of each bin.
    pub void_fraction: Vec<Real>,
}

impl VoidProfile {
    /// ∫ ε(r) 2πr dr / (πR²) by the trapezoid rule on the profile's grid:
    /// the bulk porosity the profile implies.
    pub fn cross_section_mean(&self) -> Real {
        let mut sum = 0.0;
        for k in 1..self.radius.len() {
            let (r0, r1) = (self.radius[k - 1], self.radius[k]);
            sum += 0.5 * (r1 - r0) * (r0 * self.void_fraction[k - 1] + r1 * self.void_fraction[k]);
        }
        2.0 * sum / (self.tube_radius * self.tube_radius)
    }
}

/// The radii from the axis to the wall: equal steps from the wall inward, and 0.
pub fn radial_grid(tube_radius: Real, step: Real) -> Vec<Real> {
    let n = (tube_radius / step + 1e-9).floor() as usize;
    let mut radii: Vec<Real> = (0..=n).map(|i| tube_radius - i as Real * step).filter(|&r| r > 0.0).collect();
    radii.push(0.0);
    radii.reverse();
    radii
}

fn check_step(name: &str, value: Option<Real>, default: Real) -> Result<Real, AnalysisError> {
    let v = value.unwrap_or(default);
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(AnalysisError::BadParameter(format!("{name} must be a finite number > 0 mm (got {} mm)", v * 1e3)))
    }
}

/// Checks the window against the bed: 0 ≤ z0 < z1 ≤ the highest pellet point (and the lid).
pub fn check_window(bed: &Bed, window: (Real, Real)) -> Result<(), AnalysisError> {
    let (z0, z1) = window;
    let top = bed_top(bed);
    let outside = |why: String| Err(AnalysisError::Window { z0_mm: z0 * 1e3, z1_mm: z1 * 1e3, why });
    if !(z0.is_finite() && z1.is_finite()) || z1 <= z0 {
        return outside("z1 must be greater than z0".into());
    }
    if z0 < 0.0 {
        return outside("the bed starts at the floor, z = 0".into());
    }
    if z1 > top + 1e-12 {
        return outside(format!("the top of the bed (highest pellet point) is at {:.4} mm", top * 1e3));
    }
    Ok(())
}

/// The radial and axial void-fraction profiles of `bed` in `params.window`.
pub fn void_profile(bed: &Bed, params: &ProfileParams) -> Result<VoidProfile, AnalysisError> {
    bed.validate().map_err(|e| AnalysisError::BadParameter(e.to_string()))?;
    check_window(bed, params.window)?;
    let (dp, _) = reference_diameters(bed)?;
    let dr = check_step("the radial step", params.radial_step, dp / 50.0)?;
    let arc = check_step("the arc step", params.arc_step, dp / 250.0)?;
    let dz = check_step("the axial step", params.axial_step, dp / 20.0)?;
    let tube_radius = 0.5 * bed.tube.diameter;
    let (z0, z1) = params.window;
    let height = z1 - z0;
    let estimate =
        std::f64::consts::PI * tube_radius * tube_radius / (arc * dr) + (MIN_LINES as Real) * tube_radius / dr;
    if estimate > MAX_LINES as Real || height / dz > 1e7 {
        return Err(AnalysisError::BadParameter(format!(
            "the resolution asks for about {estimate:.3e} lines and {:.3e} bins (limits {MAX_LINES} and 1e7): coarsen the steps",
            height / dz
        )));
    }
    let radius = radial_grid(tube_radius, dr);
    let m = radius.len();
    // The wall circle is not sampled: ε(R) = 1 by definition.
    let lines: Vec<usize> = radius
        .iter()
        .enumerate()
        .map(|(i, &r)| match i {
            0 => 1,
            _ if i == m - 1 => 0,
            _ => ((2.0 * std::f64::consts::PI * r / arc).ceil() as usize).max(MIN_LINES),
        })
        .collect();
    // Trapezoid weights of ∫ f(r) 2πr dr; they sum to πR².
    let weight: Vec<Real> = (0..m)
        .map(|i| {
            let left = if i > 0 { radius[i] - radius[i - 1] } else { 0.0 };
            let right = if i + 1 < m { radius[i + 1] - radius[i] } else { 0.0 };
            std::f64::consts::PI * radius[i] * (left + right)
        })
        .collect();
    let bins = ((height / dz) - 1e-9).ceil().max(1.0) as usize;
    let mut edges: Vec<Real> = (0..bins).map(|j| z0 + j as Real * dz).collect();
    edges.push(z1);
    let mut axial_solid = vec![0.0; bins];
    let mut solid_length = vec![0.0; m];

    // Pellets that can reach the window, ordered by their innermost radius.
    let mut entries: Vec<Entry> = Vec::new();
    for (index, pose) in bed.pellets.iter().enumerate() {
        let pellet = &bed.pellet_types[pose.type_index as usize];
        let reach = pellet.mesh.max_radius().max(pellet.closed_form.map_or(0.0, |c| c.bounding_radius()));
        let z = pose.position[2];
        if z + reach <= z0 || z - reach >= z1 {
            continue;
        }
        let rho = pose.position[0].hypot(pose.position[1]);
        entries.push(Entry { index, rho, phi: pose.position[1].atan2(pose.position[0]), reach });
    }
    entries.sort_by(|a, b| (a.rho - a.reach).total_cmp(&(b.rho - b.reach)));

    let mut active: Vec<(Entry, LineCaster)> = Vec::new();
    let mut next_entry = 0;
    let mut buffers: Vec<Vec<(Real, Real)>> = Vec::new();
    let mut merged: Vec<(Real, Real)> = Vec::new();
    let mut lengths: Vec<Real> = Vec::new();
    let chunk = ((0.5 * dp / dr).ceil() as usize).max(1);
    let mut first = 0;
    while first < m {
        let last = (first + chunk).min(m);
        let (r_lo, r_hi) = (radius[first], radius[last - 1]);
        active.retain(|(e, _)| e.rho + e.reach >= r_lo);
        while next_entry < entries.len() && entries[next_entry].rho - entries[next_entry].reach <= r_hi {
            let e = entries[next_entry];
            let pose = &bed.pellets[e.index];
            let caster = LineCaster::new(&bed.pellet_types[pose.type_index as usize], pose, params.geometry);
            active.push((e, caster));
            next_entry += 1;
        }
        // Line directions and buffers of this chunk.
        let offsets: Vec<usize> = (first..=last)
            .scan(0, |acc, i| {
                let o = *acc;
                *acc += if i < last { lines[i] } else { 0 };
                Some(o)
            })
            .collect();
        let total = offsets[last - first];
        if buffers.len() < total {
            buffers.resize_with(total, Vec::new);
        }
        buffers[..total].iter_mut().for_each(Vec::clear);
        for (e, caster) in &active {
            let footprint = caster.footprint();
            for i in first..last {
                let (r, n) = (radius[i], lines[i]);
                let Some((k_lo, k_hi)) = line_range(r, n, e.rho, e.phi, footprint) else { continue };
                let base = offsets[i - first];
                for k in k_lo..=k_hi {
                    let k = k.rem_euclid(n as i64) as usize;
                    let theta = line_angle(k, n);
                    caster.intervals(r * theta.cos(), r * theta.sin(), &mut buffers[base + k]);
                }
            }
        }
        let mut refiner = Refiner::new(active.iter().map(|(_, c)| c).collect(), (z0, z1), dp * REFINE_TOLERANCE);
        for i in first..last {
            let (base, n) = (offsets[i - first], lines[i]);
            let w = if n > 0 { weight[i] / n as Real } else { 0.0 };
            lengths.clear();
            for buffer in &mut buffers[base..base + n] {
                union_in_window(buffer, (z0, z1), &mut merged);
                // The buffer now holds the merged intervals, for the refinement below.
                std::mem::swap(buffer, &mut merged);
                lengths.push(buffer.iter().map(|(a, b)| b - a).sum::<Real>());
                for &(a, b) in buffer.iter() {
                    deposit(&mut axial_solid, &edges, dz, a, b, w);
                }
            }
            solid_length[i] += lengths.iter().sum::<Real>();
            if n < 2 {
                continue;
            }
            let h = 2.0 * std::f64::consts::PI / n as Real;
            for k in 0..n {
                let k2 = (k + 1) % n;
                if (lengths[k] - lengths[k2]).abs() <= refiner.tolerance {
                    continue;
                }
                let (first_extra, last_extra, added) =
                    refiner.gap(radius[i], line_angle(k, n), h, lengths[k], lengths[k2]);
                // Extra weights are in radians; one line stands for h radians.
                let mut extra = first_extra * lengths[k] + last_extra * lengths[k2];
                for (line, e) in [(base + k, first_extra), (base + k2, last_extra)] {
                    for &(a, b) in &buffers[line] {
                        deposit(&mut axial_solid, &edges, dz, a, b, w * e / h);
                    }
                }
                for add in &added {
                    extra += add.weight * add.length;
                    for &(a, b) in &add.intervals {
                        deposit(&mut axial_solid, &edges, dz, a, b, w * add.weight / h);
                    }
                }
                solid_length[i] += extra / h;
            }
        }
        first = last;
    }
    let void_fraction: Vec<Real> =
        (0..m).map(|i| if lines[i] == 0 { 1.0 } else { 1.0 - solid_length[i] / (lines[i] as Real * height) }).collect();
    let section = std::f64::consts::PI * tube_radius * tube_radius;
    let axial_void: Vec<Real> =
        (0..bins).map(|j| 1.0 - axial_solid[j] / (section * (edges[j + 1] - edges[j]))).collect();
    Ok(VoidProfile {
        tube_radius,
        window: params.window,
        radius,
        void_fraction,
        lines,
        axial: AxialProfile { edges, void_fraction: axial_void },
        steps: (dr, arc, dz),
    })
}

#[derive(Clone, Copy)]
struct Entry {
    index: usize,
    rho: Real,
    phi: Real,
    reach: Real,
}

/// Angle of line `k` of `n` on a circle.
fn line_angle(k: usize, n: usize) -> Real {
    2.0 * std::f64::consts::PI * (k as Real + 0.5) / n as Real
}

/// The (unwrapped) indices of the lines on circle `r` (n lines) that can
/// meet a footprint of radius `reach` centred at polar (rho, phi).
fn line_range(r: Real, n: usize, rho: Real, phi: Real, reach: Real) -> Option<(i64, i64)> {
    if n == 0 {
        return None;
    }
    let all = Some((0, n as i64 - 1));
    if r == 0.0 || rho < 1e-15 {
        // One of the two circles is a point: all lines or none.
        return if (r - rho).abs() <= reach { all } else { None };
    }
    let cos_alpha = (r * r + rho * rho - reach * reach) / (2.0 * r * rho);
    if cos_alpha >= 1.0 {
        return None;
    }
    if cos_alpha <= -1.0 {
        return all;
    }
    let alpha = cos_alpha.acos();
    let scale = n as Real / (2.0 * std::f64::consts::PI);
    let lo = ((phi - alpha) * scale - 0.5).ceil() as i64;
    let hi = ((phi + alpha) * scale - 0.5).floor() as i64;
    if hi < lo {
        None
    } else if hi - lo + 1 >= n as i64 {
        all
    } else {
        Some((lo, hi))
    }
}

/// Sorts `intervals`, merges overlaps and clips them to `window`.
pub(crate) fn union_in_window(intervals: &mut [(Real, Real)], window: (Real, Real), out: &mut Vec<(Real, Real)>) {
    out.clear();
    intervals.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
    for &(a, b) in intervals.iter() {
        let (a, b) = (a.max(window.0), b.min(window.1));
        if b <= a {
            continue;
        }
        match out.last_mut() {
            Some(last) if a <= last.1 => last.1 = last.1.max(b),
            _ => out.push((a, b)),
        }
    }
}

/// Adds `weight ×` the overlap of [a, b] with each bin.
fn deposit(solid: &mut [Real], edges: &[Real], dz: Real, a: Real, b: Real, weight: Real) {
    let z0 = edges[0];
    let last = solid.len() - 1;
    let first_bin = (((a - z0) / dz).floor().max(0.0) as usize).min(last);
    for (j, s) in solid.iter_mut().enumerate().skip(first_bin) {
        let (lo, hi) = (edges[j], edges[j + 1]);
        if lo >= b {
            break;
        }
        let overlap = b.min(hi) - a.max(lo);
        if overlap > 0.0 {
            *s += weight * overlap;
        }
    }
}
