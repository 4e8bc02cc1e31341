//! What the fuzz tests share: case counts, the sample files made by packbed's own writers, and
//! the rule every reader's error must keep.
#![allow(dead_code)] // each test file uses part of it

use std::fmt::Display;

use pellet_geom::{Bed, Pellet, PlacedPellet, Resolution, ShapeSpec, Tube};
use pellet_io::{
    encode_packing, encode_pellet, PackingFile, PelletFile, Provenance, SettleVerdict, TrajectoryHeader,
    TrajectoryWriter,
};
use proptest::prelude::*;
use proptest::test_runner::Config;

/// `default` cases per property, or `PROPTEST_CASES` (`make fuzz` raises it). Small defaults keep
/// the fuzz tests within seconds of `cargo test`.
pub fn config(default: u32) -> Config {
    let cases = std::env::var("PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(default);
    // No regression files written into the source tree: a failure prints its input.
    Config { cases, failure_persistence: None, ..Config::default() }
}

/// How many byte positions the truncation sweeps try past the first 4 KiB, where they try
/// every one.
pub fn sampled_cuts() -> usize {
    std::env::var("PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(256)
}

/// Every cut in the first 4 KiB, then `sampled_cuts()` spread evenly over the rest.
pub fn cuts(len: usize) -> Vec<usize> {
    let dense = len.min(4096);
    let mut v: Vec<usize> = (0..dense).collect();
    let rest = len - dense;
    let n = sampled_cuts().min(rest);
    v.extend((0..n).map(|i| dense + i * rest / n.max(1)));
    v
}

/// An error a user reads: one line, short enough to read.
#[track_caller]
pub fn assert_readable(e: &impl Display) {
    let s = e.to_string();
    let head: String = s.chars().take(400).collect();
    assert!(!s.contains('\n'), "a multi-line error: {head:?}");
    assert!(s.chars().count() <= 300, "an error of {} characters: {head}", s.chars().count());
    assert!(!s.is_empty(), "an empty error");
}

/// `r`'s error, if any, checked with [`assert_readable`].
#[track_caller]
pub fn check<T, E: Display>(r: Result<T, E>) -> Option<T> {
    match r {
        Ok(v) => Some(v),
        Err(e) => {
            assert_readable(&e);
            None
        }
    }
}

pub fn provenance() -> Provenance {
    Provenance { tool: "fuzz".into(), version: "0".into(), args: vec!["x".into()] }
}

/// A coarse pellet of `shape`: small files, fast decoding.
pub fn pellet(shape: ShapeSpec) -> Pellet {
    Pellet::build(shape, Resolution { level: 0, faces: None }).unwrap()
}

pub fn pellet_file(shape: ShapeSpec) -> PelletFile {
    PelletFile { length_unit: "m".into(), provenance: provenance(), pellet: pellet(shape) }
}

pub fn sphere() -> ShapeSpec {
    ShapeSpec::Sphere { diameter_mm: 10.0 }
}

pub fn cylinder() -> ShapeSpec {
    ShapeSpec::Cylinder { diameter_mm: 10.0, height_mm: 10.0 }
}

/// Eight spheres in a 40 mm tube, in two layers.
pub fn packing() -> PackingFile {
    let pellets = (0..8)
        .map(|i| {
            let a = i as f64 * std::f64::consts::FRAC_PI_2;
            PlacedPellet {
                type_index: 0,
                position: [0.012 * a.cos(), 0.012 * a.sin(), 0.005 + 0.01 * (i / 4) as f64],
                orientation: [1.0, 0.0, 0.0, 0.0],
            }
        })
        .collect();
    PackingFile {
        length_unit: "m".into(),
        provenance: provenance(),
        time_s: 1.5,
        verdict: Some(SettleVerdict { settled: true, settle_time_s: Some(1.2), kinetic_energy_j: 1e-9 }),
        bed: Bed { tube: Tube { diameter: 0.04, lid_height: None }, pellet_types: vec![pellet(sphere())], pellets },
    }
}

pub fn pellet_bytes() -> Vec<u8> {
    encode_pellet(&pellet_file(sphere())).unwrap()
}

pub fn packing_bytes() -> Vec<u8> {
    encode_packing(&packing()).unwrap()
}

/// The numbers a damaged or hostile file holds: NaN, infinities, zero, negative, huge, tiny.
pub fn odd_number() -> impl Strategy<Value = f64> {
    prop_oneof![
        Just(f64::NAN),
        Just(f64::INFINITY),
        Just(f64::NEG_INFINITY),
        Just(0.0),
        Just(-0.0),
        Just(-1.0),
        Just(1e300),
        Just(-1e300),
        Just(f64::MIN_POSITIVE),
        Just(5e-324),
        -1e3..1e3f64,
        any::<f64>(),
    ]
}

/// A trajectory writer at `path` for one 10 mm sphere type in a 40 mm tube.
pub fn trajectory_writer(path: &std::path::Path) -> TrajectoryWriter {
    let provenance = provenance();
    let files = [pellet_bytes()];
    let tube = Tube { diameter: 0.04, lid_height: None };
    let header = TrajectoryHeader {
        provenance: &provenance,
        config_json: "{}",
        seed: 1,
        build: "git test",
        pellet_files: &files,
        tube: &tube,
    };
    TrajectoryWriter::create(path, &header).unwrap()
}
