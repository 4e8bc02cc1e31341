//! Every parameter of a `pack` run, from flags and case files.
//!
//! [`PackOptions`] holds what the user typed (mm, s, degrees; every field
//! optional); a case file (TOML or JSON, keys spelled like the flags:
//! `tube-diameter = 69.83`) gives one, the command line another, and
//! [`PackOptions::overlay`] lets the flags win. [`PackConfig::resolve`]
//! fills in the defaults — the paper's validation values — checks every
//! range and converts to SI.

use serde::{Deserialize, Serialize};

use crate::driver::STEP_S;
use crate::keys;
use crate::loading::LoadingScheme;
use pellet_geom::math::shown;
use pellet_sim::EngineParams;
pub use pellet_sim::Stepper;

/// Most pellets a bed may hold: checked before anything is allocated for them (a million
/// pellets take a few GB with their contacts; four billion aborted the allocator).
pub const MAX_COUNT: u32 = 1_000_000;

/// Largest tube diameter and fill height, mm: mkpellet's largest pellet size. A larger tube is
/// a typing slip, and a run in it would never end (the pellets fall and spread for ever).
pub const MAX_LENGTH_MM: f64 = 1e4;
use crate::ConfigError;

/// Parameters as typed (lengths in mm, times in s, angles in degrees).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case", deny_unknown_fields)]
pub struct PackOptions {
    /// Pellet file.
    pub pellet: Option<String>,
    /// Output trajectory.
    pub output: Option<String>,
    /// Tube inner diameter (mm).
    pub tube_diameter: Option<f64>,
    /// Number of pellets.
    pub count: Option<u32>,
    /// Fill until the settled bed reaches this height (mm).
    pub fill_height: Option<f64>,
    /// Random seed.
    pub seed: Option<u64>,
    /// Pellet–pellet coefficient of restitution.
    pub cor: Option<f64>,
    /// Pellet–pellet friction coefficient.
    pub friction: Option<f64>,
    /// Pellet–wall and pellet–floor coefficient of restitution.
    pub wall_cor: Option<f64>,
    /// Pellet–wall and pellet–floor friction coefficient.
    pub wall_friction: Option<f64>,
    /// Pellet density (kg/m³).
    pub density: Option<f64>,
    /// Height of a new pellet's centre above the bed top (mm).
    pub drop_height: Option<f64>,
    /// Height above the floor at which pellets enter, the top of the tube they are poured
    /// into (mm); `drop_height` above the bed once the bed comes within it.
    pub release_height: Option<f64>,
    /// Interval between recorded pose frames (s).
    pub record_every: Option<f64>,
    /// Interval between checkpoints (simulated s; 0: only at the end).
    pub checkpoint_every: Option<f64>,
    /// Simulated time limit (s).
    pub max_time: Option<f64>,
    /// Loading scheme.
    pub scheme: Option<LoadingScheme>,
    /// Tilt of the pellet axis from vertical in the column schemes (degrees).
    pub tilt: Option<f64>,
    /// Largest horizontal disturbance of the entry point (fraction of dp).
    pub position_jitter: Option<f64>,
    /// Largest disturbance of the entry orientation (degrees).
    pub angle_jitter: Option<f64>,
    /// Shortest time between two pellets entering (s).
    pub spacing: Option<f64>,
    /// Settle-test window (s).
    pub settle_window: Option<f64>,
    /// Settle-test relative tolerance on the kinetic-energy change.
    pub settle_tolerance: Option<f64>,
    /// Settle-test bound on the fastest pellet's speed (m/s).
    pub max_speed: Option<f64>,
    /// Record velocities in the pose frames.
    pub record_velocities: Option<bool>,
    /// Contact model.
    pub contact_model: Option<ContactModel>,
    /// εp, the resting band of relative normal speed (m/s).
    pub resting_band: Option<f64>,
    /// The friction clamp rule (overrides the contact model's).
    pub friction_clamp: Option<ClampRule>,
    /// Also write the Foxglove viewer channels.
    pub foxglove: Option<bool>,
    /// The engine's time-stepping scheme.
    pub stepper: Option<Stepper>,
    /// Radius of the patch a contact point stands for, in pellet diameters (velocity-level stepper).
    pub contact_patch: Option<f64>,
    /// Largest relative surface travel of a near pair over one step, in pellet diameters
    /// (velocity-level stepper).
    pub step_travel: Option<f64>,
    /// Longest step (s; velocity-level stepper).
    pub max_step: Option<f64>,
    /// Factor on the force-level stepper's substep rule (its slip per substep and its cap).
    pub substep_scale: Option<f64>,
    /// Threads of the engine (default: the machine's cores).
    pub threads: Option<u32>,
}

