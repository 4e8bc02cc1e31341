//! The records of an MCAP file, chunks unpacked, with a bound on every record's length.
//!
//! Why not `mcap::read::ChunkFlattener`: it leaves the sans-io reader's record-length limit
//! unset (its `LinearReader` sets it; 0.26), and the reader reserves a record's declared length
//! before it decompresses it. A trajectory with one corrupt byte in a chunk then asked the
//! allocator for ~5e17 bytes and the process aborted or panicked ("capacity overflow") instead
//! of reporting a corrupt file. This drives the same sans-io reader with a limit.
//!
//! [`Salvage`] reads past a damaged record, for `pack --resume`: a run whose file took one bad
//! byte goes on from its last checkpoint that reads instead of being lost.

use mcap::records::{op, Record};
use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};
use mcap::McapResult;

/// Longest record accepted, uncompressed: the file's own length times 64 or 64 MiB, whichever is
/// larger, and never over 1 GiB. `pack`'s records (a frame, an energy record, a checkpoint of one
/// bed, the pellet file) are far below that, and no record inside a chunk can be longer than the
/// chunk uncompressed, which zstd keeps within a small multiple of the file.
pub fn record_length_limit(file_len: usize) -> usize {
    file_len.saturating_mul(64).clamp(64 << 20, 1 << 30)
}

/// Iterates over the records of `bytes` (an MCAP file from its magic on; a missing end magic is
/// accepted, as in a killed run), chunks unpacked. Stops after the first error.
pub struct Records<'a> {
    rest: &'a [u8],
    reader: LinearReader,
    failed: bool,
}

impl<'a> Records<'a> {
    /// A reader over the whole file, each chunk's CRC checked before any of its records is
    /// given: a damaged byte in a chunk is found as damage, not read as other numbers.
    pub fn new(bytes: &'a [u8]) -> Self {
        let options = LinearReaderOptions::default()
            .with_skip_end_magic(true)
            .with_prevalidate_chunk_crcs(true)
            .with_record_length_limit(record_length_limit(bytes.len()));
        Records { rest: bytes, reader: LinearReader::new_with_options(options), failed: false }
    }

    /// A reader over one complete top-level record (`bytes` from its opcode on), chunk CRCs
    /// checked before any of its records is given.
    fn record(bytes: &'a [u8], limit: usize) -> Self {
        let options = LinearReaderOptions::default()
            .with_skip_start_magic(true)
            .with_skip_end_magic(true)
            .with_prevalidate_chunk_crcs(true)
            .with_record_length_limit(limit);
        Records { rest: bytes, reader: LinearReader::new_with_options(options), failed: false }
    }
}

impl<'a> Iterator for Records<'a> {
    type Item = McapResult<Record<'static>>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.failed {
            return None;
        }
        while let Some(event) = self.reader.next_event() {
            match event {
                Ok(LinearReadEvent::ReadRequest(need)) => {
                    let n = need.min(self.rest.len());
                    self.reader.insert(n).copy_from_slice(&self.rest[..n]);
                    self.reader.notify_read(n);
                    self.rest = &self.rest[n..];
                }
                Ok(LinearReadEvent::Record { data, opcode }) => {
                    let record = mcap::parse_record(opcode, data).map(Record::into_owned);
                    self.failed = record.is_err();
                    return Some(record);
                }
                Err(e) => {
                    self.failed = true;
                    return Some(Err(e));
                }
            }
        }
        None
    }
}

/// A stretch of a file that [`Salvage`] skipped.
#[derive(Clone, Debug, PartialEq)]
pub struct Skipped {
    /// Offset of its first byte.
    pub offset: usize,
    /// Its length (bytes).
    pub len: usize,
    /// What was wrong at its start.
    pub reason: String,
}

/// Iterates over the records of `bytes` as [`Records`] does, but goes on past damage: a record
/// that does not read (a chunk that fails its CRC check, say) is skipped, and reading goes on at
/// the next chunk that reads whole, its CRC checked; each skipped stretch is in `skipped`. A tail
/// that is no complete record and is followed by no such chunk (a killed run's cut) ends it, the
/// reason in `cut`.
pub struct Salvage<'a> {
    bytes: &'a [u8],
    pos: usize,
    limit: usize,
    pending: std::vec::IntoIter<Record<'static>>,
    /// The stretches skipped so far.
    pub skipped: Vec<Skipped>,
    /// Why reading stopped before the end of the file.
    pub cut: Option<String>,
}

/// Why a record did not read: `Cut` if it runs past the end of the file.
enum Failure {
    Cut(String),
    Bad(String),
}

impl<'a> Salvage<'a> {
    /// A reader over the whole file (which starts with the MCAP magic).
    pub fn new(bytes: &'a [u8]) -> Self {
        Salvage {
            bytes,
            pos: mcap::MAGIC.len().min(bytes.len()),
            limit: record_length_limit(bytes.len()),
            pending: Vec::new().into_iter(),
            skipped: Vec::new(),
            cut: None,
        }
    }

