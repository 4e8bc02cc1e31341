//! Pellet poses from other generators (Blender, LIGGGHTS, tomography) as CSV.
//!
//! # Format
//!
//! One pellet per line: `id,x,y,z` with the centroid in **millimetres**,
//! followed by `qw,qx,qy,qz`, the unit quaternion rotating the pellet's body
//! frame (origin at the centroid, symmetry axis along body z, as `mkpellet`
//! makes it) into the world, where the pellet is not a sphere. The tube axis
//! is world z and the floor is z = 0.
//!
//! - An optional header line names the columns (`id,x,y,z,qw,qx,qy,qz`, any
//!   order, case-insensitive); other columns are ignored. Without a header
//!   the columns are positional: 4 fields (spheres) or 8. The id is any
//!   text, but no two pellets may share one (a repeated row is refused).
//! - Lines starting with `#` and blank lines are skipped.
//! - Quaternions are normalised; one whose norm differs from 1 by more than
//!   0.001 is refused, as are non-finite numbers.

use pellet_geom::PlacedPellet;

use crate::reason::shown_field;
use crate::IoError;

const NAMES: [&str; 8] = ["id", "x", "y", "z", "qw", "qx", "qy", "qz"];

/// Reads a poses CSV into poses of pellet type 0, in metres.
///
/// One pellet per line: `id,x,y,z` (centroid, mm), then `qw,qx,qy,qz` (unit
/// quaternion, body → world; body frame as `mkpellet` makes it: origin at
/// the centroid, symmetry axis along z). An optional header names the
/// columns (any order, case-insensitive, extra columns ignored); without
/// one, 4 or 8 positional fields. `#` lines and blank lines are skipped.
/// Quaternions are normalised; a norm off by more than 0.001 is refused,
/// and so is an id given twice.
/// `orientation_required`: refuse rows without a quaternion (every shape
/// but the sphere).
pub fn decode_poses_csv(bytes: &[u8], path: &str, orientation_required: bool) -> Result<Vec<PlacedPellet>, IoError> {
    let corrupt =
        |line: usize, reason: String| IoError::Corrupt { path: path.into(), reason: format!("line {line}: {reason}") };
    let text = std::str::from_utf8(bytes)
        .map_err(|e| IoError::Corrupt { path: path.into(), reason: format!("not UTF-8 text ({e})") })?;
    // columns[k]: the field index of NAMES[k], if present.
    let mut columns: Option<[Option<usize>; 8]> = None;
    let mut poses = Vec::new();
    let mut ids: std::collections::HashMap<String, usize> = std::collections::HashMap::new();
    for (n, raw) in text.lines().enumerate() {
        let line_no = n + 1;
        let line = raw.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        if columns.is_none() {
            if fields.iter().any(|f| NAMES.iter().any(|name| name.eq_ignore_ascii_case(f))) {
                let mut found = [None; 8];
                for (i, f) in fields.iter().enumerate() {
                    if let Some(k) = NAMES.iter().position(|name| name.eq_ignore_ascii_case(f)) {
                        found[k] = Some(i);
                    }
                }
                for k in 1..4 {
                    if found[k].is_none() {
                        return Err(corrupt(line_no, format!("the header lacks the column {:?}", NAMES[k])));
                    }
                }
                let quaternion = found[4..].iter().filter(|c| c.is_some()).count();
                if quaternion != 0 && quaternion != 4 {
                    return Err(corrupt(line_no, "the header names some but not all of qw, qx, qy, qz".into()));
                }
                columns = Some(found);
                continue;
            }
            columns = Some(match fields.len() {
                4 => [Some(0), Some(1), Some(2), Some(3), None, None, None, None],
                8 => NAMES.map(|name| NAMES.iter().position(|n| *n == name)),
                k => {
                    return Err(corrupt(line_no, format!("{k} fields; expected id,x,y,z or id,x,y,z,qw,qx,qy,qz")));
                }
            });
        }
        let cols = columns.expect("set above");
        let value = |k: usize| -> Result<Option<f64>, IoError> {
            let Some(i) = cols[k] else { return Ok(None) };
            let f = fields.get(i).ok_or_else(|| corrupt(line_no, format!("no {} field", NAMES[k])))?;
            match f.parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(Some(v)),
                _ => Err(corrupt(line_no, format!("{} = `{}` is not a finite number", NAMES[k], shown_field(f)))),
            }
        };
        if let Some(id) = cols[0].and_then(|i| fields.get(i)) {
            if let Some(first) = ids.insert(id.to_string(), line_no) {
                return Err(corrupt(
                    line_no,
                    format!("id {} is also on line {first}; every pellet needs its own id", shown_field(id)),
                ));
            }
        }
        let mut position = [0.0; 3];
        for (k, p) in position.iter_mut().enumerate() {
            *p = value(k + 1)?.expect("x, y, z are required") * 1e-3;
        }
        let orientation = match (value(4)?, value(5)?, value(6)?, value(7)?) {
            (Some(w), Some(x), Some(y), Some(z)) => {
                let norm = (w * w + x * x + y * y + z * z).sqrt();
                if (norm - 1.0).abs() > 1e-3 {
                    return Err(corrupt(
                        line_no,
                        format!("the quaternion has norm {}, not 1", pellet_geom::math::shown(norm)),
                    ));
                }
                [w / norm, x / norm, y / norm, z / norm]
            }
            _ if orientation_required => {
                return Err(corrupt(line_no, "no orientation: the pellet is not a sphere, so give qw,qx,qy,qz".into()));
            }
            _ => [1.0, 0.0, 0.0, 0.0],
        };
        poses.push(PlacedPellet { type_index: 0, position, orientation });
    }
    Ok(poses)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn headers_positional_columns_and_errors() {
        let with_header =
            b"# from Blender\nqw,qx,qy,qz,z,y,x,id\n1,0,0,0,5,2,1,a\n\n0.7071068,0.7071068,0,0,15,0,0,b\n";
        let poses = decode_poses_csv(with_header, "p.csv", true).unwrap();
        assert_eq!(poses.len(), 2);
        assert_eq!(poses[0].position, [0.001, 0.002, 0.005]);
        assert!((poses[1].orientation[1] - std::f64::consts::FRAC_1_SQRT_2).abs() < 1e-12);
        let positional = decode_poses_csv(b"1,0,0,5\n2,10,0,5\n", "p.csv", false).unwrap();
        assert_eq!(positional[1].position, [0.01, 0.0, 0.005]);
        let err = decode_poses_csv(b"1,0,0,5\n", "p.csv", true).unwrap_err().to_string();
        assert!(err.contains("line 1") && err.contains("qw,qx,qy,qz"), "{err}");
        let err = decode_poses_csv(b"1,0,0,5,2,0,0,0\n", "p.csv", true).unwrap_err().to_string();
        assert!(err.contains("norm 2"), "{err}");
        let err = decode_poses_csv(b"id,x,y\n1,2,3\n", "p.csv", false).unwrap_err().to_string();
        assert!(err.contains("\"z\""), "{err}");
        let err = decode_poses_csv(b"1,0,0,5\n2,0,nan,5\n", "p.csv", false).unwrap_err().to_string();
        assert!(err.contains("line 2") && err.contains("y"), "{err}");
        let err = decode_poses_csv(b"1,0,0,5\n2,0,0,15\n1,0,0,25\n", "p.csv", false).unwrap_err().to_string();
        assert!(err.contains("line 3: id 1 is also on line 1"), "{err}");
        let err = decode_poses_csv(b"1,0,0\n", "p.csv", false).unwrap_err().to_string();
        assert!(err.contains("3 fields"), "{err}");
    }
}
