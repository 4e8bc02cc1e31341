//! Reading a trajectory back: every record in file order, or with [`ReadOptions::skip_damage`]
//! what reads of a damaged file.

use std::collections::BTreeMap;

use mcap::records::Record;

use pellet_geom::Tube;

use super::{
    decode, EnergyRecord, Frame, TubeJson, CHECKPOINT_TOPIC, ENERGY_TOPIC, POSES_TOPIC, RUN_METADATA,
    TRAJECTORY_PROFILE, TUBE_ATTACHMENT,
};
use crate::mcap_records::{Records, Salvage};
use crate::IoError;

/// A trajectory read back: the header records, every energy record, and
/// every frame's time with where to find it.
pub struct Trajectory {
    /// The `packbed.run` metadata (tool, version, args, seed, units, config).
    pub run: BTreeMap<String, String>,
    /// The attached pellet files' bytes, by type index.
    pub pellet_files: Vec<Vec<u8>>,
    /// The tube.
    pub tube: Option<Tube>,
    /// Every energy record, in time order.
    pub energy: Vec<EnergyRecord>,
    /// Every pose frame, in time order.
    pub frames: Vec<Frame>,
    /// Why reading stopped early, for a truncated file (a killed run).
    pub truncated: Option<String>,
    /// The bytes of the last checkpoint (see [`super::TrajectoryWriter::write_checkpoint`]).
    pub checkpoint: Option<Vec<u8>>,
    /// The damaged stretches [`ReadOptions::skip_damage`] went past, each in a few words: where,
    /// what was wrong, which stretch of the run is missing. Read strictly, the damage reading
    /// stopped at (then `truncated` is `None`: the file is whole but does not read).
    pub damaged: Vec<String>,
}

/// How [`read_trajectory_with`] reads.
#[derive(Clone, Copy, Debug, Default)]
pub struct ReadOptions {
    /// Go on past a record that does not read (one bad byte in a chunk) at the next chunk that
    /// reads whole, instead of stopping there as at a killed run's end.
    pub skip_damage: bool,
    /// Leave the pose frames out, undecoded (for a reader that needs the run's state only).
    pub skip_frames: bool,
}

/// Reads a whole trajectory from its bytes. A truncated file (a killed
/// run) yields everything up to its last complete chunk, with
/// `truncated` saying so; a file that is not MCAP at all is an error.
pub fn read_trajectory(bytes: &[u8], path: &str) -> Result<Trajectory, IoError> {
    read_trajectory_with(bytes, path, ReadOptions::default())
}

/// The channels [`super::TrajectoryWriter`] adds, in this order, numbered from 1 by the MCAP
/// writer. Their records are in the first chunk only: when it is damaged, the messages of the
/// chunks after it are placed by these.
const WRITER_CHANNELS: [&str; 3] = [POSES_TOPIC, ENERGY_TOPIC, CHECKPOINT_TOPIC];

enum Reader<'a> {
    Strict(Records<'a>),
    Salvage(Salvage<'a>),
}

/// Why the strict reader stopped before the end of the file.
enum Stop {
    Cut(String),
    Damaged(String),
}

impl Reader<'_> {
    fn next(&mut self) -> Option<Result<Record<'static>, Stop>> {
        match self {
            Reader::Strict(r) => r.next().map(|r| {
                r.map_err(|e| match e {
                    mcap::McapError::UnexpectedEof => Stop::Cut(e.to_string()),
                    e => Stop::Damaged(e.to_string()),
                })
            }),
            Reader::Salvage(s) => s.next().map(Ok),
        }
    }

    fn skipped(&self) -> usize {
        match self {
            Reader::Strict(_) => 0,
            Reader::Salvage(s) => s.skipped.len(),
        }
    }
}

