//! The `.packing` file: one frame of a bed, self-describing (see the crate doc).

use serde::{Deserialize, Serialize};

use pellet_geom::Bed;

use crate::pellet_file::Provenance;
use crate::IoError;

/// The first eight bytes of every packing file.
pub const PACKING_MAGIC: &[u8; 8] = b"PBPACKNG";
/// The packing format version this build writes and reads.
pub const PACKING_FORMAT_VERSION: u32 = 1;

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

fn config() -> impl bincode::config::Config {
    // The limit stops a corrupt length prefix from asking for terabytes.
    bincode::config::standard().with_fixed_int_encoding().with_little_endian().with_limit::<{ 1 << 31 }>()
}

/// The bytes of a packing file.
pub fn encode_packing(file: &PackingFile) -> Result<Vec<u8>, IoError> {
    let mut out = Vec::with_capacity(1 << 16);
    out.extend_from_slice(PACKING_MAGIC);
    out.extend_from_slice(&PACKING_FORMAT_VERSION.to_le_bytes());
    let payload = bincode::serde::encode_to_vec(file, config())
        .map_err(|e| IoError::Corrupt { path: "<packing>".into(), reason: format!("cannot encode: {e}") })?;
    out.extend_from_slice(&payload);
    Ok(out)
}

/// Reads a packing file's bytes; `path` is only used in error messages.
pub fn decode_packing(bytes: &[u8], path: &str) -> Result<PackingFile, IoError> {
    if bytes.len() < 12 || &bytes[..8] != PACKING_MAGIC {
        return Err(IoError::Corrupt {
            path: path.into(),
            reason: "not a packbed packing file (bad magic); make one with `settle-check … -o bed.packing`".into(),
        });
    }
    let version = u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]);
    if version != PACKING_FORMAT_VERSION {
        return Err(IoError::Corrupt {
            path: path.into(),
            reason: format!("packing format version {version}, but this build reads version {PACKING_FORMAT_VERSION}"),
        });
    }
    let (file, used): (PackingFile, usize) =
        bincode::serde::decode_from_slice(&bytes[12..], config()).map_err(|e| IoError::Corrupt {
            path: path.into(),
            reason: format!("truncated or corrupt packing file ({e})"),
        })?;
    if used != bytes.len() - 12 {
        return Err(IoError::Corrupt { path: path.into(), reason: "unexpected bytes after the packing data".into() });
    }
    file.bed.validate().map_err(|e| IoError::Corrupt { path: path.into(), reason: e.to_string() })?;
    Ok(file)
}
