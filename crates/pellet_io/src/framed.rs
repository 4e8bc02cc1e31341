//! The layout shared by packbed's own binary files: an 8-byte magic, a
//! u32 little-endian format version, a bincode 2 payload and, from
//! [`CHECKED_VERSION`] on, the CRC-32 (IEEE) of everything before it as a
//! u32 little-endian, so that a damaged byte is found on read instead of
//! becoming a wrong vertex.

use serde::de::DeserializeOwned;
use serde::Serialize;

use crate::IoError;

/// The first version with a checksum, of both the pellet and the packing format. The
/// version before it is read unchecked, with a note.
pub(crate) const CHECKED_VERSION: u32 = 2;

/// One framed file format.
pub(crate) struct Format {
    /// The first eight bytes.
    pub magic: &'static [u8; 8],
    /// The version this build writes and reads.
    pub version: u32,
    /// What the file is, for messages ("pellet", "packing").
    pub kind: &'static str,
    /// How to make one, for messages.
    pub remedy: &'static str,
}

/// bincode 2, standard configuration, fixed-width little-endian integers.
/// The limit stops a corrupt length prefix from asking for terabytes.
pub(crate) fn config() -> impl bincode::config::Config {
    bincode::config::standard().with_fixed_int_encoding().with_little_endian().with_limit::<{ 1 << 31 }>()
}

impl Format {
    /// Magic, version and payload.
    pub fn encode<T: Serialize>(&self, value: &T) -> Result<Vec<u8>, IoError> {
        let mut out = Vec::with_capacity(1 << 16);
        out.extend_from_slice(self.magic);
        out.extend_from_slice(&self.version.to_le_bytes());
        bincode::serde::encode_into_std_write(value, &mut out, config()).map_err(|e| IoError::Corrupt {
            path: format!("<{}>", self.kind),
            reason: format!("cannot encode: {e}"),
        })?;
        let crc = crc32fast::hash(&out);
        out.extend_from_slice(&crc.to_le_bytes());
        Ok(out)
    }

    /// Checks the magic and the version and decodes the payload, which must fill the rest.
    pub fn decode<T: DeserializeOwned>(&self, bytes: &[u8], path: &str) -> Result<T, IoError> {
        if bytes.len() < 12 || &bytes[..8] != self.magic {
            let head = &bytes[..bytes.len().min(8)];
            return Err(IoError::BadMagic {
                path: path.into(),
                kind: self.kind.into(),
                found: String::from_utf8_lossy(head).into_owned(),
                expected: String::from_utf8_lossy(self.magic).into_owned(),
                remedy: self.remedy.into(),
            });
        }
        let version = u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]);
        let checked = version == self.version;
        if !checked && version != CHECKED_VERSION - 1 {
            return Err(IoError::UnsupportedVersion {
                path: path.into(),
                kind: self.kind.into(),
                found: version,
                supported: self.version,
                remedy: self.remedy.into(),
            });
        }
        // The payload ends before the checksum; decoded first, so that a cut file reads as cut.
        let end = if checked { bytes.len().saturating_sub(4).max(12) } else { bytes.len() };
        let (value, used): (T, usize) =
            bincode::serde::decode_from_slice(&bytes[12..end], config()).map_err(|e| IoError::Corrupt {
                path: path.into(),
                reason: format!("the {} file {}; {}", self.kind, what_is_wrong(&e), self.remedy),
            })?;
        if used != end - 12 {
            return Err(IoError::Corrupt {
                path: path.into(),
                reason: format!("{} unexpected bytes after the {} data", end - 12 - used, self.kind),
            });
        }
        if !checked {
            eprintln!(
                "{}: note: {path}: a {} file of format version {version}, from before checksums, read unchecked; {} to add one",
                program(),
                self.kind,
                self.remedy
            );
        } else if bytes[end..] != crc32fast::hash(&bytes[..end]).to_le_bytes()[..] {
            return Err(IoError::Corrupt {
                path: path.into(),
                reason: format!(
                    "the {} file's checksum does not match its contents: it was changed or damaged after it was written; {}",
                    self.kind, self.remedy
                ),
            });
        }
        Ok(value)
    }
}

/// A decoding error in the reader's terms: the decoder's own names (`UnexpectedEnd`,
/// `LimitExceeded`) mean nothing to someone holding a damaged file.
pub(crate) fn what_is_wrong(e: &bincode::error::DecodeError) -> &'static str {
    use bincode::error::DecodeError as E;
    match e {
        E::UnexpectedEnd { .. } => "is truncated (its data ends early)",
        E::LimitExceeded | E::OutsideUsizeRange(_) => "is corrupt (a length in it is impossibly large)",
        E::Utf8 { .. } | E::InvalidCharEncoding(_) => "is corrupt (a text in it is not UTF-8)",
        _ => "is corrupt (its data does not decode)",
    }
}

/// The running tool's name, for the note's `tool: note:` prefix.
fn program() -> String {
    std::env::args()
        .next()
        .and_then(|a| std::path::Path::new(&a).file_name().map(|n| n.to_string_lossy().into_owned()))
        .unwrap_or_else(|| "packbed".into())
}
