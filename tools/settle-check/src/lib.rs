//! `settle-check`: the kinetic-energy termination test on a `pack`
//! trajectory, and the settled bed as a packing file or CSV.

use std::fmt::Write as _;

use anyhow::{bail, Context};
use clap::Parser;

use pellet_cli::{shown, Outcome};
use pellet_geom::{Bed, PlacedPellet};
use pellet_io::{Frame, OutputFile, PackingFile, Provenance, SettleVerdict, Trajectory};
use pellet_settle::{check_settled, EnergySample, SettleCriteria, SettleReport};

const EXAMPLES: &str = "\
Examples:
  settle-check bed.mcap                         verdict only (exit 0 settled, 1 not)
  settle-check bed.mcap -o bed.packing          and write the settled bed for voidprof
  settle-check bed.mcap --csv poses.csv         the settled poses as CSV (mm)
  settle-check bed.mcap --at 2.5 -o t2.packing  the frame nearest t = 2.5 s
  settle-check bed.mcap --all-frames --csv traj.csv

Exit codes: 0 settled, 1 not settled, 2 error.";

/// Apply the kinetic-energy termination test to a `pack` trajectory (MCAP)
/// and extract the settled bed.
///
/// The bed is settled at the first time t where, over the window [t − w, t],
/// no pellet was added, the kinetic energy varied by at most the tolerance
/// (relative; in a bed of spheres the translational kinetic energy, since a
/// sphere's spin moves none of its surface), the translational kinetic energy
/// is below a bound and no pellet moves faster than a speed bound. A truncated
/// trajectory (a killed run) is read up to its last complete chunk.
#[derive(Debug, Parser)]
#[command(name = "settle-check", version = pellet_cli::LONG_VERSION, after_help = EXAMPLES, allow_negative_numbers = true)]
pub struct Args {
    /// The trajectory written by `pack` (`-` = stdin).
    #[arg(default_value = "-")]
    input: String,
    /// Write the chosen frame as a packing file (`-` = stdout, not a terminal).
    #[arg(short, long)]
    output: Option<String>,
    /// Write the chosen frame's poses as CSV: id,x,y,z (mm),qw,qx,qy,qz.
    #[arg(long)]
    csv: Option<String>,
    /// Use the frame nearest this simulated time (s) instead of the settled one.
    #[arg(long, value_name = "S")]
    at: Option<f64>,
    /// With --csv: write every recorded frame (time,id,x,y,z,qw,qx,qy,qz).
    #[arg(long, requires = "csv")]
    all_frames: bool,
    /// Window w of the test (s).
    #[arg(long, default_value_t = 0.15, value_name = "S")]
    settle_window: f64,
    /// Allowed variation of the kinetic energy over the window (fraction of its maximum).
    #[arg(long, default_value_t = 1e-3, value_name = "FRACTION")]
    settle_tolerance: f64,
    /// Bound on the translational kinetic energy (J) [default: 1e-7·N·m·g·dpv of the run's pellets].
    #[arg(long, value_name = "J")]
    ke_bound: Option<f64>,
    /// Bound on the fastest pellet's speed (m/s).
    #[arg(long, default_value_t = 1e-3, value_name = "M/S")]
    max_speed: f64,
    /// Print the report as JSON.
    #[arg(long)]
    json: bool,
}

