//! Pellet files and mesh exports survive a round trip exactly.

mod common;

use pellet_geom::{Pellet, Resolution, ShapeSpec};
use pellet_io::{decode_pellet, encode_pellet, obj_bytes, read_mesh, stl_bytes, MeshFormat, PelletFile, Provenance};

fn file(shape: ShapeSpec) -> PelletFile {
    PelletFile {
        length_unit: "m".into(),
        provenance: Provenance { tool: "test".into(), version: "0".into(), args: vec!["a".into()] },
        pellet: Pellet::build(shape, Resolution::default()).unwrap(),
    }
}

#[test]
fn pellet_file_round_trip_is_bit_identical() {
    for shape in [
        ShapeSpec::Sphere { diameter_mm: 10.0 },
        ShapeSpec::Ring { outer_diameter_mm: 10.0, inner_diameter_mm: 6.0, height_mm: 10.0 },
        ShapeSpec::Lobed { lobes: 4, lobe_diameter_mm: 1.5, size_mm: 2.8, height_mm: 5.0 },
    ] {
        let original = file(shape);
        let bytes = encode_pellet(&original).unwrap();
        let decoded = decode_pellet(&bytes, "mem").unwrap();
        assert_eq!(decoded, original);
        // f64 values are stored bit-exact, so re-encoding gives the same bytes.
        assert_eq!(encode_pellet(&decoded).unwrap(), bytes);
    }
}

#[test]
fn every_truncation_is_an_error_not_a_panic() {
    let bytes = encode_pellet(&file(ShapeSpec::Sphere { diameter_mm: 2.0 })).unwrap();
    for cut in [0, 7, 11, 12, 100, bytes.len() / 3, bytes.len() - 1] {
        assert!(decode_pellet(&bytes[..cut], "cut").is_err(), "cut at {cut} decoded");
    }
    // Damage reads in words: a cut file is truncated, a wild length prefix corrupt.
    let cut = decode_pellet(&bytes[..bytes.len() / 2], "cut.pellet").unwrap_err().to_string();
    assert!(cut.contains("cut.pellet: the pellet file is truncated (its data ends early)"), "{cut}");
    let mut wild = bytes.clone();
    wild[12..20].copy_from_slice(&u64::MAX.to_le_bytes());
    let wild = decode_pellet(&wild, "w.pellet").unwrap_err().to_string();
    assert!(wild.contains("is corrupt (a length in it is impossibly large)") && !wild.contains("Limit"), "{wild}");
    let mut extended = bytes.clone();
    extended.push(0);
    assert!(decode_pellet(&extended, "long").unwrap_err().to_string().contains("unexpected bytes"));
}

#[test]
fn stl_and_obj_exports_reimport_with_the_same_mesh() {
    let f = file(ShapeSpec::Cylinder { diameter_mm: 10.0, height_mm: 10.0 });
    let mesh = &f.pellet.mesh;
    let stl = read_mesh(&stl_bytes(mesh, 1e3).unwrap(), MeshFormat::Stl, "x.stl").unwrap();
    assert_eq!(stl.face_count(), mesh.face_count());
    assert_eq!(stl.vertices.len(), mesh.vertices.len());
    let obj = read_mesh(&obj_bytes(mesh, 1e3, "c"), MeshFormat::Obj, "x.obj").unwrap();
    // Same triangles in the same order with the same corners (tobj may
    // renumber vertices, so compare coordinates, not indices).
    assert_eq!(obj.face_count(), mesh.face_count());
    let worst = (0..mesh.face_count())
        .flat_map(|t| obj.corners(t).into_iter().zip(mesh.corners(t)).map(|(a, b)| (a - b * 1e3).norm()))
        .fold(0.0, f64::max);
    assert!(worst < 1e-9, "OBJ corners moved by up to {worst} mm");
    let ascii = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n";
    assert_eq!(read_mesh(ascii.as_bytes(), MeshFormat::Stl, "a.stl").unwrap().face_count(), 1);
}

