//! Assembling what is known of the beds from summaries, profile CSVs and
//! flags. Flags win over summaries (they are explicit); summaries win over
//! what a profile's columns imply.

use anyhow::{bail, Context, Result};

use pellet_refs::metrics::{cross_section_mean, interpolate};
use pellet_refs::scoring::{Bed, Profile, ZUnit};
use pellet_refs::Shape;

use crate::inputs::{self, Summary, Table};
use crate::Args;

/// The simulated profile to score: one packing, or the mean of several.
#[derive(Clone, Debug)]
pub struct SimProfile {
    /// The input file(s), comma-separated.
    pub source: String,
    /// Mean profile.
    pub profile: Profile,
    /// Spread: standard deviation over packings, or the CSV's `void_fraction_std`.
    pub spread: Option<Vec<f64>>,
    /// Number of packings averaged.
    pub packings: usize,
}

/// What the report says about the inputs and parameters.
#[derive(Clone, Debug, Default)]
pub struct Info {
    /// The command line.
    pub command: String,
    /// (role, path) of every input file.
    pub inputs: Vec<(String, String)>,
    /// (parameter, value and where it came from).
    pub params: Vec<(String, String)>,
    /// How ε_b was chosen.
    pub eps_b_mode: String,
}

/// Everything read.
pub struct Inputs {
    /// One bed per summary, or one from the flags and the profile.
    pub beds: Vec<Bed>,
    /// The simulated profile, if any.
    pub profile: Option<SimProfile>,
    /// For the report.
    pub info: Info,
    /// dp and dpv (mm) of the profile's bed, if known.
    pub lengths_mm: (Option<f64>, Option<f64>),
    /// The summaries read, with the name each was read from.
    pub summaries: Vec<(String, Summary)>,
}

fn read_bytes(path: &str) -> Result<Vec<u8>> {
    Ok(pellet_io::read_input(path)?)
}

fn shown(path: &str) -> String {
    if path == "-" {
        "stdin".into()
    } else {
        path.to_string()
    }
}

fn fmt_opt(v: Option<f64>, from: &str) -> String {
    v.map_or_else(|| "unknown".into(), |v| format!("{v:.6} ({from})"))
}

impl Inputs {
    /// Reads the summaries and profiles named on the command line.
    pub fn read(args: &Args, profile_paths: &[String], unit: ZUnit) -> Result<Inputs> {
        let mut info = Info { command: std::env::args().collect::<Vec<_>>().join(" "), ..Info::default() };
        let mut summaries = Vec::new();
        for path in &args.summaries {
            let s = inputs::parse_summary(&shown(path), &read_bytes(path)?)?;
            info.inputs.push(("summary (bed)".into(), shown(path)));
            summaries.push((shown(path), s));
        }
        let mut tables = Vec::new();
        for path in profile_paths {
            let t = Table::parse(&shown(path), &read_bytes(path)?)?;
            if t.is_empty() {
                bail!("{}: empty profile (a header but no data rows)", shown(path));
            }
            info.inputs.push(("simulated profile".into(), shown(path)));
            tables.push(t);
        }
        for path in &args.exp {
            info.inputs.push(("experimental profile".into(), shown(path)));
        }
        let first = summaries.first().map(|(_, s)| s.clone()).unwrap_or_default();
        let hints = tables.first().map_or_else(Hints::default, |t| Hints {
            d: inputs::tube_diameter_from_columns(t),
            dp: inputs::length_from_columns(t, "dp"),
            dpv: inputs::length_from_columns(t, "dpv"),
        });
        let mut beds = Vec::new();
        if summaries.is_empty() {
            let source = profile_paths.first().map_or("flags".into(), |p| shown(p));
            beds.push(bed_from(args, &Summary::default(), source, hints, &mut info)?);
        } else {
            for (i, (source, s)) in summaries.iter().enumerate() {
                let h = if i == 0 { hints } else { Hints::default() };
                let mut scratch = Info::default();
                let info_for = if i == 0 { &mut info } else { &mut scratch };
                beds.push(bed_from(args, s, source.clone(), h, info_for)?);
            }
        }
        let shape = beds[0].shape;
        let dp = args.dp.or(first.pellet_diameter_mm).or(hints.dp);
        let dpv = args.dpv.or(first.dpv_mm).or(hints.dpv).or(if shape == Shape::Sphere { dp } else { None });
        let profile = if tables.is_empty() {
            None
        } else {
            let (length, flag) = match unit {
                ZUnit::Dp => (dp, "--dp"),
                ZUnit::Dpv => (dpv, "--dpv"),
            };
            Some(sim_profile(&tables, unit, length, flag)?)
        };
        info.params.push(("wall coordinate".into(), format!("z = (R − r)/{}", unit.name())));
        if let Some(p) = &profile {
            if p.packings > 1 {
                info.params.push(("packings averaged".into(), p.packings.to_string()));
            }
            if beds[0].bulk_porosity.is_none() {
                if let Some(n) = beds[0].n_for(unit) {
                    let z_max = p.profile.z.last().copied().unwrap_or(0.0);
                    beds[0].bulk_porosity = cross_section_mean(&p.profile.z, &p.profile.eps, n / 2.0);
                    let coverage = if z_max < 0.98 * n / 2.0 {
                        format!("; the profile covers only z ≤ {z_max:.3} of N/2 = {:.3}", n / 2.0)
                    } else {
                        String::new()
                    };
                    info.params.push((
                        "bulk porosity".into(),
                        fmt_opt(beds[0].bulk_porosity, &format!("the profile's cross-section mean{coverage}")),
                    ));
                }
            }
        }
        Ok(Inputs { beds, profile, info, lengths_mm: (dp, dpv), summaries })
    }
}

