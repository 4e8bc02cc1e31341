//! STL, the surface format CFD meshers import (snappyHexMesh, STAR-CCM+,
//! Fluent).
//!
//! # Format
//!
//! - **Binary** ([`binary`]): the standard layout, little-endian: an 80-byte
//!   header (ASCII text saying what the file holds and its unit, padded with
//!   spaces), a u32 triangle count, then per triangle the unit normal and
//!   the three corners as 12 f32 and a u16 attribute of 0. Binary STL has
//!   no solids: all the meshes given form one surface.
//! - **ASCII** ([`ascii`]): one `solid NAME … endsolid NAME` block per mesh,
//!   so meshers see one region per pellet (`pellet_00000`, …); coordinates
//!   printed with 9 significant digits (more than f32 holds).
//!
//! STL carries no unit: every coordinate is multiplied by `scale` (1000 for
//! millimetres, 1 for metres) and the unit is written into the header or a
//! leading comment of the file name's choice by the caller. Triangles are
//! counter-clockwise seen from outside (normals point out of the solid).

use std::fmt::Write;

use pellet_geom::math::Real;
use pellet_geom::TriMesh;

/// Binary STL of all `meshes` as one surface, coordinates × `scale`.
/// `header` (ASCII, cut to 80 bytes) describes the contents; it must not
/// start with `solid`, which would make readers take the file for ASCII.
pub fn binary(meshes: &[&TriMesh], scale: Real, header: &str) -> Vec<u8> {
    let count: usize = meshes.iter().map(|m| m.face_count()).sum();
    let mut out = Vec::with_capacity(84 + 50 * count);
    let mut head: Vec<u8> = header.bytes().filter(|b| b.is_ascii() && !b.is_ascii_control()).take(80).collect();
    if head.starts_with(b"solid") {
        head.insert(0, b'#');
        head.truncate(80);
    }
    head.resize(80, b' ');
    out.extend_from_slice(&head);
    out.extend_from_slice(&(count as u32).to_le_bytes());
    for mesh in meshes {
        for t in 0..mesh.face_count() {
            let n = mesh.area_normal(t);
            let n = if n.norm() > 0.0 { n.normalize() } else { n };
            for c in [n.x, n.y, n.z] {
                out.extend_from_slice(&(c as f32).to_le_bytes());
            }
            for p in mesh.corners(t) {
                for c in [p.x, p.y, p.z] {
                    out.extend_from_slice(&((c * scale) as f32).to_le_bytes());
                }
            }
            out.extend_from_slice(&0u16.to_le_bytes());
        }
    }
    out
}

/// ASCII STL with one named solid per mesh, coordinates × `scale`.
pub fn ascii(solids: &[(String, &TriMesh)], scale: Real) -> Vec<u8> {
    let faces: usize = solids.iter().map(|(_, m)| m.face_count()).sum();
    let mut s = String::with_capacity(260 * faces + 64 * solids.len());
    for (name, mesh) in solids {
        let _ = writeln!(s, "solid {name}");
        for t in 0..mesh.face_count() {
            let n = mesh.area_normal(t);
            let n = if n.norm() > 0.0 { n.normalize() } else { n };
            let _ = writeln!(s, "  facet normal {:.6e} {:.6e} {:.6e}", n.x, n.y, n.z);
            s.push_str("    outer loop\n");
            for p in mesh.corners(t) {
                let _ = writeln!(s, "      vertex {:.8e} {:.8e} {:.8e}", p.x * scale, p.y * scale, p.z * scale);
            }
            s.push_str("    endloop\n  endfacet\n");
        }
        let _ = writeln!(s, "endsolid {name}");
    }
    s.into_bytes()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{enclosed_volume, tube_mesh};

    #[test]
    fn binary_and_ascii_read_back_with_stl_io() {
        let a = tube_mesh(0.01, 0.0, 0.02, 12);
        let mut b = a.clone();
        b.translate(&pellet_geom::math::Vector::new(0.05, 0.0, 0.0));
        let bin = binary(&[&a, &b], 1000.0, "solid-looking header");
        assert_eq!(&bin[..6], b"#solid");
        let read = stl_io::read_stl(&mut std::io::Cursor::new(&bin)).unwrap();
        assert_eq!(read.faces.len(), 2 * a.face_count());
        let text = ascii(&[("one".into(), &a), ("two".into(), &b)], 1000.0);
        // stl_io reads only the first solid of an ASCII file: parse the solids here.
        let solids = parse_ascii(std::str::from_utf8(&text).unwrap());
        assert_eq!(solids.iter().map(|(n, f)| (n.as_str(), f.len())).collect::<Vec<_>>(), [("one", 48), ("two", 48)]);
        assert!((solids[1].1[0][0][0] - b.corners(0)[0].x as f32 * 1000.0).abs() < 1e-4);
        // The re-read surface encloses twice the tube (mm³).
        let mesh = pellet_geom::TriMesh {
            vertices: read
                .vertices
                .iter()
                .map(|v| pellet_geom::math::Point::new(v[0].into(), v[1].into(), v[2].into()))
                .collect(),
            triangles: read.faces.iter().map(|f| f.vertices.map(|i| i as u32)).collect(),
        };
        let expected = 2.0 * enclosed_volume(&a) * 1e9;
        assert!((enclosed_volume(&mesh) / expected - 1.0).abs() < 1e-5);
    }

    /// (name, triangles) of each solid of an ASCII STL, by hand.
    pub fn parse_ascii(text: &str) -> Vec<(String, Vec<[[f32; 3]; 3]>)> {
        let mut solids: Vec<(String, Vec<[[f32; 3]; 3]>)> = Vec::new();
        let mut corners = Vec::new();
        for line in text.lines().map(str::trim) {
            if let Some(name) = line.strip_prefix("solid ") {
                solids.push((name.to_string(), Vec::new()));
            } else if let Some(v) = line.strip_prefix("vertex ") {
                let c: Vec<f32> = v.split_whitespace().map(|x| x.parse().unwrap()).collect();
                corners.push([c[0], c[1], c[2]]);
                if corners.len() == 3 {
                    solids.last_mut().unwrap().1.push([corners[0], corners[1], corners[2]]);
                    corners.clear();
                }
            }
        }
        solids
    }
}
