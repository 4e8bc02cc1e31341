//! Every file packbed reads or writes, and the rules for writing them.
//!
//! Only this crate touches files, stdin and stdout, and only it knows the
//! byte layouts. Outputs are written atomically (a temporary file in the
//! target's directory, renamed into place when complete), so an error or an
//! interruption never leaves a partial file under the final name. The path
//! `-` means stdin or stdout.
//!
//! # The pellet file (`.pellet`)
//!
//! Written by `mkpellet`, read by `pack`, `voidprof` and `bedexport`.
//!
//! | bytes | content |
//! |---|---|
//! | 0..8 | magic `PBPELLET` |
//! | 8..12 | format version, u32 little-endian (currently [`PELLET_FORMAT_VERSION`]) |
//! | 12..n−4 | a [`PelletFile`] encoded with bincode 2 (`config::standard()` with fixed-width little-endian integers), serde layout |
//! | n−4..n | CRC-32 (IEEE, as zlib) of bytes 0..n−4, u32 little-endian; a mismatch is an error |
//!
//! Units: every length in the [`pellet_geom::Pellet`] is in **metres**
//! (mesh vertices, convex pieces, closed-form radii, bounding radius), mass
//! properties are **per unit density** (volume m³, area m², inertia m⁵:
//! multiply by a density in kg/m³ for kg and kg·m²). Shape parameters are
//! recorded in millimetres, as typed (fields end in `_mm`). The body frame
//! has its origin at the centroid and the symmetry axis along z.
//!
//! Compatibility: a reader accepts its own format version and the one
//! before it (version 1, without the checksum: read unchecked, with a note
//! on stderr), and fails with an error naming both versions otherwise.
//!
//! # The packing file (`.packing`)
//!
//! Written by `settle-check`, read by `voidprof` and `bedexport`: one
//! frame of a bed. Same layout as the pellet file (checksum included) with magic `PBPACKNG`
//! and its own version ([`PACKING_FORMAT_VERSION`]); the payload is a
//! [`PackingFile`]: provenance, the frame's time (s), the settle verdict,
//! and a [`pellet_geom::Bed`] — the tube (diameter and optional lid height,
//! m; axis z, floor z = 0), the pellet types (complete [`pellet_geom::Pellet`]s,
//! so the file alone is enough), and every pellet's type index, centroid
//! position (m) and unit quaternion (w, x, y, z) mapping body to world.
//!
//! # The trajectory (`.mcap`)
//!
//! Written by `pack`, read by `settle-check`: an [MCAP](https://mcap.dev)
//! file, zstd-compressed 1 MiB chunks with a summary and indexes, header
//! profile `packbed/1`. In order:
//!
//! - metadata record `packbed.run`: `tool`, `version`, `args`, `seed`,
//!   `units` (SI), `config` (the full run configuration as JSON) and `build`
//!   (the source `pack` was built from, `git <commit>`; a resumed run lists
//!   each leg's, `git a; from t = 24.230 s git b`);
//! - attachments `pellet-<i>.pellet` (the pellet files, byte for byte) and
//!   `tube.json` (`{"diameter_m": …, "lid_height_m": … | null}`), so the
//!   file alone is enough to analyse the bed;
//! - channel `/pack/poses`, schema `packbed.Frame.v1`: a [`Frame`] every
//!   recorded interval (time, type index, positions in m, unit quaternions
//!   w, x, y, z, optional velocities);
//! - channel `/pack/energy`, schema `packbed.EnergyRecord.v1`: an
//!   [`EnergyRecord`] every step (kinetic, potential and dissipated energies
//!   in J, contact counts, solver residual, max penetration in m);
//! - channel `/pack/checkpoint`, schema `packbed.Checkpoint.v1`: now and
//!   then (`pack --checkpoint-every`, simulated seconds) and at the end, the
//!   complete state of the run (bodies with momenta, warm-start forces,
//!   loader, settle history; `pellet_pack::Checkpoint`), each closing its
//!   chunk; `pack --resume` continues from the last one, bit for bit.
//!
//! The channels use message encoding `x-packbed-bincode2-v1`: bincode 2
//! with the standard configuration and fixed-width little-endian integers,
//! serde layout of the Rust types. Log times are simulated nanoseconds.
//! `pack` writes to `<name>.part` and renames it when done; a killed run
//! leaves the `.part` file, readable up to its last complete chunk.
//! # Pellet poses from elsewhere (CSV)
//!
//! `voidprof --poses` reads beds made by other generators as CSV:
//! `id,x,y,z[,qw,qx,qy,qz]`, millimetres, body → world quaternions; see
//! [`decode_poses_csv`] and the `poses_csv` module for the details.
//!
//! # Meshes
//!
//! STL (binary or ASCII) and Wavefront OBJ are read into
//! [`pellet_geom::TriMesh`]; STL is written binary (f32, the common
//! hand-off to CFD meshers) and OBJ as text. STL has no unit: packbed
//! writes millimetres unless told otherwise.
#![deny(missing_docs)]