/// Which contact model the engine uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ContactModel {
    /// The paper's model: dynamic Coulomb friction only (none below the slip
    /// threshold εf), no velocity bias.
    Paper,
    /// The recommended model: static friction at resting contacts, the
    /// stick clamp, and the velocity bias that removes drift at resting contacts.
    Recommended,
}

/// What friction does where it would reverse a contact's slip within a substep (the "friction
/// rule" whose effect on porosity a sensitivity study reports).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ClampRule {
    /// Clamp it to the force or impulse that stops the slip (the recommended model's rule).
    Stick,
    /// Drop it (the literal reading of the paper; the paper model's rule).
    Zero,
}

fn recorded_resting_band() -> f64 {
    5e-3
}

macro_rules! overlay_fields {
    ($base:ident, $over:ident, $($f:ident),*) => {
        PackOptions { $($f: $over.$f.or($base.$f)),* }
    };
}

impl PackOptions {
    /// The file paths of a case file read from `case_path`: a relative `pellet` or `output`
    /// names a file beside the case file, wherever `pack` runs (as `include` in a Makefile or
    /// a path in Cargo.toml). A case read from stdin (`-`) keeps them relative to the working
    /// directory, as flags are.
    pub fn relative_to_case_file(mut self, case_path: &str) -> Self {
        if case_path == "-" {
            return self;
        }
        let dir = std::path::Path::new(case_path).parent().unwrap_or(std::path::Path::new(""));
        for file in [&mut self.pellet, &mut self.output].into_iter().flatten() {
            if file != "-" && std::path::Path::new(file.as_str()).is_relative() {
                *file = dir.join(file.as_str()).to_string_lossy().into_owned();
            }
        }
        self
    }

    /// `self` with every field that `over` sets replaced by `over`'s.
    pub fn overlay(self, over: PackOptions) -> PackOptions {
        let base = self;
        overlay_fields!(
            base,
            over,
            pellet,
            output,
            tube_diameter,
            count,
            fill_height,
            seed,
            cor,
            friction,
            wall_cor,
            wall_friction,
            density,
            drop_height,
            release_height,
            record_every,
            checkpoint_every,
            max_time,
            scheme,
            tilt,
            position_jitter,
            angle_jitter,
            spacing,
            settle_window,
            settle_tolerance,
            max_speed,
            record_velocities,
            contact_model,
            resting_band,
            friction_clamp,
            foxglove,
            stepper,
            contact_patch,
            step_travel,
            max_step,
            substep_scale,
            threads
        )
    }
}

/// How much to load.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Amount {
    /// This many pellets.
    Count(u32),
    /// Until the bed top reaches this height (m).
    FillHeight(f64),
}

