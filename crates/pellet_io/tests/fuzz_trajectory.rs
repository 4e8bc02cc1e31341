//! The MCAP trajectory, damaged every way: every cut in its first 4 KiB and a sample after, and
//! random flipped bytes, read strictly and salvaging. Each read is a value or a one-line error,
//! never a panic; a damaged file says it is damaged, a cut one that it is cut.

mod common;

use common::*;
use pellet_io::{decode_pellet, read_trajectory, read_trajectory_with, EnergyRecord, Frame, ReadOptions, Trajectory};
use proptest::prelude::*;

/// A run of five pellets over 0.3 s: a frame and an energy record every 0.01 s, a checkpoint
/// closing a chunk every 0.1 s.
fn trajectory() -> Vec<u8> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("run.mcap");
    let mut w = trajectory_writer(&path);
    for i in 0..30 {
        let t = i as f64 * 0.01;
        let frame = Frame {
            time_s: t,
            type_index: vec![0; 5],
            positions: (0..5).map(|k| [0.01 * k as f64, 0.0, 0.1 - t]).collect(),
            orientations: vec![[1.0, 0.0, 0.0, 0.0]; 5],
            velocities: None,
        };
        w.write_frame(&frame).unwrap();
        w.write_energy(&EnergyRecord { time_s: t, pellets: 5, ..EnergyRecord::default() }).unwrap();
        if i % 10 == 9 {
            w.write_checkpoint(t, &[i as u8; 32]).unwrap();
        }
    }
    w.finish().unwrap();
    std::fs::read(&path).unwrap()
}

fn sample() -> &'static [u8] {
    static BYTES: std::sync::OnceLock<Vec<u8>> = std::sync::OnceLock::new();
    BYTES.get_or_init(trajectory)
}

/// Everything a tool prints of a trajectory read back is one readable line each, and its
/// pellet files are read as the tools read them.
fn check_read(r: Result<Trajectory, pellet_io::IoError>) -> Option<Trajectory> {
    let t = check(r)?;
    if let Some(why) = &t.truncated {
        assert_readable(why);
    }
    t.damaged.iter().for_each(assert_readable);
    for bytes in &t.pellet_files {
        check(decode_pellet(bytes, "attached.pellet"));
    }
    Some(t)
}

const SALVAGE: ReadOptions = ReadOptions { skip_damage: true, skip_frames: false };

#[test]
fn every_cut_of_a_trajectory_reads_up_to_the_cut_or_is_an_error() {
    let bytes = sample();
    for cut in cuts(bytes.len()) {
        let part = &bytes[..cut];
        if let Some(t) = check_read(read_trajectory(part, "cut.mcap")) {
            assert!(t.damaged.is_empty(), "cut at {cut}: a cut read as damage: {:?}", t.damaged);
        }
        check_read(read_trajectory_with(part, "cut.mcap", SALVAGE));
    }
}

/// The offsets of the chunk records (opcode 0x06), walking the records after the magic.
fn chunks(bytes: &[u8]) -> Vec<usize> {
    let (mut at, mut out) = (8, Vec::new());
    while at + 9 <= bytes.len() {
        let len = u64::from_le_bytes(bytes[at + 1..at + 9].try_into().unwrap()) as usize;
        if bytes[at] == 0x06 {
            out.push(at);
        }
        at += 9 + len;
    }
    out
}

#[test]
fn a_damaged_chunk_reads_as_damaged_not_truncated() {
    let whole = sample();
    let chunks = chunks(whole);
    assert!(chunks.len() >= 3, "{chunks:?}");
    let mut bytes = whole.to_vec();
    bytes[chunks[1] + 120] ^= 0x5a; // in the second chunk's compressed data
    let t = read_trajectory(&bytes, "d.mcap").unwrap();
    assert!(t.truncated.is_none(), "damage read as a cut: {:?}", t.truncated);
    assert_eq!(t.damaged.len(), 1, "{:?}", t.damaged);
    assert!(t.damaged[0].contains("damaged"), "{}", t.damaged[0]);
    assert_readable(&t.damaged[0]);
    assert_eq!(t.checkpoint.as_deref(), Some(&[9u8; 32][..]), "the run before the damage is kept");
}

proptest! {
    #![proptest_config(config(200))]

    #[test]
    fn flipped_bytes_in_a_trajectory_never_panic(
        flips in prop::collection::vec((any::<usize>(), 1..=255u8), 1..=8), salvage in any::<bool>(),
    ) {
        let mut bytes = sample().to_vec();
        for (at, x) in flips {
            let n = bytes.len();
            bytes[at % n] ^= x;
        }
        let options = if salvage { SALVAGE } else { ReadOptions::default() };
        check_read(read_trajectory_with(&bytes, "f.mcap", options));
    }

    /// Lengths and counts that lie: a u64 or u32 written over any 8 or 4 bytes.
    #[test]
    fn a_lying_length_anywhere_in_a_trajectory_never_panics(
        at in any::<usize>(), value in prop_oneof![Just(u64::MAX), Just(1u64 << 62), Just(u32::MAX as u64), any::<u64>()],
        wide in any::<bool>(), salvage in any::<bool>(),
    ) {
        let mut bytes = sample().to_vec();
        let w = if wide { 8 } else { 4 };
        let at = 8 + at % (bytes.len() - 8 - w);
        bytes[at..at + w].copy_from_slice(&value.to_le_bytes()[..w]);
        let options = if salvage { SALVAGE } else { ReadOptions::default() };
        check_read(read_trajectory_with(&bytes, "l.mcap", options));
    }
}
