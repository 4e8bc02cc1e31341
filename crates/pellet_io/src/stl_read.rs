//! Reading STL, binary or ASCII, into triangles of single-precision corners.
//!
//! Not `stl_io`'s reader: a binary file whose triangle count does not match its size failed
//! with "failed to fill whole buffer", and an ASCII one with the parser's debug output
//! (`vertex f32 f32 f32, got ["vertex", "1", "2"]`) and no line number.

use crate::reason::shown_field;

/// Bytes before the first triangle of a binary STL: an 80-byte header and the u32 count.
const BINARY_HEADER: usize = 84;
/// Bytes per triangle of a binary STL: normal, three corners (f32) and a u16 attribute.
const BINARY_TRIANGLE: usize = 50;

/// The corners of every triangle of an STL file, in file order.
pub(crate) fn read_stl(bytes: &[u8]) -> Result<Vec<[[f32; 3]; 3]>, String> {
    let count = bytes.get(80..84).map(|c| u32::from_le_bytes(c.try_into().expect("4 bytes")) as usize);
    let binary_len = count.and_then(|n| n.checked_mul(BINARY_TRIANGLE)).and_then(|b| b.checked_add(BINARY_HEADER));
    // The size decides, not the header: some exporters begin binary headers with "solid".
    if binary_len == Some(bytes.len()) {
        return Ok(read_binary(&bytes[BINARY_HEADER..]));
    }
    if bytes.trim_ascii_start().starts_with(b"solid") {
        let text = std::str::from_utf8(bytes).map_err(|e| {
            format!("an ASCII STL that is not text (a byte that is not UTF-8 at byte {})", e.valid_up_to())
        })?;
        return read_ascii(text);
    }
    match count {
        None => Err(format!(
            "a binary STL is truncated: {} bytes, fewer than the {BINARY_HEADER} of its header",
            bytes.len()
        )),
        Some(n) => Err(format!(
            "a binary STL is truncated or damaged: its header counts {n} triangles ({} bytes), but the file has {} bytes",
            binary_len.map_or_else(|| "more than can be".into(), |b| b.to_string()),
            bytes.len()
        )),
    }
}

fn read_binary(data: &[u8]) -> Vec<[[f32; 3]; 3]> {
    let f = |b: &[u8]| f32::from_le_bytes(b.try_into().expect("4 bytes"));
    data.chunks_exact(BINARY_TRIANGLE)
        .map(|t| {
            let corner = |k: usize| {
                let at = 12 + 12 * k; // after the normal
                [f(&t[at..at + 4]), f(&t[at + 4..at + 8]), f(&t[at + 8..at + 12])]
            };
            [corner(0), corner(1), corner(2)]
        })
        .collect()
}

/// What the ASCII reader expects next.
#[derive(Clone, Copy, PartialEq)]
enum Expect {
    Solid,
    Facet,
    OuterLoop,
    Vertex(usize),
    EndLoop,
    EndFacet,
}

impl Expect {
    fn words(self) -> &'static str {
        match self {
            Expect::Solid => "`solid`",
            Expect::Facet => "`facet normal x y z` or `endsolid`",
            Expect::OuterLoop => "`outer loop`",
            Expect::Vertex(_) => "`vertex x y z`",
            Expect::EndLoop => "`endloop`",
            Expect::EndFacet => "`endfacet`",
        }
    }
}

/// An ASCII STL: every solid in the file, one keyword line at a time.
fn read_ascii(text: &str) -> Result<Vec<[[f32; 3]; 3]>, String> {
    let mut triangles = Vec::new();
    let mut corners = [[0.0f32; 3]; 3];
    let mut expect = Expect::Solid;
    let mut last = 0;
    for (n, line) in text.lines().enumerate() {
        let line_no = n + 1;
        last = line_no;
        let words: Vec<&str> = line.split_whitespace().collect();
        let Some(&first) = words.first() else { continue };
        let wrong = || format!("line {line_no}: expected {}, found `{}`", expect.words(), shown_field(line.trim()));
        expect = match (expect, first) {
            (Expect::Solid, "solid") => Expect::Facet,
            (Expect::Facet, "endsolid") => Expect::Solid,
            (Expect::Facet, "facet") if words.get(1) == Some(&"normal") => {
                // The normal is not used (packbed computes its own), but it must be numbers.
                numbers(&words[2..], line_no, "facet normal")?;
                Expect::OuterLoop
            }
            (Expect::OuterLoop, "outer") if words.get(1) == Some(&"loop") && words.len() == 2 => Expect::Vertex(0),
            (Expect::Vertex(k), "vertex") => {
                corners[k] = numbers(&words[1..], line_no, "vertex")?;
                if k == 2 {
                    Expect::EndLoop
                } else {
                    Expect::Vertex(k + 1)
                }
            }
            (Expect::EndLoop, "endloop") => Expect::EndFacet,
            (Expect::EndFacet, "endfacet") => {
                triangles.push(corners);
                Expect::Facet
            }
            _ => return Err(wrong()),
        };
    }
    if expect != Expect::Solid {
        return Err(format!(
            "the ASCII STL is truncated: it ends at line {last}, where {} was expected",
            expect.words()
        ));
    }
    Ok(triangles)
}

/// Three numbers after a keyword.
fn numbers(words: &[&str], line_no: usize, keyword: &str) -> Result<[f32; 3], String> {
    let parsed: Vec<Option<f32>> = words.iter().map(|w| w.parse::<f32>().ok().filter(|v| v.is_finite())).collect();
    match parsed[..] {
        [Some(x), Some(y), Some(z)] => Ok([x, y, z]),
        _ => Err(format!(
            "line {line_no}: `{keyword}` must be followed by three finite numbers, found `{}`",
            shown_field(&words.join(" "))
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_name_the_line_and_what_was_expected() {
        let text = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 1 2\n";
        assert_eq!(
            read_stl(text.as_bytes()).unwrap_err(),
            "line 4: `vertex` must be followed by three finite numbers, found `1 2`"
        );
        let text = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n";
        let e = read_stl(text.as_bytes()).unwrap_err();
        assert_eq!(e, "the ASCII STL is truncated: it ends at line 6, where `endloop` was expected");
        let e = read_stl(b"solid t\nfacet normal 0 0 1\nendloop\n").unwrap_err();
        assert_eq!(e, "line 3: expected `outer loop`, found `endloop`");
    }

    #[test]
    fn a_binary_count_that_lies_is_named() {
        let mut b = vec![0u8; 84 + 50];
        b[80..84].copy_from_slice(&3u32.to_le_bytes());
        let e = read_stl(&b).unwrap_err();
        assert!(e.contains("header counts 3 triangles (234 bytes), but the file has 134 bytes"), "{e}");
        assert!(read_stl(b"").unwrap_err().contains("truncated: 0 bytes"));
        b[80..84].copy_from_slice(&1u32.to_le_bytes());
        assert_eq!(read_stl(&b).unwrap().len(), 1);
    }
}
