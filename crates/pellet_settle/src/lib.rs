//! When is a bed settled? The kinetic-energy termination test of the
//! paper (the total kinetic energy stops changing over a time window),
//! made robust: with frictionless resting contacts a spinning pellet
//! keeps its energy forever and a sliding one keeps it until it hits
//! something, so "ΔKE ≈ 0" alone can stop a run too early. A time t is
//! settled when, over the window [t − w, t]:
//!
//! 1. no pellet was added (the pellet count is final and constant),
//! 2. the kinetic energy varies by at most `relative_tolerance` × its
//!    largest value in the window (or by at most the energy floor),
//! 3. the *translational* kinetic energy at t is at most `ke_bound_j`, and
//! 4. the fastest pellet moves at most `max_speed_m_s`.
//!
//! Test 2 is also passed by a bed at rest: the fastest pellet below
//! [`REST_FRACTION`] of the speed bound and the kinetic energy below that
//! fraction of the energy bound, throughout the window (no pellet then
//! moves more than 0.1 × 1 mm/s × 0.15 s = 15 µm in it). A bed of a few
//! pellets at rest keeps a sub-micrometre oscillation whose energy swings
//! from 0 to its peak within every window, so its relative variation stays
//! near 1; in a large bed such swings average out. Measured: 3 spheres of
//! 10 mm in a 10.5 mm tube oscillate with period 0.075 s, at most 2.9e-5
//! m/s and 2.9e-12 J (bound 1.2e-10 J), to 120 s without passing test 2
//! alone; at rest by this rule from 4.0 s (2 spheres 17 s, 5 spheres
//! 4.9 s). The default pipeline's 40-sphere bed settles at 2.34 s either
//! way; a 20-sphere bed in a 40 mm tube at 1.435 s instead of 1.515 s.
//!
//! The bound in 3 is on translational energy because a sphere spinning in
//! place (about its contact normal, which Coulomb point friction does not
//! resist) keeps its rotational energy forever without changing the bed —
//! measured: a 20-sphere bed whose only motion left was such a spin, 8e-8 J
//! at 3e-6 m/s, constant to 1.6e-9 over the window.
//!
//! In a bed of spheres (`spheres`) test 2 reads the translational energy
//! too: a sphere's rotation moves none of its surface, and it acts on the
//! bed only through friction, which shows in the translational energy. Such
//! a spin does not always keep its energy: against neighbours that touch it
//! with forces at the solver's noise level it decays by a few per cent per
//! second, slower than test 2 allows and far too slowly to reach the floor.
//! Measured: a 690-sphere batch bed (D = 79.9 mm, seed 3) whose bed was
//! still at 51.7 s, four floor spheres spinning about the vertical at
//! 0.5–2.3 rad/s, total energy 1.4e-7 J falling 0.3 % per window; on the
//! translational energy the same record settles at 0.785 s.
//!
//! `pack` runs this test on the fly to decide when to stop, and
//! `settle-check` runs the same code on the recorded energy channel.
#![deny(missing_docs)]

use pellet_geom::math::shown;
use serde::{Deserialize, Serialize};

/// A bed whose fastest pellet stays below this fraction of the speed bound, and whose kinetic
/// energy stays below this fraction of the energy bound, over the window is at rest.
pub const REST_FRACTION: f64 = 0.1;

/// One sample of the run's energy history.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct EnergySample {
    /// Simulated time (s).
    pub time_s: f64,
    /// Total kinetic energy (J).
    pub kinetic_j: f64,
    /// Translational kinetic energy (J).
    pub kinetic_translational_j: f64,
    /// Fastest pellet's translational speed (m/s).
    pub max_speed_m_s: f64,
    /// Pellets in the tube.
    pub pellets: u32,
}

/// The test's thresholds.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SettleCriteria {
    /// Window length w (s).
    pub window_s: f64,
    /// Allowed variation of KE over the window, as a fraction of its maximum there.
    pub relative_tolerance: f64,
    /// Bound on the translational kinetic energy (J).
    pub ke_bound_j: f64,
    /// Bound on the fastest pellet's speed (m/s).
    pub max_speed_m_s: f64,
    /// A bed of spheres only: the window's variation test reads the
    /// translational kinetic energy (a sphere's spin moves none of its
    /// surface). Reports written before it existed read as `false`.
    #[serde(default)]
    pub spheres: bool,
}