/// A resolved run configuration, SI units. Serialised into the trajectory's metadata.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PackConfig {
    /// Pellet file path.
    pub pellet: String,
    /// Tube inner diameter (m).
    pub tube_diameter_m: f64,
    /// How much to load.
    pub amount: Amount,
    /// Random seed.
    pub seed: u64,
    /// Pellet–pellet restitution.
    pub cor: f64,
    /// Pellet–pellet friction.
    pub friction: f64,
    /// Pellet–wall/floor restitution.
    pub wall_cor: f64,
    /// Pellet–wall/floor friction.
    pub wall_friction: f64,
    /// Density (kg/m³).
    pub density_kg_m3: f64,
    /// Drop height above the bed top (m).
    pub drop_height_m: f64,
    /// Height above the floor at which pellets enter while the bed is lower than it by more
    /// than the drop height (m): pellets poured in at the top of the tube. Configurations
    /// recorded before it existed read as none, the rule that wrote them.
    #[serde(default)]
    pub release_height_m: Option<f64>,
    /// Frame interval (s).
    pub record_every_s: f64,
    /// Time limit (s).
    pub max_time_s: f64,
    /// Loading scheme.
    pub scheme: LoadingScheme,
    /// Tilt (rad).
    pub tilt_rad: f64,
    /// Position disturbance (fraction of dp).
    pub position_jitter_dp: f64,
    /// Orientation disturbance (rad).
    pub angle_jitter_rad: f64,
    /// Minimum time between entries (s).
    pub spacing_s: f64,
    /// Settle window (s).
    pub settle_window_s: f64,
    /// Settle tolerance (relative).
    pub settle_tolerance: f64,
    /// Settle speed bound (m/s).
    pub max_speed_m_s: f64,
    /// Whether frames carry velocities.
    pub record_velocities: bool,
    /// The contact model.
    pub contact_model: ContactModel,
    /// εp (m/s); also εf, and the substep cap is εp / (2 g). Archives written before it
    /// existed read as 5e-3 m/s, the value that wrote them.
    #[serde(default = "recorded_resting_band")]
    pub resting_band_m_s: f64,
    /// The friction clamp rule, if it overrides the contact model's.
    #[serde(default)]
    pub friction_clamp: Option<ClampRule>,
    /// Whether the trajectory carries the Foxglove viewer channels.
    pub foxglove: bool,
    /// Interval between checkpoints in the trajectory (simulated s; 0: only at the end).
    /// Configurations recorded before it existed read as 1 s.
    #[serde(default = "default_checkpoint_every")]
    pub checkpoint_every_s: f64,
    /// The engine's time-stepping scheme. Archives written before there was a choice read as
    /// `acceleration`, the scheme that wrote them.
    #[serde(default = "Stepper::recorded_default")]
    pub stepper: Stepper,
    /// Radius of the patch a contact point stands for under the velocity-level stepper, as a
    /// fraction of the pellet diameter (0: contact points turn freely). Archives
    /// written before it existed read as 0, the model that wrote them.
    #[serde(default)]
    pub contact_patch_dp: f64,
    /// The velocity-level stepper's largest relative surface travel of a near pair over one
    /// step, as a fraction of the pellet diameter. Archives written before it was a setting
    /// read as 0.025, the value that wrote them.
    #[serde(default = "recorded_step_travel")]
    pub step_travel_dp: f64,
    /// The velocity-level stepper's longest step (s). Archives written before it was a setting
    /// read as 1.25 ms, the value that wrote them.
    #[serde(default = "recorded_max_step")]
    pub max_step_s: f64,
    /// Factor on the force-level stepper's substep rule: its slip per substep (0.2λ) and its
    /// cap. Archives written before it existed read as 1, the rule that wrote them.
    #[serde(default = "recorded_substep_scale")]
    pub substep_scale: f64,
    /// Threads of the engine. Any number gives the same bed bit for bit, so a run may resume
    /// with another (`checkpoint::MAY_CHANGE`); it is recorded to tell what the run's times
    /// were measured with. Archives written before it was a setting read as 1, the one thread
    /// that wrote them.
    #[serde(default = "recorded_threads")]
    pub threads: u32,
}

fn recorded_threads() -> u32 {
    1
}

fn recorded_substep_scale() -> f64 {
    1.0
}

/// Most threads `--threads` takes.
pub const MAX_THREADS: u32 = 1024;

