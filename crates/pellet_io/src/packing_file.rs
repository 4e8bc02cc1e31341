//! The `.packing` file: one frame of a bed, self-describing (see the crate doc).

use serde::{Deserialize, Serialize};

use pellet_geom::Bed;

use crate::framed::Format;
use crate::pellet_file::Provenance;
use crate::IoError;

/// The first eight bytes of every packing file.
pub const PACKING_MAGIC: &[u8; 8] = b"PBPACKNG";
/// The packing format version this build writes and reads.
pub const PACKING_FORMAT_VERSION: u32 = crate::framed::CHECKED_VERSION;

/// How the frame was chosen and what the termination test said.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SettleVerdict {
    /// Whether the kinetic-energy test found the bed settled.
    pub settled: bool,
    /// Simulated time at which it settled (s), if it did.
    pub settle_time_s: Option<f64>,
    /// Total kinetic energy at the frame (J).
    pub kinetic_energy_j: f64,
}

/// The payload of a packing file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PackingFile {
    /// Length unit of every geometric quantity (always `"m"`).
    pub length_unit: String,
    /// Who wrote the file.
    pub provenance: Provenance,
    /// Simulated time of the frame (s).
    pub time_s: f64,
    /// The settle verdict, when the frame came from a settle test.
    pub verdict: Option<SettleVerdict>,
    /// The tube, the pellet types and the poses.
    pub bed: Bed,
}

const FORMAT: Format = Format {
    magic: PACKING_MAGIC,
    version: PACKING_FORMAT_VERSION,
    kind: "packing",
    remedy: "make one with `settle-check bed.mcap -o bed.packing`",
};

/// The bytes of a packing file.
pub fn encode_packing(file: &PackingFile) -> Result<Vec<u8>, IoError> {
    FORMAT.encode(file)
}

/// Reads a packing file's bytes; `path` is only used in error messages.
pub fn decode_packing(bytes: &[u8], path: &str) -> Result<PackingFile, IoError> {
    let file: PackingFile = FORMAT.decode(bytes, path)?;
    file.bed.validate().map_err(|e| IoError::Corrupt { path: path.into(), reason: e.to_string() })?;
    for (i, pellet) in file.bed.pellet_types.iter().enumerate() {
        crate::pellet_file::check_pellet(pellet).map_err(|e| IoError::Corrupt {
            path: path.into(),
            reason: format!("pellet type {i} {e}; {}", FORMAT.remedy),
        })?;
    }
    Ok(file)
}
