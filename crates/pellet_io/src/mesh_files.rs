//! STL and OBJ: reading user meshes, exporting pellet meshes.

use std::io::Cursor;

use pellet_geom::math::{Point, Real};
use pellet_geom::TriMesh;

use crate::IoError;

/// Mesh file formats packbed reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshFormat {
    /// STL, binary or ASCII.
    Stl,
    /// Wavefront OBJ (polygons are fan-triangulated).
    Obj,
}

impl MeshFormat {
    /// The format named by a file's extension (case-insensitive).
    pub fn from_path(path: &str) -> Option<MeshFormat> {
        let ext = std::path::Path::new(path).extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "stl" => Some(MeshFormat::Stl),
            "obj" => Some(MeshFormat::Obj),
            _ => None,
        }
    }
}

/// Parses a mesh. Coordinates are returned as stored (no unit conversion);
/// coincident STL vertices are merged so the mesh is indexed.
pub fn read_mesh(bytes: &[u8], format: MeshFormat, path: &str) -> Result<TriMesh, IoError> {
    let corrupt = |reason: String| IoError::Corrupt { path: path.into(), reason };
    let mesh = match format {
        MeshFormat::Stl => {
            let triangles = crate::stl_read::read_stl(bytes).map_err(|e| corrupt(format!("unreadable STL: {e}")))?;
            let corner = |c: [f32; 3]| Point::new(c[0] as Real, c[1] as Real, c[2] as Real);
            let vertices = triangles.iter().flat_map(|t| t.map(corner)).collect();
            let triangles = (0..triangles.len() as u32).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect();
            merge_coincident(TriMesh { vertices, triangles })
        }
        MeshFormat::Obj => {
            let options = tobj::LoadOptions { triangulate: true, single_index: true, ..Default::default() };
            let (models, _) = tobj::load_obj_buf(&mut Cursor::new(bytes), &options, |_| {
                Err(tobj::LoadError::GenericFailure) // materials are not needed
            })
            .map_err(|e| corrupt(format!("unreadable OBJ: {e}")))?;
            let mut mesh = TriMesh::default();
            for model in models {
                let base = mesh.vertices.len() as u32;
                let m = model.mesh;
                let count = m.positions.len() / 3;
                if let Some(&i) = m.indices.iter().find(|&&i| i as usize >= count) {
                    return Err(corrupt(format!(
                        "unreadable OBJ: a face names vertex {} of an object with {count}",
                        i as u64 + 1
                    )));
                }
                mesh.vertices
                    .extend(m.positions.chunks_exact(3).map(|p| Point::new(p[0] as Real, p[1] as Real, p[2] as Real)));
                mesh.triangles.extend(m.indices.chunks_exact(3).map(|t| [base + t[0], base + t[1], base + t[2]]));
            }
            merge_coincident(mesh)
        }
    };
    if mesh.triangles.is_empty() {
        return Err(corrupt("the file holds no triangles".into()));
    }
    // Binary STL and OBJ (`nan`, `1e999`) can hold numbers no pellet is made of.
    if mesh.vertices.iter().any(|v| !v.iter().all(|c| c.is_finite())) {
        return Err(corrupt("a vertex has a coordinate that is not a finite number (NaN or infinite)".into()));
    }
    if format == MeshFormat::Stl {
        single_precision_suffices(&mesh).map_err(corrupt)?;
    }
    Ok(mesh)
}

/// STL stores single-precision coordinates: far from the origin their step (2⁻²³ of the
/// distance) is a visible part of a small pellet, and re-centring cannot bring back what the
/// file no longer holds. Refused when the step exceeds 1e-4 of the pellet's size.
fn single_precision_suffices(mesh: &TriMesh) -> Result<(), String> {
    let far = mesh.vertices.iter().flat_map(|v| [v.x, v.y, v.z]).fold(0.0, |m: Real, c| m.max(c.abs()));
    let size = (0..3)
        .map(|k| {
            let (lo, hi) = mesh
                .vertices
                .iter()
                .fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), v| (lo.min(v.coords[k]), hi.max(v.coords[k])));
            hi - lo
        })
        .fold(0.0, Real::max);
    let step = far * Real::from(f32::EPSILON);
    if step > 1e-4 * size {
        return Err(format!(
            "the mesh lies {far:.4e} units from the origin, where STL's single precision resolves only {step:.3e} \
             units of its {size:.4e}-unit size; move it to the origin before exporting (or export OBJ, which keeps double precision)"
        ));
    }
    Ok(())
}

/// Merges vertices with identical coordinates (OBJ groups repeat them, STL lists every
/// triangle's corners).
fn merge_coincident(mesh: TriMesh) -> TriMesh {
    let mut index = std::collections::BTreeMap::new();
    let mut vertices = Vec::new();
    let remap: Vec<u32> = mesh
        .vertices
        .iter()
        .map(|v| {
            let key = [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()];
            *index.entry(key).or_insert_with(|| {
                vertices.push(*v);
                (vertices.len() - 1) as u32
            })
        })
        .collect();
    let triangles = mesh.triangles.iter().map(|t| t.map(|i| remap[i as usize])).collect();
    TriMesh { vertices, triangles }
}

/// Binary STL of `mesh` with every coordinate multiplied by `scale`
/// (1000 for metres → millimetres).
pub fn stl_bytes(mesh: &TriMesh, scale: Real) -> Result<Vec<u8>, IoError> {
    let triangles: Vec<stl_io::Triangle> = (0..mesh.face_count())
        .map(|t| {
            let n = mesh.area_normal(t);
            let n = if n.norm() > 0.0 { n.normalize() } else { n };
            let [a, b, c] = mesh.corners(t);
            let v = |p: Point| stl_io::Vertex::new([(p.x * scale) as f32, (p.y * scale) as f32, (p.z * scale) as f32]);
            stl_io::Triangle {
                normal: stl_io::Normal::new([n.x as f32, n.y as f32, n.z as f32]),
                vertices: [v(a), v(b), v(c)],
            }
        })
        .collect();
    let mut out = Vec::with_capacity(84 + 50 * triangles.len());
    stl_io::write_stl(&mut out, triangles.iter()).map_err(|source| IoError::Io { path: "<stl>".into(), source })?;
    Ok(out)
}

/// Wavefront OBJ text of `mesh`, coordinates multiplied by `scale`.
pub fn obj_bytes(mesh: &TriMesh, scale: Real, comment: &str) -> Vec<u8> {
    use std::fmt::Write;
    let mut s = String::with_capacity(64 * (mesh.vertices.len() + mesh.triangles.len()));
    for line in comment.lines() {
        let _ = writeln!(s, "# {line}");
    }
    for v in &mesh.vertices {
        let _ = writeln!(s, "v {} {} {}", v.x * scale, v.y * scale, v.z * scale);
    }
    for t in &mesh.triangles {
        let _ = writeln!(s, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    s.into_bytes()
}