#[test]
fn packing_file_round_trip_and_validation() {
    use pellet_geom::{Bed, PlacedPellet, Tube};
    use pellet_io::{decode_packing, encode_packing, PackingFile, SettleVerdict};
    let pellet = Pellet::build(ShapeSpec::Sphere { diameter_mm: 10.0 }, Resolution { level: 0, faces: None }).unwrap();
    let mut packing = PackingFile {
        length_unit: "m".into(),
        provenance: Provenance { tool: "test".into(), version: "0".into(), args: vec![] },
        time_s: 1.5,
        verdict: Some(SettleVerdict { settled: true, settle_time_s: Some(1.2), kinetic_energy_j: 1e-9 }),
        bed: Bed {
            tube: Tube { diameter: 0.04, lid_height: None },
            pellet_types: vec![pellet],
            pellets: vec![PlacedPellet {
                type_index: 0,
                position: [0.0, 0.0, 0.005],
                orientation: [1.0, 0.0, 0.0, 0.0],
            }],
        },
    };
    let bytes = encode_packing(&packing).unwrap();
    assert_eq!(decode_packing(&bytes, "p").unwrap(), packing);
    assert!(decode_packing(&bytes[..bytes.len() - 5], "p").is_err());
    packing.bed.pellets[0].type_index = 3;
    let bad = encode_packing(&packing).unwrap();
    assert!(decode_packing(&bad, "p").unwrap_err().to_string().contains("pellet types"));
}

/// A trajectory written to a FIFO goes into the FIFO (no `.part` beside it, no rename over
/// it) and reads back whole: `pack -o /dev/null` must not replace the null device.
#[cfg(unix)]
#[test]
fn a_trajectory_to_a_fifo_is_written_in_place() {
    use pellet_io::{read_trajectory, Frame};
    use std::os::unix::fs::FileTypeExt;
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("run.mcap");
    assert!(std::process::Command::new("mkfifo").arg(&fifo).status().expect("run mkfifo").success());
    let path = fifo.clone();
    let reader = std::thread::spawn(move || std::fs::read(path).unwrap());
    let mut w = common::trajectory_writer(&fifo);
    w.write_frame(&Frame { time_s: 0.5, ..Frame::default() }).unwrap();
    w.finish().unwrap();
    assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo(), "the FIFO was replaced");
    assert!(!dir.path().join("run.mcap.part").exists());
    let bytes = reader.join().unwrap();
    let t = read_trajectory(&bytes, "fifo").unwrap();
    assert_eq!(t.frames.len(), 1);
    assert_eq!(t.frames[0].time_s, 0.5);
}

/// A trajectory cut inside its first records (a run killed at once) says it is truncated.
#[test]
fn a_trajectory_cut_in_its_header_is_reported_truncated() {
    use pellet_io::read_trajectory;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("run.mcap");
    common::trajectory_writer(&path).finish().unwrap();
    let bytes = std::fs::read(&path).unwrap();
    for cut in [10, 12, 20] {
        let Err(e) = read_trajectory(&bytes[..cut], "cut.mcap") else { panic!("cut at {cut} read") };
        let e = e.to_string();
        assert!(e.contains("truncated: the file ends within its MCAP header"), "cut at {cut}: {e}");
    }
}

/// A byte changed in a pellet's vertex data is found by the checksum; a file of the format
/// before checksums (version 1: no trailing CRC) still reads.
#[test]
fn a_changed_byte_fails_the_checksum_and_old_files_still_read() {
    let original = file(ShapeSpec::Sphere { diameter_mm: 10.0 });
    let bytes = encode_pellet(&original).unwrap();
    let x = original.pellet.mesh.vertices[10].x.to_le_bytes();
    let at = bytes.windows(8).position(|w| w == x).expect("a vertex's bytes in the file");
    let mut flipped = bytes.clone();
    flipped[at + 3] ^= 0x10;
    let e = decode_pellet(&flipped, "f.pellet").unwrap_err().to_string();
    assert!(e.contains("f.pellet: the pellet file's checksum does not match its contents"), "{e}");
    let mut crc = bytes.clone();
    let n = crc.len();
    crc[n - 1] ^= 1;
    assert!(decode_pellet(&crc, "c.pellet").unwrap_err().to_string().contains("checksum"));
    let mut old = bytes[..bytes.len() - 4].to_vec();
    old[8..12].copy_from_slice(&1u32.to_le_bytes());
    assert_eq!(decode_pellet(&old, "old.pellet").unwrap(), original);
    let mut future = bytes.clone();
    future[8..12].copy_from_slice(&3u32.to_le_bytes());
    assert!(decode_pellet(&future, "new.pellet").unwrap_err().to_string().contains("format version 3"));
}