impl SettleCriteria {
    /// The recommended values: window 0.15 s, |ΔKE| ≤ 1e-3 KE, KE ≤ 1e-7·N·m·g·d,
    /// speed ≤ 1 mm/s, for `pellets` pellets of mass `mass_kg` and size `size_m`.
    pub fn recommended(pellets: u32, mass_kg: f64, size_m: f64) -> Self {
        SettleCriteria {
            window_s: 0.15,
            relative_tolerance: 1e-3,
            ke_bound_j: 1e-7 * pellets.max(1) as f64 * mass_kg * 9.81 * size_m,
            max_speed_m_s: 1e-3,
            spheres: false,
        }
    }

    /// Checks that every threshold is finite and in its range: above 0 and at most 1000 s, 1
    /// (a fraction), 1000 J and 1000 m/s (the same as `pack`'s flags).
    pub fn validate(&self) -> Result<(), String> {
        let checks = [
            ("--settle-window", self.window_s, 1e3, " s"),
            ("--settle-tolerance", self.relative_tolerance, 1.0, ""),
            ("--ke-bound", self.ke_bound_j, 1e3, " J"),
            ("--max-speed", self.max_speed_m_s, 1e3, " m/s"),
        ];
        for (flag, v, hi, unit) in checks {
            if !(v.is_finite() && v > 0.0 && v <= hi) {
                return Err(format!("{flag} must be in (0, {hi}]{unit} (got {})", shown(v)));
            }
        }
        Ok(())
    }
}

/// What the test found.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SettleReport {
    /// Whether some time passed every criterion.
    pub settled: bool,
    /// The first such time (s).
    pub settle_time_s: Option<f64>,
    /// Index of that sample in the history.
    pub settle_index: Option<usize>,
    /// Time of the last sample (s).
    pub final_time_s: f64,
    /// Kinetic energy of the last sample (J).
    pub final_kinetic_j: f64,
    /// Relative KE variation over the window ending at the last sample.
    pub final_relative_change: f64,
    /// Fastest pellet's speed at the last sample (m/s).
    pub final_max_speed_m_s: f64,
    /// Which criterion failed at the last sample, if the bed is not settled.
    pub reason: Option<String>,
}

/// The reason a run that never finished loading is not settled: the test starts when the last
/// pellet has entered, so such a run gave it nothing to test.
pub const NOTHING_AFTER_LOADING: &str =
    "the run stopped while pellets were still entering, before the settle test could start; \
     run pack longer (a larger --max-time; --resume goes on from where it stopped)";

/// Runs the test over a time-ordered energy history.
pub fn check_settled(history: &[EnergySample], criteria: &SettleCriteria) -> SettleReport {
    let Some(last) = history.last() else {
        return SettleReport {
            settled: false,
            settle_time_s: None,
            settle_index: None,
            final_time_s: 0.0,
            final_kinetic_j: 0.0,
            final_relative_change: f64::INFINITY,
            final_max_speed_m_s: 0.0,
            reason: Some(NOTHING_AFTER_LOADING.into()),
        };
    };
    let final_count = last.pellets;
    let mut first_settled = None;
    let mut verdict_at_end = None;
    // Sliding window [start, i]: two pointers keep the scan linear.
    let mut start = 0;
    for (i, s) in history.iter().enumerate() {
        while history[start].time_s < s.time_s - criteria.window_s {
            start += 1;
        }
        let verdict = window_verdict(&history[start..=i], history[0].time_s, criteria, final_count);
        if verdict.is_ok() && first_settled.is_none() {
            first_settled = Some(i);
        }
        if i + 1 == history.len() {
            verdict_at_end = Some(verdict);
        }
    }
    let window_start = history.iter().position(|s| s.time_s >= last.time_s - criteria.window_s).unwrap_or(0);
    let (lo, hi) = min_max(&history[window_start..], criteria.spheres);
    SettleReport {
        settled: first_settled.is_some(),
        settle_time_s: first_settled.map(|i| history[i].time_s),
        settle_index: first_settled,
        final_time_s: last.time_s,
        final_kinetic_j: last.kinetic_j,
        final_relative_change: if hi > 0.0 { (hi - lo) / hi } else { 0.0 },
        final_max_speed_m_s: last.max_speed_m_s,
        reason: match (first_settled, verdict_at_end) {
            (Some(_), _) => None,
            (None, Some(Err(why))) => Some(why),
            (None, _) => Some("no window passed every criterion".into()),
        },
    }
}

/// The smallest and largest kinetic energy of the window that test 2 reads:
/// the translational energy in a bed of spheres, else the total.
fn min_max(window: &[EnergySample], spheres: bool) -> (f64, f64) {
    let ke = |s: &EnergySample| if spheres { s.kinetic_translational_j } else { s.kinetic_j };
    window.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), s| (lo.min(ke(s)), hi.max(ke(s))))
}