/// As [`read_trajectory`], the way `options` say.
pub fn read_trajectory_with(bytes: &[u8], path: &str, options: ReadOptions) -> Result<Trajectory, IoError> {
    if bytes.len() < 8 && mcap::MAGIC.starts_with(bytes) {
        return Err(IoError::CutInHeader { path: path.into(), len: bytes.len() });
    }
    if bytes.len() < 8 || &bytes[..8] != mcap::MAGIC {
        return Err(IoError::Corrupt {
            path: path.into(),
            reason: "not an MCAP file (bad magic); `pack` writes trajectories".into(),
        });
    }
    // Not mcap's ChunkFlattener: it sets no bound on record lengths (`mcap_records`).
    let mut reader =
        if options.skip_damage { Reader::Salvage(Salvage::new(bytes)) } else { Reader::Strict(Records::new(bytes)) };
    let mut out = Trajectory {
        run: BTreeMap::new(),
        pellet_files: Vec::new(),
        tube: None,
        energy: Vec::new(),
        frames: Vec::new(),
        truncated: None,
        checkpoint: None,
        damaged: Vec::new(),
    };
    let mut topics: BTreeMap<u16, String> = BTreeMap::new();
    if options.skip_damage {
        topics.extend(WRITER_CHANNELS.iter().zip(1..).map(|(topic, id)| (id, topic.to_string())));
    }
    // The simulated times of the last message before each skipped stretch and the first after.
    let mut around: Vec<(Option<f64>, Option<f64>)> = Vec::new();
    let mut last_time = None;
    let mut profile_ok = false;
    let mut header_seen = false;
    while let Some(record) = reader.next() {
        let record = match record {
            Ok(r) => r,
            // The file ends inside a record: a killed run's cut.
            Err(Stop::Cut(e)) => {
                out.truncated = Some(e);
                break;
            }
            // A record that is all there but does not read: damage, which a cut file never has.
            Err(Stop::Damaged(e)) => {
                let after = last_time.map_or(String::new(), |t| format!(" after t = {t:.3} s"));
                out.damaged.push(format!("the file is damaged{after}, and not read past it ({e})"));
                break;
            }
        };
        around.resize(reader.skipped(), (last_time, None));
        match record {
            Record::Header(h) => {
                header_seen = true;
                profile_ok = h.profile == TRAJECTORY_PROFILE;
            }
            Record::Metadata(m) if m.name == RUN_METADATA => out.run = m.metadata,
            Record::Attachment { header, data, .. } => {
                if header.name == TUBE_ATTACHMENT {
                    out.tube = parse_tube(&data);
                } else if let Some(i) = header.name.strip_prefix("pellet-").and_then(|s| s.strip_suffix(".pellet")) {
                    let i: usize = i.parse().unwrap_or(usize::MAX);
                    if i < 4096 {
                        if out.pellet_files.len() <= i {
                            out.pellet_files.resize(i + 1, Vec::new());
                        }
                        out.pellet_files[i] = data.into_owned();
                    }
                }
            }
            Record::Channel(c) => {
                topics.insert(c.id, c.topic.clone());
            }
            Record::Message { header, data } => {
                let t = header.log_time as f64 * 1e-9;
                last_time = Some(t);
                around.iter_mut().filter(|a| a.1.is_none()).for_each(|a| a.1 = Some(t));
                match topics.get(&header.channel_id).map(String::as_str) {
                    Some(POSES_TOPIC) if !options.skip_frames => out.frames.push(decode(&data, path, "pose")?),
                    Some(ENERGY_TOPIC) => out.energy.push(decode(&data, path, "energy")?),
                    Some(CHECKPOINT_TOPIC) => out.checkpoint = Some(data.into_owned()),
                    _ => {}
                }
            }
            _ => {}
        }
    }
    if let Reader::Salvage(s) = reader {
        out.truncated = s.cut;
        around.resize(s.skipped.len(), (last_time, None));
        out.damaged = s
            .skipped
            .iter()
            .zip(&around)
            .map(|(d, &(before, after))| {
                let missing = match (before, after) {
                    (Some(a), Some(b)) => format!("; the run between t = {a:.3} s and t = {b:.3} s is missing"),
                    (None, Some(b)) => format!("; the run up to t = {b:.3} s is missing"),
                    (Some(a), None) => format!("; the run after t = {a:.3} s is missing"),
                    (None, None) => String::new(),
                };
                format!("{} bytes at byte {} do not read ({}){missing}", d.len, d.offset, d.reason)
            })
            .collect();
    }
    if !header_seen && out.truncated.is_some() && out.damaged.is_empty() {
        return Err(IoError::CutInHeader { path: path.into(), len: bytes.len() });
    }
    if !header_seen && !options.skip_damage {
        if let Some(damage) = out.damaged.first() {
            return Err(IoError::Corrupt { path: path.into(), reason: damage.clone() });
        }
    }
    if !profile_ok {
        return Err(IoError::Corrupt {
            path: path.into(),
            reason: format!("not a packbed trajectory (MCAP profile is not {TRAJECTORY_PROFILE:?})"),
        });
    }
    Ok(out)
}

fn parse_tube(data: &[u8]) -> Option<Tube> {
    let t: TubeJson = serde_json::from_slice(data).ok()?;
    Some(Tube { diameter: t.diameter_m, lid_height: t.lid_height_m })
}
