//! The `.mcap` trajectory archive written by `pack` (see the crate doc).

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use pellet_geom::Tube;

use crate::foxglove::{self, ViewerShape};
use crate::pellet_file::Provenance;
use crate::IoError;

mod read;
pub use read::{read_trajectory, read_trajectory_with, ReadOptions, Trajectory};

/// MCAP header profile of packbed trajectories.
pub const TRAJECTORY_PROFILE: &str = "packbed/1";
/// Message encoding of packbed's channels: bincode 2, standard config, fixed-width LE integers.
pub const MESSAGE_ENCODING: &str = "x-packbed-bincode2-v1";
/// Topic of the pose frames.
pub const POSES_TOPIC: &str = "/pack/poses";
/// Topic of the per-step energy records.
pub const ENERGY_TOPIC: &str = "/pack/energy";
/// Topic of the run checkpoints (`pack --resume` continues from the last one).
pub const CHECKPOINT_TOPIC: &str = "/pack/checkpoint";
/// Schema name of the checkpoints: the driver's state, opaque to this crate, encoded with
/// [`encode_message`].
pub const CHECKPOINT_SCHEMA: &str = "packbed.Checkpoint.v1";
/// Schema name of [`Frame`].
pub const FRAME_SCHEMA: &str = "packbed.Frame.v1";
/// Schema name of [`EnergyRecord`].
pub const ENERGY_SCHEMA: &str = "packbed.EnergyRecord.v1";
/// Name of the metadata record holding the run configuration.
pub const RUN_METADATA: &str = "packbed.run";
/// Attachment name of the tube description (JSON).
pub const TUBE_ATTACHMENT: &str = "tube.json";

/// Every pellet's pose at one time. Positions in m, quaternions (w, x, y, z) body → world.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Frame {
    /// Simulated time (s).
    pub time_s: f64,
    /// Pellet type of each pellet (index into the attached pellet files).
    pub type_index: Vec<u32>,
    /// Centroid positions (m).
    pub positions: Vec<[f64; 3]>,
    /// Orientations, unit quaternions (w, x, y, z).
    pub orientations: Vec<[f64; 4]>,
    /// Linear and angular velocities (m/s, rad/s), when recorded.
    pub velocities: Option<Vec<[f64; 6]>>,
}

/// The state of the run after one step.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct EnergyRecord {
    /// Simulated time (s).
    pub time_s: f64,
    /// Pellets in the tube.
    pub pellets: u32,
    /// Translational kinetic energy (J).
    pub kinetic_translational_j: f64,
    /// Rotational kinetic energy (J).
    pub kinetic_rotational_j: f64,
    /// Gravitational potential energy relative to z = 0 (J).
    pub potential_j: f64,
    /// Energy removed by collisions so far (J).
    pub dissipated_collisions_j: f64,
    /// Energy removed by friction so far (J).
    pub dissipated_friction_j: f64,
    /// Energy changed by position projection so far (J).
    pub projection_j: f64,
    /// Colliding contacts in the step.
    pub colliding_contacts: u32,
    /// Resting contacts in the step.
    pub resting_contacts: u32,
    /// Substeps taken in the step.
    pub substeps: u32,
    /// Largest resting-contact solver residual in the step (m/s²).
    pub solver_residual: f64,
    /// Solver iterations in the step.
    pub solver_iterations: u32,
    /// Largest penetration at the end of the step (m).
    pub max_penetration_m: f64,
    /// Fastest pellet's speed (m/s).
    pub max_speed_m_s: f64,
}

impl EnergyRecord {
    /// Total kinetic energy (J).
    pub fn kinetic_j(&self) -> f64 {
        self.kinetic_translational_j + self.kinetic_rotational_j
    }
}

use crate::framed::config;

/// Encodes a value as packbed's channels do ([`MESSAGE_ENCODING`]).
pub fn encode_message<T: Serialize>(value: &T) -> Result<Vec<u8>, IoError> {
    let mut buf = Vec::new();
    encode(value, &mut buf)?;
    Ok(buf)
}

/// Decodes a message written by [`encode_message`]; `what` names it in the error.
pub fn decode_message<T: serde::de::DeserializeOwned>(bytes: &[u8], path: &str, what: &str) -> Result<T, IoError> {
    decode(bytes, path, what)
}

fn encode<T: Serialize>(value: &T, buf: &mut Vec<u8>) -> Result<(), IoError> {
    buf.clear();
    bincode::serde::encode_into_std_write(value, buf, config())
        .map(|_| ())
        .map_err(|e| IoError::Corrupt { path: "<mcap>".into(), reason: format!("cannot encode: {e}") })
}