/// What a profile's columns imply about its bed (mm).
#[derive(Clone, Copy, Debug, Default)]
struct Hints {
    d: Option<f64>,
    dp: Option<f64>,
    dpv: Option<f64>,
}

fn bed_from(args: &Args, s: &Summary, source: String, hints: Hints, info: &mut Info) -> Result<Bed> {
    let shape = match (args.shape, &s.shape) {
        (Some(a), _) => a.into(),
        (None, Some(name)) => {
            Shape::parse(name).with_context(|| format!("{source}: unknown shape {name:?} (sphere, cylinder, ring)"))?
        }
        (None, None) => Shape::Sphere,
    };
    let shape_from = if args.shape.is_some() {
        "--shape"
    } else if s.shape.is_some() {
        "summary"
    } else {
        "assumed"
    };
    let (d, d_from) = first_of(&[
        (args.tube_diameter, "--tube-diameter"),
        (s.tube_diameter_mm, "summary"),
        (hints.d, "profile: r_mm + wall_distance_mm"),
    ]);
    let (dp, dp_from) = first_of(&[
        (args.dp, "--dp"),
        (s.pellet_diameter_mm, "summary"),
        (hints.dp, "profile: wall_distance_mm / wall_distance_dp"),
    ]);
    let sphere_dp = if shape == Shape::Sphere { dp } else { None };
    let (dpv, dpv_from) = first_of(&[
        (args.dpv, "--dpv"),
        (s.dpv_mm, "summary"),
        (hints.dpv, "profile: wall_distance_mm / wall_distance_dpv"),
        (sphere_dp, "= dp for spheres"),
    ]);
    let (n_dp, n_dp_from) = match (d, dp) {
        (Some(d), Some(dp)) => (Some(d / dp), "D/dp"),
        _ => (s.n, "summary"),
    };
    let (n_dpv, n_dpv_from) = match (d, dpv) {
        (Some(d), Some(dpv)) => (Some(d / dpv), "D/dpv"),
        _ => first_of(&[(s.n_dpv, "summary"), (if shape == Shape::Sphere { n_dp } else { None }, "= N for spheres")]),
    };
    let bulk = args.bulk_porosity.or(s.bulk_porosity);
    let p = &mut info.params;
    p.push(("shape".into(), format!("{} ({shape_from})", shape.name())));
    p.push(("tube diameter D (mm)".into(), fmt_opt(d, d_from)));
    p.push(("pellet diameter dp (mm)".into(), fmt_opt(dp, dp_from)));
    p.push(("volume-equivalent diameter dpv (mm)".into(), fmt_opt(dpv, dpv_from)));
    p.push(("N = D/dp".into(), fmt_opt(n_dp, n_dp_from)));
    p.push(("N_dpv = D/dpv".into(), fmt_opt(n_dpv, n_dpv_from)));
    if let Some(b) = bulk {
        let from = if args.bulk_porosity.is_some() { "--bulk-porosity" } else { "summary" };
        p.push(("bulk porosity".into(), format!("{b:.6} ({from})")));
    }
    if let Some(n) = s.pellets {
        p.push(("pellets".into(), format!("{n} (summary)")));
    }
    let (ring_di_do, ring_from) = first_of(&[(args.ring_di_do, "--ring-di-do"), (s.ring_di_do, "summary")]);
    if shape == Shape::Ring {
        p.push(("ring di/do".into(), fmt_opt(ring_di_do, ring_from)));
    }
    let (sphericity, phi_from) = first_of(&[(args.sphericity, "--sphericity"), (s.sphericity, "summary")]);
    if sphericity.is_some() {
        p.push(("sphericity φ".into(), fmt_opt(sphericity, phi_from)));
    }
    Ok(Bed { source, shape, bulk_porosity: bulk, n_dp, n_dpv, ring_di_do, sphericity })
}