/// The threads of a run that does not choose: the cores this process may use (1 if unknown).
pub fn default_threads() -> u32 {
    std::thread::available_parallelism().map_or(1, |n| u32::try_from(n.get()).unwrap_or(MAX_THREADS).min(MAX_THREADS))
}

fn recorded_step_travel() -> f64 {
    0.025
}

fn recorded_max_step() -> f64 {
    1.25e-3
}

fn default_checkpoint_every() -> f64 {
    DEFAULT_CHECKPOINT_EVERY_S
}

/// Default of `--checkpoint-every` (simulated s). A checkpoint holds every body (~270 bytes
/// each) and the warm forces (~60 bytes per contact), ~0.2 MB before compression for 300
/// cylinders; the frames of such a bed take ~0.9 MB per simulated second (the paper's
/// 69.83 mm cylinder bed: 15.9 MB for 17.9 s).
pub const DEFAULT_CHECKPOINT_EVERY_S: f64 = 1.0;

/// `v` if it is in the flag's range ([`keys::KEYS`], the case file's too), or the message.
fn check(flag: &str, v: f64) -> Result<f64, ConfigError> {
    let r = keys::range(flag);
    if r.holds(v) {
        Ok(v)
    } else {
        let open = if r.lo_open { "(" } else { "[" };
        let hi_txt = if r.hi.is_infinite() { "∞)".to_string() } else { format!("{}]", r.hi) };
        Err(ConfigError(format!("--{flag} must be in {open}{}, {hi_txt}{} (got {})", r.lo, r.unit, shown(v))))
    }
}

/// A time (s) that the run can honour: frames and the time limit fall on engine steps of
/// [`STEP_S`], so a shorter time, or one between two steps, would silently become another.
fn whole_steps(flag: &str, v: f64) -> Result<f64, ConfigError> {
    let v = check(flag, v)?;
    let steps = (v / STEP_S).round();
    if steps < 1.0 || (steps * STEP_S - v).abs() > 1e-9 * v.max(1.0) {
        let time = |steps: f64| {
            let t = format!("{:.3}", steps.max(1.0) * STEP_S);
            t.trim_end_matches('0').trim_end_matches('.').to_string()
        };
        let (below, above) = (time((v / STEP_S).floor()), time((v / STEP_S).ceil()));
        let nearest = if below == above { below } else { format!("{below} or {above}") };
        return Err(ConfigError(format!(
            "--{flag} must be a whole number of the {STEP_S} s engine steps (at least {STEP_S} s; got {} s): give {nearest}",
            shown(v)
        )));
    }
    Ok(v)
}