fn decode<T: serde::de::DeserializeOwned>(bytes: &[u8], path: &str, what: &str) -> Result<T, IoError> {
    bincode::serde::decode_from_slice(bytes, config()).map(|(v, _)| v).map_err(|e| IoError::Corrupt {
        path: path.into(),
        reason: format!("a {what} message {}", crate::framed::what_is_wrong(&e)),
    })
}

fn mcap_error(path: &Path) -> impl Fn(mcap::McapError) -> IoError {
    let path = path.display().to_string();
    // An I/O failure (a full disk) is reported as the operating system words it.
    move |e| match e {
        mcap::McapError::Io(source) => IoError::Io { path: path.clone(), source },
        e => IoError::Corrupt { path: path.clone(), reason: format!("MCAP: {e}") },
    }
}

/// What goes at the start of a trajectory.
pub struct TrajectoryHeader<'a> {
    /// Who is writing it and with which arguments.
    pub provenance: &'a Provenance,
    /// The full run configuration as a JSON object (SI units).
    pub config_json: &'a str,
    /// The random seed.
    pub seed: u64,
    /// The source the writing binary was built from (`git <commit>`); for a resumed run, the
    /// builds of all its legs with the time each took over.
    pub build: &'a str,
    /// The pellet files (bytes of `.pellet` files), one per pellet type.
    pub pellet_files: &'a [Vec<u8>],
    /// The container.
    pub tube: &'a Tube,
}

/// Streams a trajectory to `<path>.part` and renames it to `<path>` when
/// finished, so a completed file never coexists with a partial one under
/// the final name. Chunks are flushed as they fill: a killed run leaves a
/// `.part` file readable up to its last complete chunk.
pub struct TrajectoryWriter {
    writer: Option<mcap::Writer<BufWriter<File>>>,
    part_path: PathBuf,
    final_path: PathBuf,
    /// The target is a special file: `finish` copies the part file into it instead of renaming.
    copy_over: bool,
    poses_channel: u16,
    energy_channel: u16,
    checkpoint_channel: u16,
    poses_sequence: u32,
    energy_sequence: u32,
    checkpoint_sequence: u32,
    buf: Vec<u8>,
    viewer: Option<Viewer>,
}

/// State of the optional Foxglove viewer channels (see [`crate::foxglove`]).
struct Viewer {
    scene_channel: u16,
    transforms_channel: u16,
    shapes: Vec<ViewerShape>,
    /// Pellets whose entity has been written.
    announced: usize,
    scene_sequence: u32,
    transforms_sequence: u32,
}

/// Simulated seconds → MCAP log time (ns).
fn log_time(time_s: f64) -> u64 {
    (time_s.max(0.0) * 1e9).round() as u64
}

impl TrajectoryWriter {
    /// Creates `<path>.part` and writes the header records. For a special file (`/dev/null`, a
    /// FIFO: [`crate::is_special_file`]), which a rename would replace and MCAP cannot
    /// seek in, the part file is in the temporary directory and `finish` copies it over.
    pub fn create(path: &Path, header: &TrajectoryHeader) -> Result<Self, IoError> {
        let mut meta = BTreeMap::new();
        meta.insert("tool".to_string(), header.provenance.tool.clone());
        meta.insert("version".to_string(), header.provenance.version.clone());
        meta.insert("args".to_string(), header.provenance.args.join(" "));
        meta.insert("build".to_string(), header.build.to_string());
        meta.insert("seed".to_string(), header.seed.to_string());
        meta.insert("units".to_string(), "SI (m, kg, s, J)".to_string());
        meta.insert("config".to_string(), header.config_json.to_string());
        Self::create_with_run(path, &meta, header.pellet_files, header.tube)
    }