/// Runs `settle-check`.
pub fn run(args: Args) -> anyhow::Result<Outcome> {
    let outputs = [("-o", &args.output), ("--csv", &args.csv)];
    pellet_cli::refuse_clashing_outputs(
        [&args.input],
        outputs.iter().filter_map(|(f, p)| p.as_ref().map(|p| (f.to_string(), p.clone()))),
    )?;
    let bytes = pellet_io::read_input(&args.input)?;
    let trajectory = pellet_io::read_trajectory(&bytes, &args.input)?;
    let stopped: Vec<String> = (trajectory.truncated.iter().map(|why| format!("{} is truncated ({why})", args.input)))
        .chain(trajectory.damaged.iter().map(|damage| format!("{}: {damage}", args.input)))
        .collect();
    if trajectory.energy.is_empty() {
        // One line: the damage or the cut is why there is nothing, not a warning before it.
        if let Some(why) = stopped.first() {
            bail!("{why}; no energy record reads");
        }
        bail!("{}: the trajectory has no energy records; was `pack` stopped before its first step?", args.input);
    }
    for why in &stopped {
        eprintln!("settle-check: warning: {why}; using what it holds");
    }
    let bed_types = pellet_types(&trajectory, &args.input)?;
    let criteria = criteria(&args, &trajectory, &bed_types)?;
    let history: Vec<EnergySample> = trajectory
        .energy
        .iter()
        .map(|e| EnergySample {
            time_s: e.time_s,
            kinetic_j: e.kinetic_j(),
            kinetic_translational_j: e.kinetic_translational_j,
            max_speed_m_s: e.max_speed_m_s,
            pellets: e.pellets,
        })
        .collect();
    let report = check_settled(&history, &criteria);

    let frame = choose_frame(&trajectory, &report, args.at)?;
    let mut outputs = Vec::new();
    if let (Some(path), Some(frame)) = (&args.output, frame) {
        let tube = trajectory.tube.with_context(|| format!("{}: no tube attachment", args.input))?;
        let packing = PackingFile {
            length_unit: "m".into(),
            provenance: Provenance {
                tool: "settle-check".into(),
                version: env!("CARGO_PKG_VERSION").into(),
                args: std::env::args().skip(1).collect(),
            },
            time_s: frame.time_s,
            verdict: Some(SettleVerdict {
                settled: report.settled,
                settle_time_s: report.settle_time_s,
                kinetic_energy_j: kinetic_at(&trajectory, frame.time_s),
            }),
            bed: Bed { tube, pellet_types: bed_types.clone(), pellets: placed(frame) },
        };
        packing.bed.validate().map_err(|e| anyhow::anyhow!("{}: frame at {} s: {e}", args.input, frame.time_s))?;
        outputs.push(OutputFile {
            path: path.clone(),
            bytes: pellet_io::encode_packing(&packing)?,
            binary: true,
            what: "packing file".into(),
        });
    } else if args.output.is_some() {
        bail!("{}: the trajectory holds no pose frames; run `pack` with a shorter --record-every", args.input);
    }
    if let Some(path) = &args.csv {
        let text =
            if args.all_frames { all_frames_csv(&trajectory.frames) } else { frame.map(frame_csv).unwrap_or_default() };
        outputs.push(OutputFile { path: path.clone(), bytes: text.into_bytes(), binary: false, what: "CSV".into() });
    }
    let report_text = if args.json {
        serde_json::to_string_pretty(&serde_json::json!({
            "settled": report.settled,
            "settle_time_s": report.settle_time_s,
            "final_time_s": report.final_time_s,
            "final_kinetic_energy_j": report.final_kinetic_j,
            "final_relative_ke_change": report.final_relative_change,
            "final_max_speed_m_s": report.final_max_speed_m_s,
            "pellets": history.last().map(|s| s.pellets),
            "criteria": criteria,
            "reason": report.reason,
            "frame_time_s": frame.map(|f| f.time_s),
            "truncated": trajectory.truncated.is_some(),
            "damaged": !trajectory.damaged.is_empty(),
            // The source of the `pack` that made the trajectory (null before it was recorded).
            "build": trajectory.run.get("build"),
            "stepper": recorded_stepper(&trajectory),
        }))? + "\n"
    } else {
        render(&report, &criteria, frame, history.last().map(|s| s.pellets).unwrap_or(0))
    };
    let stdout_taken = outputs.iter().any(|o| o.path == "-");
    pellet_io::write_outputs(&outputs)?;
    if stdout_taken {
        eprint!("{report_text}");
    } else {
        pellet_cli::print_stdout(&report_text)?;
    }
    Ok(if report.settled { Outcome::Success } else { Outcome::CheckFailed })
}

/// The time-stepping scheme `pack` ran (`velocity` or `acceleration`) as its recorded
/// configuration says; a configuration from before the choice existed was the force-level
/// stepper's. None without a readable configuration.
fn recorded_stepper(t: &Trajectory) -> Option<String> {
    let config: serde_json::Value = serde_json::from_str(t.run.get("config")?).ok()?;
    let config = config.as_object()?;
    Some(config.get("stepper").and_then(|s| s.as_str()).unwrap_or("acceleration").to_string())
}

fn pellet_types(t: &Trajectory, path: &str) -> anyhow::Result<Vec<pellet_geom::Pellet>> {
    if t.pellet_files.is_empty() {
        bail!("{path}: the trajectory has no pellet attachment; it was not written by `pack`");
    }
    t.pellet_files
        .iter()
        .enumerate()
        .map(|(i, b)| Ok(pellet_io::decode_pellet(b, &format!("{path}: attachment pellet-{i}.pellet"))?.pellet))
        .collect()
}

