//! The text and mesh readers — poses CSV, STL (binary and ASCII), OBJ — on cut, flipped and
//! hostile input: every cut, random flipped bytes, and fields replaced by NaN, infinities,
//! huge, negative, empty or not numbers at all, triangle counts that lie, face indices out of
//! range. Each read is a value or a one-line error, never a panic.

mod common;

use common::*;
use pellet_io::{decode_poses_csv, obj_bytes, read_mesh, stl_bytes, MeshFormat};
use proptest::prelude::*;

fn stl_binary() -> Vec<u8> {
    stl_bytes(&pellet(cylinder()).mesh, 1e3).unwrap()
}

/// The same cylinder as ASCII STL, as `bedexport --stl-ascii` lays it out.
fn stl_ascii() -> String {
    let mesh = pellet(cylinder()).mesh;
    let mut s = String::from("solid cylinder\n");
    for t in 0..mesh.face_count() {
        let n = mesh.area_normal(t).normalize();
        s += &format!("  facet normal {} {} {}\n    outer loop\n", n.x, n.y, n.z);
        for c in mesh.corners(t) {
            s += &format!("      vertex {} {} {}\n", c.x * 1e3, c.y * 1e3, c.z * 1e3);
        }
        s += "    endloop\n  endfacet\n";
    }
    s + "endsolid cylinder\n"
}

fn obj() -> String {
    String::from_utf8(obj_bytes(&pellet(cylinder()).mesh, 1e3, "a cylinder\nfrom the fuzz tests")).unwrap()
}

/// Eight pellets, header and quaternions.
fn poses() -> String {
    let mut s = String::from("# eight pellets\nid,x,y,z,qw,qx,qy,qz\n");
    for i in 0..8 {
        s += &format!("p{i},{},{},{},0.7071068,0,0.7071068,0\n", 10 * i, -3.5 * i as f64, 5 + 10 * i);
    }
    s
}

fn mesh(bytes: &[u8], format: MeshFormat) {
    check(read_mesh(bytes, format, "m"));
}

#[test]
fn every_cut_of_a_mesh_or_poses_file_is_read_or_an_error() {
    let (stl, ascii, obj, csv) = (stl_binary(), stl_ascii(), obj(), poses());
    for cut in cuts(stl.len()) {
        let read = check(read_mesh(&stl[..cut], MeshFormat::Stl, "cut.stl"));
        assert!(read.is_none() || cut == stl.len(), "a binary STL cut at {cut} read");
    }
    for cut in cuts(ascii.len()) {
        mesh(&ascii.as_bytes()[..cut], MeshFormat::Stl);
    }
    for cut in cuts(obj.len()) {
        mesh(&obj.as_bytes()[..cut], MeshFormat::Obj);
    }
    for cut in cuts(csv.len()) {
        for required in [false, true] {
            check(decode_poses_csv(&csv.as_bytes()[..cut], "cut.csv", required));
        }
    }
}