impl PackConfig {
    /// Defaults, checks and unit conversion. The defaults are the paper's
    /// validation values (density 8030 kg/m³, COR 0.9 and μ 0.1 between
    /// pellets, 0.6 and 0.6 at the wall), one column with a 45° tilt.
    pub fn resolve(o: &PackOptions) -> Result<PackConfig, ConfigError> {
        let mm = 1e-3;
        let pellet =
            o.pellet.clone().ok_or_else(|| ConfigError("--pellet is required (a file made by mkpellet)".into()))?;
        let tube = o.tube_diameter.ok_or_else(|| ConfigError("--tube-diameter is required (mm)".into()))?;
        let amount = match (o.count, o.fill_height) {
            (Some(_), Some(_)) => return Err(ConfigError("give either --count or --fill-height, not both".into())),
            (Some(0), None) => return Err(ConfigError("--count must be at least 1".into())),
            (Some(n), None) if n > MAX_COUNT => {
                return Err(ConfigError(format!(
                    "--count must be in [1, {MAX_COUNT}] (got {n}): a bed of more pellets does not fit in memory here"
                )))
            }
            (Some(n), None) => Amount::Count(n),
            (None, Some(h)) => Amount::FillHeight(check("fill-height", h)? * mm),
            (None, None) => return Err(ConfigError("give --count N or --fill-height MM".into())),
        };
        let scheme = o.scheme.unwrap_or(LoadingScheme::OneColumn);
        if scheme == LoadingScheme::Batch && matches!(amount, Amount::FillHeight(_)) {
            return Err(ConfigError(
                "the batch scheme places every pellet at once: give --count N instead of --fill-height".into(),
            ));
        }
        // The engine's settings default to the engine's own (`engine_params` of a run that sets
        // none of them is `EngineParams::default()`).
        let engine = EngineParams::default();
        Ok(PackConfig {
            pellet,
            tube_diameter_m: check("tube-diameter", tube)? * mm,
            amount,
            seed: o.seed.unwrap_or(1),
            cor: check("cor", o.cor.unwrap_or(0.9))?,
            friction: check("friction", o.friction.unwrap_or(0.1))?,
            wall_cor: check("wall-cor", o.wall_cor.unwrap_or(0.6))?,
            wall_friction: check("wall-friction", o.wall_friction.unwrap_or(0.6))?,
            density_kg_m3: check("density", o.density.unwrap_or(8030.0))?,
            drop_height_m: check("drop-height", o.drop_height.unwrap_or(30.0))? * mm,
            release_height_m: match o.release_height {
                Some(_) if scheme == LoadingScheme::Batch => {
                    return Err(ConfigError(
                        "--release-height is where pellets poured one at a time enter; the batch scheme places \
                         every pellet at once: leave it out or choose another --scheme"
                            .into(),
                    ))
                }
                Some(h) => Some(check("release-height", h)? * mm),
                None => None,
            },
            record_every_s: whole_steps("record-every", o.record_every.unwrap_or(0.01))?,
            max_time_s: whole_steps("max-time", o.max_time.unwrap_or(120.0))?,
            scheme,
            tilt_rad: check("tilt", o.tilt.unwrap_or(45.0))?.to_radians(),
            position_jitter_dp: check("position-jitter", o.position_jitter.unwrap_or(0.1))?,
            angle_jitter_rad: check("angle-jitter", o.angle_jitter.unwrap_or(5.0))?.to_radians(),
            spacing_s: check("spacing", o.spacing.unwrap_or(0.02))?,
            settle_window_s: check("settle-window", o.settle_window.unwrap_or(0.15))?,
            settle_tolerance: check("settle-tolerance", o.settle_tolerance.unwrap_or(1e-3))?,
            max_speed_m_s: check("max-speed", o.max_speed.unwrap_or(1e-3))?,
            record_velocities: o.record_velocities.unwrap_or(false),
            foxglove: o.foxglove.unwrap_or(false),
            checkpoint_every_s: match o.checkpoint_every {
                Some(v) => check("checkpoint-every", v)?,
                None => DEFAULT_CHECKPOINT_EVERY_S,
            },
            // Measured: in the paper's model a poured bed never settles (it
            // keeps turning about the axis and rattling in the resting band);
            // see the README's known limits.
            contact_model: o.contact_model.unwrap_or(ContactModel::Recommended),
            resting_band_m_s: check("resting-band", o.resting_band.unwrap_or(engine.eps_p))?,
            friction_clamp: o.friction_clamp,
            stepper: o.stepper.unwrap_or(engine.stepper),
            contact_patch_dp: check("contact-patch", o.contact_patch.unwrap_or(engine.velocity.patch_radius))?,
            step_travel_dp: check("step-travel", o.step_travel.unwrap_or(engine.velocity.travel))?,
            max_step_s: check("max-step", o.max_step.unwrap_or(engine.velocity.max_step))?,
            substep_scale: check("substep-scale", o.substep_scale.unwrap_or(1.0))?,
            threads: match o.threads {
                Some(n) if !(1..=MAX_THREADS).contains(&n) => {
                    return Err(ConfigError(format!("--threads must be in [1, {MAX_THREADS}] (got {n})")))
                }
                Some(n) => n,
                None => default_threads(),
            },
        })
    }
}

#[cfg(test)]
mod tests;