fn window_verdict(window: &[EnergySample], t0: f64, c: &SettleCriteria, final_count: u32) -> Result<(), String> {
    let now = window[window.len() - 1];
    if now.time_s - t0 < c.window_s {
        return Err(format!("the run is shorter than the window ({:.3} s < {} s)", now.time_s - t0, c.window_s));
    }
    if window.iter().any(|s| s.pellets != final_count) {
        return Err("pellets were still being added during the window".into());
    }
    let (lo, hi) = min_max(window, c.spheres);
    let at_rest =
        hi <= REST_FRACTION * c.ke_bound_j && window.iter().all(|s| s.max_speed_m_s <= REST_FRACTION * c.max_speed_m_s);
    if !at_rest && hi - lo > c.relative_tolerance * hi && hi - lo > c.ke_bound_j * c.relative_tolerance {
        return Err(format!(
            "{}kinetic energy still changes by {:.3e} of its value over {} s (tolerance {:.1e})",
            if c.spheres { "translational " } else { "" },
            (hi - lo) / hi,
            c.window_s,
            c.relative_tolerance
        ));
    }
    if now.kinetic_translational_j > c.ke_bound_j {
        return Err(format!(
            "translational kinetic energy {:.3e} J is above the bound {:.3e} J",
            now.kinetic_translational_j, c.ke_bound_j
        ));
    }
    if now.max_speed_m_s > c.max_speed_m_s {
        return Err(format!(
            "a pellet still moves at {:.3e} m/s (bound {:.1e} m/s)",
            now.max_speed_m_s, c.max_speed_m_s
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn criteria() -> SettleCriteria {
        SettleCriteria {
            window_s: 0.1,
            relative_tolerance: 1e-3,
            ke_bound_j: 1e-6,
            max_speed_m_s: 1e-3,
            spheres: false,
        }
    }

    /// KE decaying as e^(−t/τ): settled once the window's relative change
    /// 1 − e^(−w/τ) ... is below tolerance is impossible for pure decay, so
    /// the energy bound and the floor decide; check the exact crossing time.
    #[test]
    fn decaying_energy_settles_when_it_drops_below_the_bound() {
        let dt = 1e-3;
        let history: Vec<EnergySample> = (0..2000)
            .map(|k| {
                let t = k as f64 * dt;
                let ke = 1e-3 * (-t / 0.05).exp();
                // Pellets still moving (above the rest speed): the floor decides, not rest.
                EnergySample { time_s: t, kinetic_j: ke, kinetic_translational_j: ke, max_speed_m_s: 5e-4, pellets: 10 }
            })
            .collect();
        let report = check_settled(&history, &criteria());
        assert!(report.settled);
        // KE ≤ 1e-6 J from t = 0.05·ln(1000) = 0.3454 s; the window's absolute change
        // is then below 1e-9 J (the floor) only once KE(t − w) − KE(t) ≤ 1e-9, i.e.
        // KE(t)·(e^(w/τ) − 1) ≤ 1e-9 → KE(t) ≤ 1e-9 / (e² − 1) → t ≥ 0.05·ln(1e-3·(e²−1)/1e-9).
        let expected = 0.05 * (1e-3 * ((2.0f64).exp() - 1.0) / 1e-9).ln();
        let t = report.settle_time_s.unwrap();
        assert!((t - expected).abs() <= 2.0 * dt, "settled at {t}, expected {expected}");
    }

    #[test]
    fn constant_spin_is_settled_but_sliding_is_not() {
        // A pellet spinning in place: constant KE (above the bound), all of it rotational.
        let spin: Vec<EnergySample> = (0..300)
            .map(|k| EnergySample {
                time_s: k as f64 * 1e-3,
                kinetic_j: 5e-7,
                kinetic_translational_j: 0.0,
                max_speed_m_s: 0.0,
                pellets: 1,
            })
            .collect();
        let r = check_settled(&spin, &criteria());
        assert!(r.settled);
        assert!((r.settle_time_s.unwrap() - 0.1).abs() < 1.5e-3);
        // Sliding at constant speed: constant KE but the speed criterion fails.
        let slide: Vec<EnergySample> = spin.iter().map(|s| EnergySample { max_speed_m_s: 0.01, ..*s }).collect();
        let r = check_settled(&slide, &criteria());
        assert!(!r.settled);
        assert!(r.reason.unwrap().contains("moves at"));
        // The same energy as slow translation (many pellets creeping) is not settled.
        // (Above the 1e-6 J bound, below the 1 mm/s speed bound.)
        let creep: Vec<EnergySample> = spin
            .iter()
            .map(|s| EnergySample { kinetic_j: 5e-6, kinetic_translational_j: 5e-6, max_speed_m_s: 5e-4, ..*s })
            .collect();
        let r = check_settled(&creep, &criteria());
        assert!(!r.settled);
        assert!(r.reason.unwrap().contains("translational kinetic energy"));
    }

    #[test]
    fn a_decaying_sphere_spin_settles_a_sphere_bed_only() {
        // Rotational energy decaying 2 % per second (a spin against noise-level friction),
        // translational energy constant and small: the total's variation over the window
        // (2e-3) exceeds the tolerance, the translational energy's does not.
        let spin: Vec<EnergySample> = (0..1000)
            .map(|k| {
                let t = k as f64 * 1e-3;
                let trans = 1e-9;
                EnergySample {
                    time_s: t,
                    kinetic_j: trans + 1e-4 * (-0.02 * t).exp(),
                    kinetic_translational_j: trans,
                    max_speed_m_s: 1e-5,
                    pellets: 7,
                }
            })
            .collect();
        let r = check_settled(&spin, &criteria());
        assert!(!r.settled);
        assert!(r.reason.unwrap().starts_with("kinetic energy still changes"));
        let spheres = SettleCriteria { spheres: true, ..criteria() };
        let r = check_settled(&spin, &spheres);
        assert!(r.settled);
        assert!((r.settle_time_s.unwrap() - 0.1).abs() < 1.5e-3, "{:?}", r.settle_time_s);
        // Translational energy that still changes (below the bound) keeps a sphere bed unsettled.
        let creeping: Vec<EnergySample> =
            spin.iter().map(|s| EnergySample { kinetic_translational_j: 1e-7 * (1.0 + s.time_s), ..*s }).collect();
        let r = check_settled(&creeping, &spheres);
        assert!(!r.settled);
        assert!(r.reason.unwrap().starts_with("translational kinetic energy still changes"));
    }

    #[test]
    fn a_pellet_added_inside_the_window_defers_settling() {
        let history: Vec<EnergySample> = (0..400)
            .map(|k| {
                let t = k as f64 * 1e-3;
                let pellets = if t < 0.2 { 4 } else { 5 };
                EnergySample { time_s: t, kinetic_j: 0.0, kinetic_translational_j: 0.0, max_speed_m_s: 0.0, pellets }
            })
            .collect();
        let r = check_settled(&history, &criteria());
        assert!(r.settled);
        assert!(r.settle_time_s.unwrap() >= 0.3 - 1e-9, "{:?}", r.settle_time_s);
    }

    /// A bed at rest whose energy is noise (relative jitter of order 1) is settled; the same
    /// jitter with a pellet above the rest speed, or more energy, is not.
    #[test]
    fn a_bed_at_rest_settles_whatever_the_jitter_of_its_noise() {
        let c = SettleCriteria { spheres: true, ..criteria() };
        let history = |ke: f64, speed: f64| -> Vec<EnergySample> {
            (0..500)
                .map(|k| {
                    let jitter = if k % 7 == 0 { 0.1 } else { 1.0 };
                    EnergySample {
                        time_s: k as f64 * 1e-3,
                        kinetic_j: ke * jitter,
                        kinetic_translational_j: ke * jitter,
                        max_speed_m_s: speed,
                        pellets: 3,
                    }
                })
                .collect()
        };
        let r = check_settled(&history(5e-2 * c.ke_bound_j, 3e-5), &c);
        assert_eq!(r.settle_time_s, Some(0.1), "{r:?}");
        assert!(!check_settled(&history(5e-2 * c.ke_bound_j, 2e-4), &c).settled);
        assert!(!check_settled(&history(0.2 * c.ke_bound_j, 3e-5), &c).settled);
    }

    #[test]
    fn short_or_empty_histories_are_not_settled() {
        assert!(!check_settled(&[], &criteria()).settled);
        let short = [EnergySample {
            time_s: 0.0,
            kinetic_j: 0.0,
            kinetic_translational_j: 0.0,
            max_speed_m_s: 0.0,
            pellets: 1,
        }];
        let r = check_settled(&short, &criteria());
        assert!(!r.settled);
        assert!(r.reason.unwrap().contains("shorter than the window"));
    }

    #[test]
    fn bad_criteria_name_the_flag() {
        let mut c = criteria();
        c.window_s = -1.0;
        assert!(c.validate().unwrap_err().contains("--settle-window"));
    }
}