#[test]
fn an_stl_that_lies_about_its_triangles_says_so() {
    let mut stl = stl_binary();
    for count in [0u32, 1, 1000, u32::MAX] {
        stl[80..84].copy_from_slice(&count.to_le_bytes());
        let e = read_mesh(&stl, MeshFormat::Stl, "l.stl").unwrap_err().to_string();
        assert!(e.contains(&format!("its header counts {count} triangles")), "{e}");
        assert_readable(&e);
    }
    let e = read_mesh(b"", MeshFormat::Stl, "e.stl").unwrap_err().to_string();
    assert_eq!(e, "e.stl: unreadable STL: a binary STL is truncated: 0 bytes, fewer than the 84 of its header");
    let e = read_mesh(b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 1 2\n", MeshFormat::Stl, "a.stl").unwrap_err();
    assert_eq!(
        e.to_string(),
        "a.stl: unreadable STL: line 4: `vertex` must be followed by three finite numbers, found `1 2`"
    );
}

fn flip(bytes: &mut [u8], flips: &[(usize, u8)]) {
    for &(at, x) in flips {
        let n = bytes.len();
        bytes[at % n] ^= x;
    }
}

fn flips() -> impl Strategy<Value = Vec<(usize, u8)>> {
    prop::collection::vec((any::<usize>(), 1..=255u8), 1..=8)
}

/// What a damaged or hostile text file holds in place of a number.
fn odd_field() -> impl Strategy<Value = String> {
    prop_oneof![
        Just(String::new()),
        Just("nan".to_string()),
        Just("NaN".to_string()),
        Just("inf".to_string()),
        Just("-inf".to_string()),
        Just("1e999".to_string()),
        Just("-1e999".to_string()),
        Just("1e38".to_string()),
        Just("-0".to_string()),
        Just("0x10".to_string()),
        Just("9".repeat(400)),
        Just("x".repeat(5000)),
        Just("\u{0}\u{7f}\r".to_string()),
        Just("é,\"q\"".to_string()),
        odd_number().prop_map(|v| v.to_string()),
        any::<i64>().prop_map(|v| v.to_string()),
        "[ -~]{0,12}",
    ]
}

/// `text` with the whitespace- or comma-separated fields at `picks` (modulo the count)
/// replaced.
fn replace_fields(text: &str, picks: &[(usize, String)], comma: bool) -> String {
    let split = |c: char| if comma { c == ',' || c == '\n' } else { c.is_whitespace() };
    let mut spans = Vec::new();
    let mut start = None;
    for (i, c) in text.char_indices() {
        match (split(c), start) {
            (true, Some(s)) => {
                spans.push((s, i));
                start = None;
            }
            (false, None) => start = Some(i),
            _ => {}
        }
    }
    if let Some(s) = start {
        spans.push((s, text.len()));
    }
    let mut chosen: Vec<(usize, &str)> = picks.iter().map(|(k, v)| (k % spans.len(), v.as_str())).collect();
    chosen.sort_by_key(|c| std::cmp::Reverse(c.0));
    chosen.dedup_by_key(|c| c.0);
    let mut out = text.to_string();
    for (k, v) in chosen {
        out.replace_range(spans[k].0..spans[k].1, v);
    }
    out
}

proptest! {
    #![proptest_config(config(150))]

    #[test]
    fn flipped_bytes_in_a_mesh_never_panic(f in flips(), which in 0..3u8) {
        let (mut bytes, format) = match which {
            0 => (stl_binary(), MeshFormat::Stl),
            1 => (stl_ascii().into_bytes(), MeshFormat::Stl),
            _ => (obj().into_bytes(), MeshFormat::Obj),
        };
        flip(&mut bytes, &f);
        mesh(&bytes, format);
    }

    #[test]
    fn flipped_bytes_in_a_poses_csv_never_panic(f in flips(), required in any::<bool>()) {
        let mut bytes = poses().into_bytes();
        flip(&mut bytes, &f);
        check(decode_poses_csv(&bytes, "f.csv", required));
    }

    #[test]
    fn odd_fields_in_a_poses_csv_are_read_or_refused(
        picks in prop::collection::vec((any::<usize>(), odd_field()), 1..6), required in any::<bool>(),
    ) {
        let text = replace_fields(&poses(), &picks, true);
        check(decode_poses_csv(text.as_bytes(), "o.csv", required));
    }

    #[test]
    fn odd_fields_in_an_ascii_stl_are_read_or_refused(picks in prop::collection::vec((any::<usize>(), odd_field()), 1..6)) {
        let text = replace_fields(&stl_ascii(), &picks, false);
        mesh(text.as_bytes(), MeshFormat::Stl);
    }

    #[test]
    fn odd_fields_in_an_obj_are_read_or_refused(picks in prop::collection::vec((any::<usize>(), odd_field()), 1..6)) {
        let text = replace_fields(&obj(), &picks, false);
        mesh(text.as_bytes(), MeshFormat::Obj);
    }

    /// Face indices out of range: zero, negative (relative), past the end, huge.
    #[test]
    fn obj_faces_out_of_range_are_refused(
        line in any::<usize>(), index in prop_oneof![Just(0i64), Just(-1), Just(-1000), Just(100_000), Just(i64::MAX), Just(u32::MAX as i64 + 2), any::<i64>()],
        corners in 1..6usize,
    ) {
        let text = obj();
        let faces: Vec<usize> = text.lines().enumerate().filter(|(_, l)| l.starts_with("f ")).map(|(i, _)| i).collect();
        let at = faces[line % faces.len()];
        let bad: Vec<String> = (0..corners).map(|k| if k == 0 { index.to_string() } else { (k + 1).to_string() }).collect();
        let text: String = text.lines().enumerate().map(|(i, l)| {
            if i == at { format!("f {}\n", bad.join(" ")) } else { format!("{l}\n") }
        }).collect();
        mesh(text.as_bytes(), MeshFormat::Obj);
    }

    /// Binary STL with any count, any coordinates (NaN and infinities among them).
    #[test]
    fn binary_stl_counts_and_coordinates_that_lie_are_refused(
        count in prop_oneof![Just(0u32), Just(u32::MAX), any::<u32>(), 0..200u32], at in any::<usize>(), value in any::<f32>(),
    ) {
        let mut stl = stl_binary();
        let real = (stl.len() - 84) / 50;
        let t = at % real;
        let c = 84 + 50 * t + 12 + 4 * (at % 9);
        stl[c..c + 4].copy_from_slice(&value.to_le_bytes());
        mesh(&stl, MeshFormat::Stl);
        stl[80..84].copy_from_slice(&count.to_le_bytes());
        let read = check(read_mesh(&stl, MeshFormat::Stl, "c.stl"));
        prop_assert!(read.is_none() || count as usize == real);
    }
}