mod atomic;
pub mod foxglove;
mod framed;
mod mcap_records;
mod mesh_files;
mod packing_file;
mod pellet_file;
mod poses_csv;
mod reason;
mod stdout;
mod stl_read;
mod trajectory;

pub use atomic::{is_special_file, read_input, remove_temporary_files_on_signal, write_outputs, OutputFile};
pub use mesh_files::{obj_bytes, read_mesh, stl_bytes, MeshFormat};
pub use packing_file::{
    decode_packing, encode_packing, PackingFile, SettleVerdict, PACKING_FORMAT_VERSION, PACKING_MAGIC,
};
pub use pellet_file::{decode_pellet, encode_pellet, PelletFile, Provenance, PELLET_FORMAT_VERSION, PELLET_MAGIC};
pub use poses_csv::decode_poses_csv;
pub use reason::plain_reason;
pub use stdout::{require_stdout, stdout_closed};
pub use trajectory::{
    decode_message, encode_message, read_trajectory, read_trajectory_with, EnergyRecord, Frame, ReadOptions,
    Trajectory, TrajectoryHeader, TrajectoryWriter, CHECKPOINT_TOPIC, ENERGY_TOPIC, MESSAGE_ENCODING, POSES_TOPIC,
    RUN_METADATA, TRAJECTORY_PROFILE,
};

/// What can go wrong reading or writing packbed's files.
#[derive(Debug, thiserror::Error)]
pub enum IoError {
    /// The tool was started with stdout closed (`>&-`), and a result was to go there.
    #[error(
        "cannot write to standard output: it is closed; redirect it to a file (or to /dev/null to discard the output)"
    )]
    StdoutClosed,
    /// The operating system refused a read or write.
    #[error("{path}: {}", plain_reason(source))]
    Io {
        /// The file involved.
        path: String,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The bytes are not a file of the expected kind.
    #[error("{path}: not a packbed {kind} file (magic {found:?}, expected {expected:?}); {remedy}")]
    BadMagic {
        /// The file involved.
        path: String,
        /// What kind of file was expected.
        kind: String,
        /// How to make one.
        remedy: String,
        /// The first bytes found.
        found: String,
        /// The magic expected.
        expected: String,
    },
    /// The file's format version is not this build's.
    #[error("{path}: {kind} format version {found}, but this build reads version {supported}; {remedy}")]
    UnsupportedVersion {
        /// The file involved.
        path: String,
        /// What kind of file.
        kind: String,
        /// How to make one this build reads.
        remedy: String,
        /// Version in the file.
        found: u32,
        /// Version this build reads.
        supported: u32,
    },
    /// The file is truncated or corrupt.
    #[error("{path}: {reason}")]
    Corrupt {
        /// The file involved.
        path: String,
        /// What is wrong.
        reason: String,
    },
    /// A trajectory that ends before its MCAP header is complete: a run killed as it began,
    /// which recorded nothing.
    #[error(
        "{path}: truncated: the file ends within its MCAP header ({len} bytes), before any of the run was recorded; run `pack` again"
    )]
    CutInHeader {
        /// The file involved.
        path: String,
        /// Its length (bytes).
        len: usize,
    },
    /// Refused to write binary data to a terminal.
    #[error("refusing to write binary {what} to a terminal; give a file name with -o or redirect stdout")]
    BinaryToTerminal {
        /// What would have been written.
        what: String,
    },
}