/// Offsets of the top-level chunk records of an MCAP file (after its 8-byte magic).
fn chunk_offsets(bytes: &[u8]) -> Vec<usize> {
    let (mut at, mut out) = (8, Vec::new());
    while at + 9 <= bytes.len() {
        let len = u64::from_le_bytes(bytes[at + 1..at + 9].try_into().unwrap()) as usize;
        if at + 9 + len > bytes.len() {
            break;
        }
        if bytes[at] == 0x06 {
            out.push(at);
        }
        at += 9 + len;
    }
    out
}

/// One bad byte in the first chunk (which also holds the channel records) of a killed run:
/// read past the damage, the chunks after it give their frames and the last checkpoint, and
/// the damage is named.
#[test]
fn a_damaged_chunk_is_skipped_when_asked() {
    use pellet_io::{read_trajectory, read_trajectory_with, Frame, ReadOptions};
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("run.mcap");
    let mut w = common::trajectory_writer(&path);
    for i in 0..40 {
        let t = i as f64 * 0.01;
        w.write_frame(&Frame { time_s: t, positions: vec![[t, 0.0, 0.0]], ..Frame::default() }).unwrap();
        if i % 10 == 9 {
            // Closes the chunk, as pack's checkpoints do.
            w.write_checkpoint(t, &[i as u8; 64]).unwrap();
        }
    }
    w.finish().unwrap();
    let whole = std::fs::read(&path).unwrap();
    let chunks = chunk_offsets(&whole);
    assert!(chunks.len() >= 4, "{chunks:?}");
    // Killed in the middle of its last chunk, one byte of the first chunk's data changed.
    let mut bytes = whole[..chunks[3] + 100].to_vec();
    bytes[chunks[0] + 80] ^= 0x5a;
    let salvage = ReadOptions { skip_damage: true, ..ReadOptions::default() };
    let t = read_trajectory_with(&bytes, "k.mcap.part", salvage).unwrap();
    assert_eq!(t.damaged.len(), 1, "{:?}", t.damaged);
    assert!(t.damaged[0].contains("the run up to t = 0.100 s is missing"), "{}", t.damaged[0]);
    assert!(t.truncated.is_some(), "the cut at the end");
    assert_eq!(t.checkpoint.as_deref(), Some(&[29u8; 64][..]));
    let times: Vec<f64> = t.frames.iter().map(|f| f.time_s).collect();
    assert_eq!(times, (10..30).map(|i| i as f64 * 0.01).collect::<Vec<_>>());
    assert_eq!(t.pellet_files, [common::pellet_bytes()]);

    // A chunk's length field made larger: the chunk is no longer taken with the ones after it.
    let mut bytes = whole.clone();
    bytes[chunks[1] + 3] ^= 0x01;
    let t = read_trajectory_with(&bytes, "g.mcap", salvage).unwrap();
    assert_eq!(t.damaged.len(), 1, "{:?}", t.damaged);
    assert_eq!(t.frames.len(), 30);
    assert_eq!(t.checkpoint.as_deref(), Some(&[39u8; 64][..]));

    // A sound file reads the same either way.
    let (a, b) = (read_trajectory(&whole, "w").unwrap(), read_trajectory_with(&whole, "w", salvage).unwrap());
    assert!(a.frames == b.frames && a.checkpoint == b.checkpoint && a.run == b.run);
    assert!(b.damaged.is_empty() && b.truncated.is_none());
}