    /// As [`TrajectoryWriter::create`], with the `packbed.run` metadata given whole: a copy of
    /// another trajectory's [`Trajectory::run`] keeps its provenance, build and configuration
    /// as they were (`pack --park`).
    pub fn create_with_run(
        path: &Path,
        run: &BTreeMap<String, String>,
        pellet_files: &[Vec<u8>],
        tube: &Tube,
    ) -> Result<Self, IoError> {
        let copy_over = crate::atomic::is_special_file(path);
        let part_path = if copy_over {
            let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
            std::env::temp_dir().join(format!("packbed-{}-{name}.part", std::process::id()))
        } else {
            let mut part = path.as_os_str().to_owned();
            part.push(".part");
            PathBuf::from(part)
        };
        let err = mcap_error(&part_path);
        let file =
            File::create(&part_path).map_err(|source| IoError::Io { path: part_path.display().to_string(), source })?;
        let options = mcap::WriteOptions::new()
            .compression(Some(mcap::Compression::Zstd))
            .chunk_size(Some(1 << 20))
            // Pinned: zstd's single- and multi-threaded modes give different bytes.
            .compression_threads(1)
            .profile(TRAJECTORY_PROFILE)
            .library(format!("packbed {}", run.get("version").map_or("", String::as_str)));
        let mut writer = mcap::Writer::with_options(BufWriter::new(file), options).map_err(&err)?;
        writer
            .write_metadata(&mcap::records::Metadata { name: RUN_METADATA.into(), metadata: run.clone() })
            .map_err(&err)?;
        for (i, bytes) in pellet_files.iter().enumerate() {
            writer
                .attach(&mcap::Attachment {
                    log_time: 0,
                    create_time: 0,
                    name: format!("pellet-{i}.pellet"),
                    media_type: "application/x-packbed-pellet".into(),
                    data: std::borrow::Cow::Borrowed(bytes),
                })
                .map_err(&err)?;
        }
        let tube_json = tube_json(tube);
        writer
            .attach(&mcap::Attachment {
                log_time: 0,
                create_time: 0,
                name: TUBE_ATTACHMENT.into(),
                media_type: "application/json".into(),
                data: std::borrow::Cow::Owned(tube_json.into_bytes()),
            })
            .map_err(&err)?;
        let frame_schema = writer
            .add_schema(FRAME_SCHEMA, MESSAGE_ENCODING, b"packbed Frame: see the pellet_io crate documentation")
            .map_err(&err)?;
        let energy_schema = writer
            .add_schema(ENERGY_SCHEMA, MESSAGE_ENCODING, b"packbed EnergyRecord: see the pellet_io crate documentation")
            .map_err(&err)?;
        let checkpoint_schema = writer
            .add_schema(CHECKPOINT_SCHEMA, MESSAGE_ENCODING, b"packbed pack-run checkpoint: see the pellet_pack crate")
            .map_err(&err)?;
        let none = BTreeMap::new();
        let poses_channel = writer.add_channel(frame_schema, POSES_TOPIC, MESSAGE_ENCODING, &none).map_err(&err)?;
        let energy_channel = writer.add_channel(energy_schema, ENERGY_TOPIC, MESSAGE_ENCODING, &none).map_err(&err)?;
        let checkpoint_channel =
            writer.add_channel(checkpoint_schema, CHECKPOINT_TOPIC, MESSAGE_ENCODING, &none).map_err(&err)?;
        Ok(TrajectoryWriter {
            writer: Some(writer),
            part_path,
            final_path: path.to_path_buf(),
            copy_over,
            poses_channel,
            energy_channel,
            checkpoint_channel,
            poses_sequence: 0,
            energy_sequence: 0,
            checkpoint_sequence: 0,
            buf: Vec::with_capacity(1 << 16),
            viewer: None,
        })
    }

    /// Adds the Foxglove viewer channels: the tube now (drawn up to
    /// `tube_height_m`), each pellet's entity (`shapes` by type index) when it
    /// first appears in a frame, and every frame's transforms.
    pub fn enable_viewer(&mut self, tube: &Tube, tube_height_m: f64, shapes: Vec<ViewerShape>) -> Result<(), IoError> {
        let err = mcap_error(&self.part_path);
        let writer = self.writer.as_mut().ok_or_else(|| err(mcap::McapError::UnexpectedEof))?;
        let none = BTreeMap::new();
        let schema = |w: &mut mcap::Writer<BufWriter<File>>, name: &str, body: serde_json::Value| {
            w.add_schema(name, foxglove::VIEWER_SCHEMA_ENCODING, body.to_string().as_bytes()).map_err(&err)
        };
        let scene_schema = schema(writer, foxglove::SCENE_SCHEMA, foxglove::scene_schema())?;
        let transforms_schema = schema(writer, foxglove::TRANSFORMS_SCHEMA, foxglove::transforms_schema())?;
        let encoding = foxglove::VIEWER_MESSAGE_ENCODING;
        let scene_channel = writer.add_channel(scene_schema, foxglove::SCENE_TOPIC, encoding, &none).map_err(&err)?;
        let transforms_channel =
            writer.add_channel(transforms_schema, foxglove::TRANSFORMS_TOPIC, encoding, &none).map_err(&err)?;
        self.viewer = Some(Viewer {
            scene_channel,
            transforms_channel,
            shapes,
            announced: 0,
            scene_sequence: 1,
            transforms_sequence: 0,
        });
        self.buf = foxglove::scene_update(vec![foxglove::tube_entity(tube, tube_height_m)]).to_string().into_bytes();
        self.write(scene_channel, 1, 0.0)
    }

