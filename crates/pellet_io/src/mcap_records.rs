//! The records of an MCAP file, chunks unpacked, with a bound on every record's length.
//!
//! Why not `mcap::read::ChunkFlattener`: it leaves the sans-io reader's record-length limit
//! unset (its `LinearReader` sets it; 0.26), and the reader reserves a record's declared length
//! before it decompresses it. A trajectory with one corrupt byte in a chunk then asked the
//! allocator for ~5e17 bytes and the process aborted or panicked ("capacity overflow") instead
//! of reporting a corrupt file. This drives the same sans-io reader with a limit.

use mcap::records::Record;
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
    /// A reader over the whole file.
    pub fn new(bytes: &'a [u8]) -> Self {
        let options = LinearReaderOptions::default()
            .with_skip_end_magic(true)
            .with_record_length_limit(record_length_limit(bytes.len()));
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
