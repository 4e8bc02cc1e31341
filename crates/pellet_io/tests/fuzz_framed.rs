//! Pellet and packing files, damaged every way: every cut, random flipped bytes, and sound
//! files (checksum and all) holding impossible values. Each read is a value or a one-line
//! error, never a panic.

mod common;

use common::*;
use pellet_io::{decode_packing, decode_pellet, encode_packing, encode_pellet};
use proptest::prelude::*;

#[test]
fn every_cut_of_a_pellet_or_packing_file_is_an_error() {
    for bytes in [pellet_bytes(), encode_pellet(&pellet_file(cylinder())).unwrap()] {
        for cut in cuts(bytes.len()) {
            assert!(check(decode_pellet(&bytes[..cut], "cut.pellet")).is_none(), "cut at {cut} read");
        }
    }
    let bytes = packing_bytes();
    for cut in cuts(bytes.len()) {
        assert!(check(decode_packing(&bytes[..cut], "cut.packing")).is_none(), "cut at {cut} read");
    }
}

/// Up to eight (offset, xor) pairs; offsets are taken modulo the file's length.
fn flips() -> impl Strategy<Value = Vec<(usize, u8)>> {
    prop::collection::vec((any::<usize>(), 1..=255u8), 1..=8)
}

fn flipped(bytes: &[u8], flips: &[(usize, u8)]) -> Vec<u8> {
    let mut b = bytes.to_vec();
    for &(at, x) in flips {
        let n = b.len();
        b[at % n] ^= x;
    }
    b
}

proptest! {
    #![proptest_config(config(200))]

    #[test]
    fn flipped_bytes_in_a_pellet_file_are_an_error(f in flips()) {
        let bytes = flipped(&pellet_bytes(), &f);
        prop_assert!(check(decode_pellet(&bytes, "f.pellet")).is_none());
    }

    #[test]
    fn flipped_bytes_in_a_packing_file_are_an_error(f in flips()) {
        let bytes = flipped(&packing_bytes(), &f);
        prop_assert!(check(decode_packing(&bytes, "f.packing")).is_none());
    }

    /// A file of the version before checksums, where a flipped byte is not caught by a CRC and
    /// reaches the decoder and the checks after it.
    #[test]
    fn flipped_bytes_in_an_unchecked_pellet_file_never_panic(f in flips()) {
        let mut old = pellet_bytes();
        old.truncate(old.len() - 4);
        old[8..12].copy_from_slice(&1u32.to_le_bytes());
        let mut bytes = flipped(&old, &f);
        bytes[8..12].copy_from_slice(&1u32.to_le_bytes());
        check(decode_pellet(&bytes, "old.pellet"));
    }

    #[test]
    fn flipped_bytes_in_an_unchecked_packing_file_never_panic(f in flips()) {
        let mut old = packing_bytes();
        old.truncate(old.len() - 4);
        old[8..12].copy_from_slice(&1u32.to_le_bytes());
        let mut bytes = flipped(&old, &f);
        bytes[8..12].copy_from_slice(&1u32.to_le_bytes());
        check(decode_packing(&bytes, "old.packing"));
    }

    /// Sound files, checksum and all, whose values are impossible.
    #[test]
    fn a_pellet_file_of_impossible_values_is_an_error(
        vertex in any::<usize>(), value in odd_number(), index in any::<u32>(), radius in odd_number(),
        volume in odd_number(),
    ) {
        let mut f = pellet_file(cylinder());
        let n = f.pellet.mesh.vertices.len();
        f.pellet.mesh.vertices[vertex % n].y = value;
        let t = vertex % f.pellet.mesh.triangles.len();
        f.pellet.mesh.triangles[t][1] = index;
        f.pellet.bounding_radius = radius;
        f.pellet.properties.volume = volume;
        let sound = value.is_finite() && (index as usize) < n && radius.is_finite() && radius > 0.0
            && volume.is_finite() && volume > 0.0;
        let read = check(decode_pellet(&encode_pellet(&f).unwrap(), "v.pellet"));
        prop_assert!(read.is_some() || !sound);
        prop_assert!(read.is_none() || sound);
    }

    #[test]
    fn a_packing_file_of_impossible_values_is_an_error(
        pellet in 0..8usize, type_index in any::<u32>(), coord in odd_number(), w in odd_number(),
        diameter in odd_number(), lid in prop::option::of(odd_number()),
    ) {
        let mut p = packing();
        let placed = &mut p.bed.pellets[pellet];
        placed.type_index = type_index % 3;
        placed.position[pellet % 3] = coord;
        placed.orientation[0] = w;
        p.bed.tube.diameter = diameter;
        p.bed.tube.lid_height = lid;
        p.time_s = coord;
        check(decode_packing(&encode_packing(&p).unwrap(), "v.packing"));
    }
}
