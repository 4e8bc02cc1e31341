//! The `.pellet` file: magic, version, bincode payload (see the crate doc).

use serde::{Deserialize, Serialize};

use pellet_geom::Pellet;

use crate::IoError;

/// The first eight bytes of every pellet file.
pub const PELLET_MAGIC: &[u8; 8] = b"PBPELLET";
/// The pellet format version this build writes and reads.
pub const PELLET_FORMAT_VERSION: u32 = 1;

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

fn config() -> impl bincode::config::Config {
    // The limit stops a corrupt length prefix from asking for terabytes.
    bincode::config::standard().with_fixed_int_encoding().with_little_endian().with_limit::<{ 1 << 31 }>()
}

/// The bytes of a pellet file.
pub fn encode_pellet(file: &PelletFile) -> Result<Vec<u8>, IoError> {
    let mut out = Vec::with_capacity(1 << 16);
    out.extend_from_slice(PELLET_MAGIC);
    out.extend_from_slice(&PELLET_FORMAT_VERSION.to_le_bytes());
    let payload = bincode::serde::encode_to_vec(file, config())
        .map_err(|e| IoError::Corrupt { path: "<pellet>".into(), reason: format!("cannot encode: {e}") })?;
    out.extend_from_slice(&payload);
    Ok(out)
}

/// Reads a pellet file's bytes; `path` is only used in error messages.
pub fn decode_pellet(bytes: &[u8], path: &str) -> Result<PelletFile, IoError> {
    if bytes.len() < 12 || &bytes[..8] != PELLET_MAGIC {
        let head = &bytes[..bytes.len().min(8)];
        return Err(IoError::BadMagic {
            path: path.into(),
            found: String::from_utf8_lossy(head).into_owned(),
            expected: String::from_utf8_lossy(PELLET_MAGIC).into_owned(),
        });
    }
    let version = u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]);
    if version != PELLET_FORMAT_VERSION {
        return Err(IoError::UnsupportedVersion {
            path: path.into(),
            found: version,
            supported: PELLET_FORMAT_VERSION,
        });
    }
    let (file, used): (PelletFile, usize) =
        bincode::serde::decode_from_slice(&bytes[12..], config()).map_err(|e| IoError::Corrupt {
            path: path.into(),
            reason: format!("truncated or corrupt pellet file ({e}); re-make it with `mkpellet`"),
        })?;
    if used != bytes.len() - 12 {
        return Err(IoError::Corrupt {
            path: path.into(),
            reason: format!("{} unexpected bytes after the pellet data", bytes.len() - 12 - used),
        });
    }
    if file.length_unit != "m" {
        return Err(IoError::Corrupt {
            path: path.into(),
            reason: format!("length unit {:?}, expected \"m\"", file.length_unit),
        });
    }
    Ok(file)
}