/// The criteria from the flags, with the energy bound defaulting to the
/// recommended 1e-7·N·m·g·dpv for the run's pellets and density.
fn criteria(args: &Args, t: &Trajectory, types: &[pellet_geom::Pellet]) -> anyhow::Result<SettleCriteria> {
    let density = t
        .run
        .get("config")
        .and_then(|c| serde_json::from_str::<serde_json::Value>(c).ok())
        .and_then(|v| v["density_kg_m3"].as_f64())
        .unwrap_or(8030.0);
    let props = &types[0].properties;
    let pellets = t.energy.last().map(|e| e.pellets).unwrap_or(1);
    let mut c = SettleCriteria::recommended(pellets, density * props.volume, props.equivalent_diameter);
    c.window_s = args.settle_window;
    c.relative_tolerance = args.settle_tolerance;
    c.max_speed_m_s = args.max_speed;
    c.spheres = types.iter().all(pellet_geom::Pellet::is_sphere);
    if let Some(b) = args.ke_bound {
        c.ke_bound_j = b;
    }
    c.validate().map_err(anyhow::Error::msg)?;
    Ok(c)
}

/// `--at T`: the nearest frame; otherwise the first frame at or after the
/// settle time, or the last frame when the bed never settled.
fn choose_frame<'a>(t: &'a Trajectory, report: &SettleReport, at: Option<f64>) -> anyhow::Result<Option<&'a Frame>> {
    if let Some(time) = at {
        let (first, last) = match (t.frames.first(), t.frames.last()) {
            (Some(a), Some(b)) => (a.time_s, b.time_s),
            _ => bail!("--at: the trajectory holds no frame"),
        };
        // Far beyond the frames every frame is equally far from the time, and the first won: the
        // time must lie within them, give or take one frame's spacing.
        let spacing = (last - first) / (t.frames.len().max(2) - 1) as f64;
        if !(time.is_finite() && time >= first - spacing && time <= last + spacing) {
            bail!(
                "--at must be a time in s within the recorded frames, {first:.4} to {last:.4} s (got {})",
                shown(time)
            );
        }
        return Ok(t.frames.iter().min_by(|a, b| (a.time_s - time).abs().total_cmp(&(b.time_s - time).abs())));
    }
    Ok(match report.settle_time_s {
        Some(ts) => t.frames.iter().find(|f| f.time_s >= ts - 1e-12).or(t.frames.last()),
        None => t.frames.last(),
    })
}

fn kinetic_at(t: &Trajectory, time: f64) -> f64 {
    t.energy
        .iter()
        .min_by(|a, b| (a.time_s - time).abs().total_cmp(&(b.time_s - time).abs()))
        .map(|e| e.kinetic_j())
        .unwrap_or(0.0)
}

fn placed(frame: &Frame) -> Vec<PlacedPellet> {
    (0..frame.positions.len())
        .map(|i| PlacedPellet {
            type_index: frame.type_index.get(i).copied().unwrap_or(0),
            position: frame.positions[i],
            orientation: frame.orientations[i],
        })
        .collect()
}

fn frame_csv(frame: &Frame) -> String {
    let mut s = String::from("id,x,y,z,qw,qx,qy,qz\n");
    rows(&mut s, frame, None);
    s
}

fn all_frames_csv(frames: &[Frame]) -> String {
    let mut s = String::from("time,id,x,y,z,qw,qx,qy,qz\n");
    for f in frames {
        rows(&mut s, f, Some(f.time_s));
    }
    s
}

fn rows(s: &mut String, frame: &Frame, time: Option<f64>) {
    for (i, (p, q)) in frame.positions.iter().zip(&frame.orientations).enumerate() {
        if let Some(t) = time {
            let _ = write!(s, "{t},");
        }
        let _ = writeln!(s, "{i},{},{},{},{},{},{},{}", p[0] * 1e3, p[1] * 1e3, p[2] * 1e3, q[0], q[1], q[2], q[3]);
    }
}

fn render(r: &SettleReport, c: &SettleCriteria, frame: Option<&Frame>, pellets: u32) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "pellets:            {pellets}");
    let _ = writeln!(s, "simulated time:     {:.4} s", r.final_time_s);
    let _ = writeln!(s, "final kinetic:      {:.4e} J (bound {:.2e} J)", r.final_kinetic_j, c.ke_bound_j);
    let _ = writeln!(
        s,
        "KE change, window:  {:.3e} of KE over {} s (tolerance {:.1e})",
        r.final_relative_change, c.window_s, c.relative_tolerance
    );
    let _ = writeln!(s, "fastest pellet:     {:.3e} m/s (bound {:.1e} m/s)", r.final_max_speed_m_s, c.max_speed_m_s);
    match r.settle_time_s {
        Some(t) => {
            let _ = writeln!(s, "verdict:            settled at {t:.4} s");
        }
        None => {
            let _ =
                writeln!(s, "verdict:            NOT settled: {}", r.reason.as_deref().unwrap_or("criteria not met"));
        }
    }
    if let Some(f) = frame {
        let _ = writeln!(s, "frame used:         t = {:.4} s", f.time_s);
    }
    s
}