/// The first known value and where it came from.
fn first_of(candidates: &[(Option<f64>, &'static str)]) -> (Option<f64>, &'static str) {
    candidates.iter().find_map(|(v, from)| v.map(|v| (Some(v), *from))).unwrap_or((None, ""))
}

/// One profile table as sorted (z, ε, spread).
fn profile_of(t: &Table, unit: ZUnit, length: Option<f64>, flag: &str) -> Result<inputs::Rows> {
    let z = inputs::wall_distance(t, unit.name(), length, flag)?;
    let eps = inputs::void_fraction(t)?;
    let (z, e, s) = inputs::sorted_rows(z, eps, t.column("void_fraction_std"));
    if z.is_empty() {
        bail!("{}: empty profile (no row with a finite wall distance and void fraction)", t.source);
    }
    Ok((z, e, s))
}

fn sim_profile(tables: &[Table], unit: ZUnit, length: Option<f64>, flag: &str) -> Result<SimProfile> {
    let source = tables.iter().map(|t| t.source.clone()).collect::<Vec<_>>().join(", ");
    let (z0, e0, s0) = profile_of(&tables[0], unit, length, flag)?;
    if tables.len() == 1 {
        return Ok(SimProfile { source, profile: Profile { z: z0, eps: e0, z_unit: unit }, spread: s0, packings: 1 });
    }
    let others: Vec<_> = tables[1..].iter().map(|t| profile_of(t, unit, length, flag)).collect::<Result<_>>()?;
    // The mean on the first packing's grid, where every packing has data.
    let (mut z, mut mean, mut std) = (Vec::new(), Vec::new(), Vec::new());
    for (i, &zi) in z0.iter().enumerate() {
        let mut vals = vec![e0[i]];
        for (oz, oe, _) in &others {
            match interpolate(oz, oe, zi) {
                Some(v) => vals.push(v),
                None => break,
            }
        }
        if vals.len() != tables.len() {
            continue;
        }
        let n = vals.len() as f64;
        let m = vals.iter().sum::<f64>() / n;
        // Sample standard deviation over packings.
        let var = vals.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / (n - 1.0);
        z.push(zi);
        mean.push(m);
        std.push(var.sqrt());
    }
    if z.is_empty() {
        bail!("the profiles {source} share no wall-distance range");
    }
    Ok(SimProfile {
        source,
        profile: Profile { z, eps: mean, z_unit: unit },
        spread: Some(std),
        packings: tables.len(),
    })
}

/// Reads an experimental profile: (file name, z in `unit`, ε).
pub fn read_experiment(
    path: &str,
    unit: ZUnit,
    lengths_mm: (Option<f64>, Option<f64>),
) -> Result<(String, Vec<f64>, Vec<f64>)> {
    let t = Table::parse(&shown(path), &read_bytes(path)?)?;
    if t.is_empty() {
        bail!("{}: empty profile (a header but no data rows)", shown(path));
    }
    let length = match unit {
        ZUnit::Dp => lengths_mm.0,
        ZUnit::Dpv => lengths_mm.1,
    };
    let flag = if unit == ZUnit::Dp { "--dp" } else { "--dpv" };
    let (z, e, _) = profile_of(&t, unit, length, flag)?;
    let name = std::path::Path::new(path).file_name().map_or(path.to_string(), |n| n.to_string_lossy().into_owned());
    Ok((name, z, e))
}
