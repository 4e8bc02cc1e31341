//! `pack`'s command line: its flags, their help and examples, and the options they give.

use clap::Parser;
use pellet_pack::{ClampRule, ContactModel, LoadingScheme, PackOptions};

const EXAMPLES: &str = "\
Examples:
  pack --pellet c.pellet --tube-diameter 69.83 --fill-height 120 --seed 1 -o bed.mcap
  pack --pellet s.pellet --tube-diameter 40 --count 40 -o small.mcap --quiet
  pack --case cases/cyl-N7.toml --seed 3 -o bed.mcap      (flags override the case file)
  pack --pellet r.pellet --tube-diameter 40.45 --count 200 --scheme four-columns --cor 0.6 -o r.mcap
  pack --pellet s.pellet --tube-diameter 100 --count 1000 --scheme batch -o t14.mcap
  pack --case cases/cyl-N7.toml -o bed.mcap --resume      (go on after a kill or an interrupt)
  pack --case cases/cyl-N7.toml -o bed.mcap --resume --max-time 60   (or past the time limit)
  pack --case cases/cyl-N7.toml -o bed.mcap --park parked.mcap   (a small copy to resume elsewhere)

A case file (TOML, or JSON starting with '{') holds any of the flags below,
spelled the same: tube-diameter = 69.83, fill-height = 120, scheme = \"sock\", ...
Relative paths in it (pellet, output) are relative to the case file's directory.
Lengths in mm, times in s, angles in degrees. Then: settle-check bed.mcap -o bed.packing.
Exit codes: 0 settled, 1 not settled within --max-time (as settle-check's 1), 2 error
(also: interrupted). After a 1 or an interrupt the trajectory is complete and readable,
and --resume continues it; after an interrupt, pack without --resume refuses to start over it.";

/// Drop pellets into a tube with the hard-contact rigid-body engine until the
/// bed settles, streaming the trajectory to an MCAP file.
#[derive(Debug, Parser)]
#[command(name = "pack", version = pellet_cli::LONG_VERSION, after_help = EXAMPLES, allow_negative_numbers = true)]
pub struct Args {
    /// Case file (TOML or JSON) with any of the parameters below.
    #[arg(long, value_name = "FILE")]
    pub(crate) case: Option<String>,
    /// Pellet file made by mkpellet.
    #[arg(long, value_name = "FILE")]
    pellet: Option<String>,
    /// Trajectory to write (MCAP) [required here or in the case file].
    #[arg(short, long, value_name = "FILE")]
    output: Option<String>,
    /// Tube inner diameter (mm, at most 10000).
    #[arg(long, value_name = "MM")]
    tube_diameter: Option<f64>,
    /// Number of pellets to load, 1 to 1000000.
    #[arg(long, value_name = "N")]
    count: Option<u32>,
    /// Or: load until the bed surface reaches this height (mm, at most 10000).
    #[arg(long, value_name = "MM")]
    fill_height: Option<f64>,
    /// Random seed (disturbances, scheme positions) [default: 1].
    #[arg(long)]
    seed: Option<u64>,
    /// Pellet–pellet coefficient of restitution, 0–1 [default: 0.9].
    #[arg(long)]
    cor: Option<f64>,
    /// Pellet–pellet friction coefficient [default: 0.1].
    #[arg(long)]
    friction: Option<f64>,
    /// Pellet–wall and pellet–floor coefficient of restitution, 0–1 [default: 0.6].
    #[arg(long)]
    wall_cor: Option<f64>,
    /// Pellet–wall and pellet–floor friction coefficient [default: 0.6].
    #[arg(long)]
    wall_friction: Option<f64>,
    /// Pellet density (kg/m³) [default: 8030].
    #[arg(long, value_name = "KG/M3")]
    density: Option<f64>,
    /// Height of a new pellet's centre above the bed surface, or the floor (mm) [default: 30].
    #[arg(long, value_name = "MM")]
    drop_height: Option<f64>,
    /// Height above the floor at which pellets enter, as when they are poured in at the top of a
    /// tube of that length (mm); once the bed surface is within --drop-height of it they enter
    /// --drop-height above the surface. Higher falls pack narrow tubes denser. Not with the
    /// batch scheme [default: none, always --drop-height above the surface].
    #[arg(long, value_name = "MM")]
    release_height: Option<f64>,
    /// Loading scheme [default: one-column].
    #[arg(long, value_enum)]
    scheme: Option<SchemeArg>,
    /// Tilt of the pellet axis from vertical in the column schemes (degrees) [default: 45].
    #[arg(long, value_name = "DEG")]
    tilt: Option<f64>,
    /// Largest random horizontal shift of the entry point (fraction of dpv, e.g. 0.8) [default: 0.1].
    #[arg(long, value_name = "FRACTION")]
    position_jitter: Option<f64>,
    /// Largest random rotation of the entry orientation (degrees, e.g. 45) [default: 5].
    #[arg(long, value_name = "DEG")]
    angle_jitter: Option<f64>,
    /// Shortest time between two pellets entering (s) [default: 0.02].
    #[arg(long, value_name = "S")]
    spacing: Option<f64>,
    /// Interval between recorded pose frames (s; a whole number of the 0.005 s engine steps) [default: 0.01].
    #[arg(long, value_name = "S")]
    record_every: Option<f64>,
    /// Record pellet velocities in the pose frames.
    #[arg(long)]
    record_velocities: bool,
    /// Also write Foxglove viewer channels (/foxglove/scene, /foxglove/transforms) to
    /// replay the run in Foxglove or Lichtblick's 3D panel (about 60 bytes per pellet per frame, compressed).
    #[arg(long)]
    foxglove: bool,
    /// Contact model: `recommended` (static friction at resting contacts, stick
    /// clamp, velocity bias; settles beds) or `paper` (dynamic friction only) [default: recommended].
    #[arg(long, value_enum)]
    contact_model: Option<ModelArg>,
    /// εp, the resting band: a contact whose relative normal speed is at most this rests
    /// (normal forces), faster approaches collide (impulses) (m/s) [default: 0.005]. Also sets εf,
    /// the slip speed below which friction is static, and caps the substep at εp / (2 g).
    #[arg(long, value_name = "M/S")]
    resting_band: Option<f64>,
    /// Friction rule where friction would reverse a contact's slip within a substep: `stick`
    /// stops the slip, `zero` drops the friction [default: the contact model's, stick for
    /// recommended, zero for paper].
    #[arg(long, value_enum)]
    friction_clamp: Option<ClampArg>,
    /// Time-stepping scheme: `velocity` (one impulse solve per step of up to 1.25 ms) or
    /// `acceleration` (the paper's force-level substeps, at most 0.25 ms each, for reproducing
    /// the paper) [default: velocity; --resume without it continues a run with its own].
    #[arg(long, value_enum)]
    stepper: Option<StepperArg>,
    /// Under the velocity-level stepper, the radius of the patch each contact point stands for,
    /// in pellet diameters: the spin of the contact is bounded by the patch's Coulomb torque
    /// (3π/16) μ a N and its rolling (except between two spheres) by a N, so that a pellet held
    /// at one or two points comes to rest; 0 lets contact points turn freely [default: 0.001;
    /// --resume without it continues a run with its own].
    #[arg(long, value_name = "DP")]
    contact_patch: Option<f64>,
    /// Under the velocity-level stepper, the largest relative surface travel of a touching or
    /// closing pair over one step, in pellet diameters; with --max-step it sets the step, and
    /// halving both checks that a bed does not depend on it [default: 0.0125; --resume
    /// without it continues a run with its own].
    #[arg(long, value_name = "DP")]
    step_travel: Option<f64>,
    /// Under the velocity-level stepper, the longest step (s) [default: 0.00125; --resume
    /// without it continues a run with its own].
    #[arg(long, value_name = "S")]
    max_step: Option<f64>,
    /// Under the force-level stepper, a factor (0 to 1) on its substep rule: the slip per
    /// substep (0.2 of the contact band) and the substep's cap; halving it checks that a bed
    /// does not depend on the substep [default: 1].
    #[arg(long, value_name = "F")]
    substep_scale: Option<f64>,
    /// Threads of the engine, 1 to 1024 (1: one thread). Any number gives the same bed bit for
    /// bit; --resume may change it. Contact generation, the impulse solve, integration and
    /// projection's first pass run on them, the rest of a step on one [default: the machine's
    /// cores].
    #[arg(long, value_name = "N")]
    threads: Option<u32>,
    /// Simulated time limit (s; a whole number of the 0.005 s engine steps) [default: 120].
    #[arg(long, value_name = "S")]
    max_time: Option<f64>,
    /// Settle-test window (s) [default: 0.15].
    #[arg(long, value_name = "S")]
    settle_window: Option<f64>,
    /// Settle-test tolerance on the kinetic-energy change over the window (fraction) [default: 0.001].
    #[arg(long, value_name = "FRACTION")]
    settle_tolerance: Option<f64>,
    /// Settle-test bound on the fastest pellet's speed (m/s) [default: 0.001].
    #[arg(long, value_name = "M/S")]
    max_speed: Option<f64>,
    /// Interval between checkpoints in the trajectory, simulated seconds (0: only at the end) [default: 1].
    #[arg(long, value_name = "S")]
    checkpoint_every: Option<f64>,
    /// Continue the run of this output from its last checkpoint: a killed run (`<output>.part`), or
    /// one that was interrupted or reached its --max-time (`<output>`; give a larger --max-time).
    /// The settings must be the run's own (--max-time, --checkpoint-every, --foxglove and --threads may change).
    /// The result equals the uninterrupted run frame for frame. A damaged chunk is skipped (its
    /// frames are missing); a partial run none of whose checkpoints reads is refused and kept.
    /// Without a partial run, or one killed before its first checkpoint, the run starts over.
    #[arg(long)]
    pub(crate) resume: bool,
    /// Instead of running: write the partial run of the output (as --resume would find it) to
    /// FILE, keeping only what --resume needs (run metadata, pellet, energy records, the last
    /// frame and checkpoint; a few hundred kB where the run is tens of MB). Copy FILE to the
    /// output on another machine and `pack --resume` goes on from its checkpoint.
    #[arg(long, value_name = "FILE", conflicts_with = "resume")]
    pub(crate) park: Option<String>,
    /// Start over even when a killed run of this output (`<output>.part` or `<output>.resume`)
    /// or an interrupted one (`<output>`) is there: without --resume or --force, pack refuses
    /// and keeps it.
    #[arg(long, conflicts_with_all = ["resume", "park"])]
    pub(crate) force: bool,
    /// No progress output.
    #[arg(short, long)]
    pub(crate) quiet: bool,
}

/// Contact models, as spelled on the command line.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
enum ModelArg {
    /// The paper's model: dynamic Coulomb friction only, no velocity bias.
    Paper,
    /// Static friction at resting contacts, stick clamp, velocity bias.
    Recommended,
}

/// Time-stepping schemes, as spelled on the command line.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
enum StepperArg {
    /// The paper's force-level scheme.
    Acceleration,
    /// Velocity-level time stepping.
    Velocity,
}

/// Friction clamp rules, as spelled on the command line.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
enum ClampArg {
    /// Friction stops the slip (the recommended model's rule).
    Stick,
    /// Friction is dropped (the paper's rule).
    Zero,
}

/// Loading schemes, as spelled on the command line.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
enum SchemeArg {
    /// One column on the tube axis (the paper's scheme 1).
    OneColumn,
    /// Two columns equidistant from the axis.
    TwoColumns,
    /// Four columns equidistant from the axis.
    FourColumns,
    /// Sock loading: low drop, random places and orientations (loose beds).
    Sock,
    /// Dense loading: high drop, spread over the cross-section (dense beds).
    Dense,
    /// Every pellet at once, a loose random cloud released from rest (needs --count).
    Batch,
}

impl From<SchemeArg> for LoadingScheme {
    fn from(s: SchemeArg) -> Self {
        match s {
            SchemeArg::OneColumn => LoadingScheme::OneColumn,
            SchemeArg::TwoColumns => LoadingScheme::TwoColumns,
            SchemeArg::FourColumns => LoadingScheme::FourColumns,
            SchemeArg::Sock => LoadingScheme::Sock,
            SchemeArg::Dense => LoadingScheme::Dense,
            SchemeArg::Batch => LoadingScheme::Batch,
        }
    }
}

impl Args {
    pub(crate) fn options(&self) -> PackOptions {
        PackOptions {
            pellet: self.pellet.clone(),
            output: self.output.clone(),
            tube_diameter: self.tube_diameter,
            count: self.count,
            fill_height: self.fill_height,
            seed: self.seed,
            cor: self.cor,
            friction: self.friction,
            wall_cor: self.wall_cor,
            wall_friction: self.wall_friction,
            density: self.density,
            drop_height: self.drop_height,
            release_height: self.release_height,
            record_every: self.record_every,
            checkpoint_every: self.checkpoint_every,
            max_time: self.max_time,
            scheme: self.scheme.map(Into::into),
            tilt: self.tilt,
            position_jitter: self.position_jitter,
            angle_jitter: self.angle_jitter,
            spacing: self.spacing,
            settle_window: self.settle_window,
            settle_tolerance: self.settle_tolerance,
            max_speed: self.max_speed,
            record_velocities: self.record_velocities.then_some(true),
            foxglove: self.foxglove.then_some(true),
            resting_band: self.resting_band,
            friction_clamp: self.friction_clamp.map(|c| match c {
                ClampArg::Stick => ClampRule::Stick,
                ClampArg::Zero => ClampRule::Zero,
            }),
            stepper: self.stepper.map(|m| match m {
                StepperArg::Acceleration => pellet_pack::Stepper::Acceleration,
                StepperArg::Velocity => pellet_pack::Stepper::Velocity,
            }),
            contact_model: self.contact_model.map(|m| match m {
                ModelArg::Paper => ContactModel::Paper,
                ModelArg::Recommended => ContactModel::Recommended,
            }),
            contact_patch: self.contact_patch,
            step_travel: self.step_travel,
            max_step: self.max_step,
            substep_scale: self.substep_scale,
            threads: self.threads,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Args;
    use clap::{CommandFactory, Parser};
    use pellet_pack::PackConfig;

    /// The value `--help` states as a flag's default ("[default: V; ..." or "[default: V]").
    fn stated_default(flag: &str) -> f64 {
        let help = Args::command().render_long_help().to_string().replace('\n', " ");
        let after = help.split(&format!("--{flag} <")).nth(1).unwrap_or_else(|| panic!("--{flag} in --help"));
        let value = after.split("[default: ").nth(1).expect("a stated default");
        let value = value.split([';', ']']).next().unwrap();
        value.parse().unwrap_or_else(|e| panic!("--{flag}'s stated default {value}: {e}"))
    }

    #[test]
    fn help_states_the_engine_defaults_a_run_gets() {
        let args = Args::parse_from(["pack", "--pellet", "p.pellet", "--tube-diameter", "40", "--count", "10"]);
        let config = PackConfig::resolve(&args.options()).unwrap();
        assert_eq!(stated_default("step-travel"), config.step_travel_dp);
        assert_eq!(stated_default("max-step"), config.max_step_s);
        assert_eq!(stated_default("contact-patch"), config.contact_patch_dp);
    }
}
