//! `pack`: drops pellets into a tube with the rigid-body engine and
//! streams the trajectory to an MCAP archive.

use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use anyhow::{bail, Context};

use pellet_cli::Outcome;
use pellet_io::foxglove::ViewerShape;
use pellet_io::{Provenance, TrajectoryHeader, TrajectoryWriter};
use pellet_pack::{check_setup, resume_pack, Amount, Ending, LoadingScheme, PackConfig, PackOptions};

mod args;
mod output_lock;
mod resume;
mod sink;

pub use args::Args;
use sink::McapSink;

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
/// the bed at a loose porosity of 0.5, with a pellet entering over it; for the batch scheme
/// the height of its initial cloud.
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
        _ => pellet_pack::entry_height(bed, config.drop_height_m, config.release_height_m) + rb,
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
