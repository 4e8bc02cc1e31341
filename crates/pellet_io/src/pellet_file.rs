//! The `.pellet` file: magic, version, bincode payload (see the crate doc).

use serde::{Deserialize, Serialize};

use pellet_geom::Pellet;

use crate::framed::Format;
use crate::IoError;

/// The first eight bytes of every pellet file.
pub const PELLET_MAGIC: &[u8; 8] = b"PBPELLET";
/// The pellet format version this build writes and reads.
pub const PELLET_FORMAT_VERSION: u32 = crate::framed::CHECKED_VERSION;

/// Who wrote a file and how: enough to make it again.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Provenance {
    /// The tool (e.g. `mkpellet`).
    pub tool: String,
    /// The tool's version.
    pub version: String,
    /// The command-line arguments after the program name.
    pub args: Vec<String>,
}

/// The payload of a pellet file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PelletFile {
    /// Length unit of every geometric quantity in `pellet` (always `"m"`).
    pub length_unit: String,
    /// Who wrote the file.
    pub provenance: Provenance,
    /// The pellet.
    pub pellet: Pellet,
}

const FORMAT: Format = Format {
    magic: PELLET_MAGIC,
    version: PELLET_FORMAT_VERSION,
    kind: "pellet",
    remedy: "make it again with `mkpellet`",
};

/// The bytes of a pellet file.
pub fn encode_pellet(file: &PelletFile) -> Result<Vec<u8>, IoError> {
    FORMAT.encode(file)
}

/// Reads a pellet file's bytes; `path` is only used in error messages.
pub fn decode_pellet(bytes: &[u8], path: &str) -> Result<PelletFile, IoError> {
    let file: PelletFile = FORMAT.decode(bytes, path)?;
    if file.length_unit != "m" {
        return Err(IoError::Corrupt {
            path: path.into(),
            reason: format!("length unit {:?}, expected \"m\"", file.length_unit),
        });
    }
    Ok(file)
}
