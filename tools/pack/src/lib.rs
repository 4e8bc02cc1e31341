//! `pack`: drops pellets into a tube with the rigid-body engine and
//! streams the trajectory to an MCAP archive.

use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use anyhow::{bail, Context};
use clap::Parser;

use pellet_cli::Outcome;
use pellet_io::foxglove::ViewerShape;
use pellet_io::{Provenance, TrajectoryHeader, TrajectoryWriter};
use pellet_pack::{
    check_setup, resume_pack, Amount, ClampRule, ContactModel, Ending, LoadingScheme, PackConfig, PackOptions,
};

mod output_lock;
mod resume;
mod sink;

use sink::McapSink;

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
    case: Option<String>,
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
    /// in pellet diameters (not used between spheres): the spin of the contact is bounded by
    /// the patch's Coulomb torque (3π/16) μ a N and its rolling by a N, so that a pellet held at
    /// one or two points comes to rest; 0 lets contact points turn freely [default: 0.001;
    /// --resume without it continues a run with its own].
    #[arg(long, value_name = "DP")]
    contact_patch: Option<f64>,
    /// Under the velocity-level stepper, the largest relative surface travel of a touching or
    /// closing pair over one step, in pellet diameters; with --max-step it sets the step, and
    /// halving both checks that a bed does not depend on it [default: 0.025; --resume
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
    /// bit; --resume may change it. The contact generation runs on them, the rest of a
    /// step on one [default: the machine's cores].
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
    resume: bool,
    /// Instead of running: write the partial run of the output (as --resume would find it) to
    /// FILE, keeping only what --resume needs (run metadata, pellet, energy records, the last
    /// frame and checkpoint; a few hundred kB where the run is tens of MB). Copy FILE to the
    /// output on another machine and `pack --resume` goes on from its checkpoint.
    #[arg(long, value_name = "FILE", conflicts_with = "resume")]
    park: Option<String>,
    /// Start over even when a killed run of this output (`<output>.part` or `<output>.resume`)
    /// or an interrupted one (`<output>`) is there: without --resume or --force, pack refuses
    /// and keeps it.
    #[arg(long, conflicts_with_all = ["resume", "park"])]
    force: bool,
    /// No progress output.
    #[arg(short, long)]
    quiet: bool,
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
    fn options(&self) -> PackOptions {
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

/// Runs `pack`.
pub fn run(args: Args) -> anyhow::Result<Outcome> {
    let base = match &args.case {
        Some(path) => {
            let text =
                String::from_utf8(pellet_io::read_input(path)?).with_context(|| format!("{path}: not UTF-8 text"))?;
            PackOptions::from_case_file(&text, path)?.relative_to_case_file(path)
        }
        None => PackOptions::default(),
    };
    let options = base.overlay(args.options());
    let output =
        options.output.clone().context("give the trajectory file with -o FILE (or `output` in the case file)")?;
    let options = if args.resume || args.park.is_some() { resume::follow_recorded(options, &output) } else { options };
    let config = PackConfig::resolve(&options)?;
    if output == "-" {
        bail!("pack writes its trajectory to a file (it is renamed into place when complete); give -o FILE");
    }
    // Checked before the run, not found out after simulating the whole bed.
    check_output_path(&output)?;
    // The run writes <output>.part, .resume and .lock beside the output, and --park a copy.
    let written = [
        ("", "-o"),
        (".part", "-o (its partial run)"),
        (".resume", "-o (its resume file)"),
        (".lock", "-o (its lock)"),
    ]
    .into_iter()
    .map(|(suffix, flag)| (flag.to_string(), format!("{output}{suffix}")));
    let parked = args.park.iter().map(|p| ("--park".to_string(), p.clone()));
    // --park reads the partial run it copies: writing over it is destroying an input, which
    // is the first thing to say.
    let runs = ["", ".part", ".resume"].map(|suffix| format!("{output}{suffix}"));
    pellet_cli::refuse_overwriting_inputs(&runs, parked.clone())?;
    pellet_cli::refuse_clashing_outputs(args.case.iter().chain([&config.pellet]), written.chain(parked))?;
    // The run ends by printing where it settled (or where it parked the run): with stdout
    // closed that line would be lost, so refuse before the run rather than after it.
    pellet_io::require_stdout()?;
    let pellet_bytes = pellet_io::read_input(&config.pellet)?;
    let pellet = pellet_io::decode_pellet(&pellet_bytes, &config.pellet)?.pellet;

    let provenance = Provenance {
        tool: "pack".into(),
        version: env!("CARGO_PKG_VERSION").into(),
        args: std::env::args().skip(1).collect(),
    };
    let mut config_json = serde_json::to_value(&config)?;
    config_json["density_kg_m3"] = config.density_kg_m3.into();
    let config_text = serde_json::to_string(&config_json)?;
    let tube = pellet_geom::Tube { diameter: config.tube_diameter_m, lid_height: None };
    let files = [pellet_bytes];
    // Check everything the engine checks before creating the output.
    check_setup(&config, &pellet)?;
    // Held until the output is in place (dropped on return).
    let _lock = output_lock::OutputLock::acquire(&output)?;
    if let Some(park) = &args.park {
        let Some(source) = resume::latest(&output, &config, &files[0])? else {
            bail!("{output}: no partial run with a checkpoint to park (none of {output}, {output}.part, {output}.resume holds one)");
        };
        let t = source.park(Path::new(park))?;
        let bytes = std::fs::metadata(park).map(|m| m.len()).unwrap_or(0);
        pellet_cli::print_stdout(&format!("parked the run of {output} at its checkpoint t = {t:.3} s in {park} ({bytes} bytes); to go on, copy it to {output} and run pack --resume\n"))?;
        return Ok(Outcome::Success);
    }
    if !args.resume && !args.force {
        refuse_to_drop_an_unfinished_run(&output)?;
    }
    let source = if args.resume {
        resume::find(&output, &config, &files[0])?.map(|s| s.set_aside(&output)).transpose()?
    } else {
        None
    };
    let build = source.as_ref().map_or_else(|| pellet_cli::BUILD.to_string(), |s| s.build_history(pellet_cli::BUILD));
    let header = TrajectoryHeader {
        provenance: &provenance,
        config_json: &config_text,
        seed: config.seed,
        build: &build,
        pellet_files: &files,
        tube: &tube,
    };
    let mut writer = TrajectoryWriter::create(Path::new(&output), &header)?;
    if config.foxglove {
        writer.enable_viewer(&tube, viewer_tube_height(&config, &pellet), vec![ViewerShape::of(&pellet)])?;
    }
    let from = match source {
        Some(source) => {
            let checkpoint = source.copy_into(&mut writer)?;
            if !args.quiet {
                eprintln!("pack: resuming at t = {:.3} s", checkpoint.time_s());
            }
            Some(checkpoint)
        }
        None => {
            if args.resume && !args.quiet {
                eprintln!("pack: no checkpoint of this run to resume from; starting at t = 0");
            }
            None
        }
    };
    let stop = Arc::new(AtomicBool::new(false));
    {
        let stop = stop.clone();
        // Ctrl-C or SIGTERM: finish the step, then close the archive cleanly.
        let _ = ctrlc::set_handler(move || stop.store(true, Ordering::SeqCst));
    }
    let mut sink = McapSink::new(writer, stop, args.quiet);
    let result = resume_pack(&config, &pellet, &mut sink, from);
    let McapSink { writer, bar, .. } = sink;
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    let summary = match result {
        Ok(s) => s,
        Err(e) => {
            // Keep what was simulated as evidence, but never over an existing output.
            let part = writer.part_path().display().to_string();
            drop(writer);
            bail!("{e} (the trajectory up to the failure is in {part})");
        }
    };
    let path = writer.finish()?;
    let line = format!(
        "pack: {} pellets, {:.3} s simulated, {} engine substeps, max penetration {:.2} % of dpv, {:.3} % at the end; wrote {}",
        summary.pellets,
        summary.time_s,
        summary.substeps,
        100.0 * summary.max_penetration_m / pellet.properties.equivalent_diameter,
        100.0 * summary.end_penetration_m / pellet.properties.equivalent_diameter,
        path.display()
    );
    if !args.quiet {
        eprintln!("{line}");
        let s = &summary.solver;
        if s.pairs > 0 {
            eprintln!(
                "pack: contact solve over the last {} s: {:.2} contact points a pair, {:.1} % of loaded contacts warm started, {:.1} % of {} steps converged",
                pellet_pack::SOLVER_WINDOW_S,
                s.contacts_per_pair(),
                100.0 * s.warm_start_rate(),
                100.0 * s.converged_rate(),
                s.steps
            );
        }
    }
    match summary.ending {
        Ending::Settled => {
            let t = summary.settle.settle_time_s.unwrap_or(summary.time_s);
            pellet_cli::print_stdout(&format!("settled at {t:.4} s\n"))?;
            Ok(Outcome::Success)
        }
        Ending::TimeLimit => {
            // Not an error: the settle test said no, as settle-check's exit 1 does.
            eprintln!(
                "pack: not settled: the bed did not settle within --max-time {} s ({}); the trajectory is in {output}",
                config.max_time_s,
                summary.settle.reason.unwrap_or_default()
            );
            Ok(Outcome::CheckFailed)
        }
        Ending::Interrupted => {
            bail!(
                "interrupted at t = {:.3} s; the trajectory so far is in {output}: the same command with --resume continues it",
                summary.time_s
            )
        }
    }
}

/// A killed run's `<output>.part` (or a killed resume's `.resume`), and an interrupted run's
/// `<output>`, are the only copy of what it simulated; starting over would write over it.
fn refuse_to_drop_an_unfinished_run(output: &str) -> anyhow::Result<()> {
    for suffix in [".part", ".resume"] {
        let partial = format!("{output}{suffix}");
        if Path::new(&partial).is_file() {
            bail!(
                "{partial} holds a killed run of {output}; add --resume to continue it, or remove it (or add --force) to start over"
            );
        }
    }
    if let Some(run) = resume::unfinished(output) {
        bail!("{output} holds {run}; add --resume to continue it, or remove it (or add --force) to start over");
    }
    Ok(())
}

/// How tall to draw the tube in the viewer (m): the fill height or the height of
/// the bed at a loose porosity of 0.5, plus the drop height; for the batch
/// scheme the height of its initial cloud.
fn viewer_tube_height(config: &PackConfig, pellet: &pellet_geom::Pellet) -> f64 {
    let area = std::f64::consts::PI * config.tube_diameter_m.powi(2) / 4.0;
    let bed = match config.amount {
        Amount::Count(n) => f64::from(n) * pellet.properties.volume / (0.5 * area),
        Amount::FillHeight(h) => h,
    };
    let rb = pellet.bounding_radius;
    match (config.scheme, config.amount) {
        (LoadingScheme::Batch, Amount::Count(n)) => {
            f64::from(n) * pellet_pack::batch_height_per_pellet(rb, 0.5 * config.tube_diameter_m) + 3.0 * rb
        }
        _ => bed + config.drop_height_m + rb,
    }
}

/// The trajectory's path must name a file in a directory that exists: an empty name, a
/// directory, or a missing or non-directory parent would only fail when the finished run is
/// renamed into place.
fn check_output_path(output: &str) -> anyhow::Result<()> {
    if output.is_empty() {
        bail!("-o is empty; give the trajectory a file name, e.g. -o bed.mcap");
    }
    let path = Path::new(output);
    if path.is_dir() {
        bail!("-o {output} is a directory; give a file name, e.g. -o {}", path.join("bed.mcap").display());
    }
    let parent = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if !parent.is_dir() {
        bail!("-o {output}: the directory {} does not exist; create it first", parent.display());
    }
    Ok(())
}