    /// The viewer messages that go with `frame`: entities of new pellets, then transforms.
    fn write_viewer(&mut self, frame: &Frame) -> Result<(), IoError> {
        let Some(v) = self.viewer.as_mut() else { return Ok(()) };
        let (scene, transforms) = (v.scene_channel, v.transforms_channel);
        let mut scene_sequence = None;
        if frame.positions.len() > v.announced {
            let mut entities = Vec::new();
            for i in v.announced..frame.positions.len() {
                let t = frame.type_index.get(i).copied().unwrap_or(0) as usize;
                if let Some(shape) = v.shapes.get(t).or(v.shapes.first()) {
                    entities.push(foxglove::pellet_entity(frame.time_s, i, shape));
                }
            }
            v.announced = frame.positions.len();
            v.scene_sequence += 1;
            scene_sequence = Some(v.scene_sequence);
            self.buf = foxglove::scene_update(entities).to_string().into_bytes();
        }
        if let Some(seq) = scene_sequence {
            self.write(scene, seq, frame.time_s)?;
        }
        let v = self.viewer.as_mut().expect("viewer checked above");
        v.transforms_sequence += 1;
        let seq = v.transforms_sequence;
        self.buf = foxglove::frame_transforms(frame).to_string().into_bytes();
        self.write(transforms, seq, frame.time_s)
    }

    fn write(&mut self, channel: u16, sequence: u32, time_s: f64) -> Result<(), IoError> {
        let err = mcap_error(&self.part_path);
        let writer = self.writer.as_mut().ok_or_else(|| err(mcap::McapError::UnexpectedEof))?;
        let header = mcap::records::MessageHeader {
            channel_id: channel,
            sequence,
            log_time: log_time(time_s),
            publish_time: log_time(time_s),
        };
        writer.write_to_known_channel(&header, &self.buf).map_err(&err)
    }

    /// Appends a pose frame.
    pub fn write_frame(&mut self, frame: &Frame) -> Result<(), IoError> {
        encode(frame, &mut self.buf)?;
        self.poses_sequence += 1;
        self.write(self.poses_channel, self.poses_sequence, frame.time_s)?;
        self.write_viewer(frame)
    }

    /// Appends an energy record.
    pub fn write_energy(&mut self, record: &EnergyRecord) -> Result<(), IoError> {
        encode(record, &mut self.buf)?;
        self.energy_sequence += 1;
        self.write(self.energy_channel, self.energy_sequence, record.time_s)
    }

    /// Appends a checkpoint (bytes from [`encode_message`]) taken at `time_s` and closes the
    /// chunk, so that a killed run can be continued from it.
    pub fn write_checkpoint(&mut self, time_s: f64, bytes: &[u8]) -> Result<(), IoError> {
        self.buf.clear();
        self.buf.extend_from_slice(bytes);
        self.checkpoint_sequence += 1;
        self.write(self.checkpoint_channel, self.checkpoint_sequence, time_s)?;
        self.flush()
    }

    /// Closes the current chunk so that everything written so far survives a kill.
    pub fn flush(&mut self) -> Result<(), IoError> {
        let err = mcap_error(&self.part_path);
        match self.writer.as_mut() {
            Some(w) => w.flush().map_err(err),
            None => Ok(()),
        }
    }

    /// Writes the summary and footer, then renames `<path>.part` to `<path>`.
    pub fn finish(mut self) -> Result<PathBuf, IoError> {
        let err = mcap_error(&self.part_path);
        if let Some(mut w) = self.writer.take() {
            w.finish().map_err(&err)?;
            let mut inner = w.into_inner();
            use std::io::Write;
            inner.flush().map_err(|source| IoError::Io { path: self.part_path.display().to_string(), source })?;
        }
        let io = |source| IoError::Io { path: self.final_path.display().to_string(), source };
        if self.copy_over {
            let mut part = File::open(&self.part_path).map_err(io)?;
            let mut target = std::fs::OpenOptions::new().write(true).open(&self.final_path).map_err(io)?;
            std::io::copy(&mut part, &mut target).map_err(io)?;
            std::fs::remove_file(&self.part_path).map_err(io)?;
        } else {
            std::fs::rename(&self.part_path, &self.final_path).map_err(io)?;
        }
        Ok(self.final_path.clone())
    }

    /// The temporary path being written.
    pub fn part_path(&self) -> &Path {
        &self.part_path
    }
}

/// The tube attachment's JSON form, units in the key names.
#[derive(Serialize, Deserialize)]
struct TubeJson {
    diameter_m: f64,
    lid_height_m: Option<f64>,
}

fn tube_json(tube: &Tube) -> String {
    serde_json::to_string(&TubeJson { diameter_m: tube.diameter, lid_height_m: tube.lid_height }).unwrap_or_default()
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_full_disk_reads_as_the_operating_system_words_it() {
        let full = mcap::McapError::Io(std::io::Error::from_raw_os_error(28));
        let e = super::mcap_error(std::path::Path::new("run.mcap.part"))(full).to_string();
        assert!(e.starts_with("run.mcap.part: No space left on device"), "{e}");
    }
}