    /// The records of the complete record at `pos`, and where the next one starts.
    fn record_at(&self, pos: usize, resync: bool) -> Result<(Vec<Record<'static>>, usize), Failure> {
        let rest = &self.bytes[pos..];
        let Some((&opcode, len)) = rest.split_first().filter(|_| rest.len() >= 9) else {
            return Err(Failure::Cut("the file ends within a record's header".into()));
        };
        let len = u64::from_le_bytes(len[..8].try_into().expect("8 bytes"));
        let Some(end) = usize::try_from(len).ok().and_then(|l| l.checked_add(9)).filter(|&e| e <= rest.len()) else {
            return Err(Failure::Cut(format!("a record of {len} bytes runs past the end of the file")));
        };
        let body = &rest[9..end];
        let bad = |e: mcap::McapError| Failure::Bad(e.to_string());
        if opcode != op::CHUNK {
            return Ok((vec![mcap::parse_record(opcode, body).map_err(bad)?.into_owned()], pos + end));
        }
        let Record::Chunk { header, data } = mcap::parse_record(op::CHUNK, body).map_err(bad)? else {
            unreachable!("a chunk opcode parses as a chunk");
        };
        // A length field that grew would pass the rest off as padding, swallowing later chunks.
        let header_len = 40 + header.compression.len();
        if body.len() != header_len + data.len() {
            return Err(Failure::Bad("a chunk's length disagrees with its header".into()));
        }
        // A chunk found by searching must prove itself: a CRC, not just bytes that decompress.
        if resync && header.uncompressed_crc == 0 {
            return Err(Failure::Bad("a chunk without a CRC".into()));
        }
        let records = Records::record(&rest[..end], self.limit).collect::<Result<Vec<_>, _>>().map_err(bad)?;
        Ok((records, pos + end))
    }

    /// The offset of the first chunk at or after `from` that reads whole.
    fn next_sound_chunk(&self, from: usize) -> Option<usize> {
        let mut at = from;
        while let Some(i) = self.bytes.get(at..)?.iter().position(|&b| b == op::CHUNK) {
            if self.record_at(at + i, true).is_ok() {
                return Some(at + i);
            }
            at += i + 1;
        }
        None
    }
}

impl Iterator for Salvage<'_> {
    type Item = Record<'static>;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            if let Some(record) = self.pending.next() {
                return Some(record);
            }
            if self.pos >= self.bytes.len() {
                return None;
            }
            match self.record_at(self.pos, false) {
                Ok((records, next)) => {
                    // The end magic follows the footer.
                    let footer = records.iter().any(|r| matches!(r, Record::Footer(_)));
                    self.pos = if footer { self.bytes.len() } else { next };
                    self.pending = records.into_iter();
                }
                Err(failure) => {
                    let next = self.next_sound_chunk(self.pos + 1);
                    let (reason, cut) = match failure {
                        Failure::Cut(r) => (r, next.is_none()),
                        Failure::Bad(r) => (r, false),
                    };
                    if cut {
                        self.cut = Some(reason);
                    } else {
                        let end = next.unwrap_or(self.bytes.len());
                        self.skipped.push(Skipped { offset: self.pos, len: end - self.pos, reason });
                    }
                    self.pos = next.unwrap_or(self.bytes.len());
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_limit_grows_with_the_file_and_is_capped() {
        assert_eq!(record_length_limit(0), 64 << 20);
        assert_eq!(record_length_limit(2 << 20), 128 << 20);
        assert_eq!(record_length_limit(usize::MAX), 1 << 30);
    }

    /// A file of one zstd chunk holding `inner` (records as they are before compression).
    fn file_with_chunk(inner: &[u8]) -> Vec<u8> {
        let compressed = zstd::encode_all(inner, 3).unwrap();
        let mut chunk = Vec::new();
        chunk.extend_from_slice(&0u64.to_le_bytes()); // message start time
        chunk.extend_from_slice(&0u64.to_le_bytes()); // message end time
        chunk.extend_from_slice(&(inner.len() as u64).to_le_bytes());
        chunk.extend_from_slice(&0u32.to_le_bytes()); // no CRC
        chunk.extend_from_slice(&4u32.to_le_bytes());
        chunk.extend_from_slice(b"zstd");
        chunk.extend_from_slice(&(compressed.len() as u64).to_le_bytes());
        chunk.extend_from_slice(&compressed);
        let mut f = mcap::MAGIC.to_vec();
        f.push(0x06);
        f.extend_from_slice(&(chunk.len() as u64).to_le_bytes());
        f.extend_from_slice(&chunk);
        f
    }

    #[test]
    fn a_record_in_a_chunk_with_a_corrupt_length_is_an_error_not_an_abort() {
        // A message record (opcode 0x05) whose length field says 2^62 bytes. Through
        // ChunkFlattener this aborted the test process ("capacity overflow" / failed allocation).
        let mut inner = vec![0x05];
        inner.extend_from_slice(&(1u64 << 62).to_le_bytes());
        inner.extend_from_slice(&[7; 100]);
        let events: Vec<_> = Records::new(&file_with_chunk(&inner)).collect();
        assert_eq!(events.len(), 1, "{events:?}");
        let err = events[0].as_ref().expect_err("refused").to_string();
        assert!(err.contains("exceeds limit"), "{err}");
    }

    #[test]
    fn a_sound_chunk_gives_its_records() {
        // A Channel-less message: parsed as a record all the same.
        let mut inner = vec![0x05];
        let body = [[0u8; 2].as_slice(), &[0; 4], &[0; 8], &[0; 8], b"hi"].concat();
        inner.extend_from_slice(&(body.len() as u64).to_le_bytes());
        inner.extend_from_slice(&body);
        let records: Vec<_> = Records::new(&file_with_chunk(&inner)).collect::<Result<_, _>>().unwrap();
        assert!(matches!(&records[..], [Record::Message { data, .. }] if data.as_ref() == b"hi"), "{records:?}");
    }
}
