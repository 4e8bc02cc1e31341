//! The `.pellet` file: magic, version, bincode payload (see the crate doc).

use serde::{Deserialize, Serialize};

use pellet_geom::math::shown;
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
    check_pellet(&file.pellet)
        .map_err(|e| IoError::Corrupt { path: path.into(), reason: format!("the pellet {e}; {}", FORMAT.remedy) })?;
    Ok(file)
}

/// The checks a pellet passes before any tool computes with it: a file whose checksum matches
/// may still have been written by something else, or by a version with a bug, and a triangle
/// pointing past the vertices or a NaN radius would panic or poison every result downstream.
pub(crate) fn check_pellet(p: &Pellet) -> Result<(), String> {
    let mesh = &p.mesh;
    if mesh.triangles.is_empty() {
        return Err("has no triangles".into());
    }
    if let Some(v) = mesh.vertices.iter().position(|v| !v.iter().all(|c| c.is_finite())) {
        return Err(format!("vertex {v} is not a finite point"));
    }
    let n = mesh.vertices.len();
    if let Some(t) = mesh.triangles.iter().position(|t| t.iter().any(|&i| i as usize >= n)) {
        return Err(format!("triangle {t} names a vertex past the {n} it has"));
    }
    let positive = |x: f64| x.is_finite() && x > 0.0;
    if !positive(p.bounding_radius) {
        return Err(format!("bounding radius {} m is not a positive number", shown(p.bounding_radius)));
    }
    let m = &p.properties;
    if !positive(m.volume) || !positive(m.area) {
        return Err(format!("volume {} m³ or area {} m² is not a positive number", shown(m.volume), shown(m.area)));
    }
    let finite = |s: &[f64]| s.iter().all(|c| c.is_finite());
    if !(finite(m.centroid.coords.as_slice())
        && finite(m.inertia.as_slice())
        && finite(m.principal_moments.as_slice())
        && finite(m.principal_axes.as_slice()))
    {
        return Err("has a mass property that is not a finite number".into());
    }
    Ok(())
}
