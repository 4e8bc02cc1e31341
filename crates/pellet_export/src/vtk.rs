//! VTK XML files for ParaView (and VisIt, PyVista, meshio).
//!
//! # Format
//!
//! VTK XML, `version="1.0"`, `byte_order="LittleEndian"`,
//! `header_type="UInt64"`; every `DataArray` is `format="binary"`: the
//! base64 encoding of a little-endian u64 byte count followed by the raw
//! little-endian values (the layout ParaView writes itself, and valid XML
//! any XML parser reads). Three files:
//!
//! - [`polydata`] (`.vtp`): the pellets' surfaces (and bridges) as
//!   triangles. Points `Float32` ×3; `Polys` with `connectivity` and
//!   `offsets` as `Int64`; cell data `pellet_id` (`Int32`, the pellet's
//!   index in the packing file, −1 for bridges).
//! - [`centres`] (`.vtp`): one vertex per pellet at its centroid, with point
//!   data `pellet_id` (`Int32`), `axis` (`Float32` ×3: the body z axis, the
//!   symmetry axis, in world), `orientation` (`Float32` ×4: the unit
//!   quaternion w, x, y, z, body → world), `radial_position` (`Float32`: the
//!   centroid's distance from the tube axis) and `wall_distance`
//!   (`Float32`: tube radius minus it). Use ParaView's *Glyph* filter with
//!   `axis` to draw orientations.
//! - [`image`] (`.vti`): the voxel grid as `ImageData` with one cell per
//!   voxel and the cell data `solid` (`UInt8`: 0 fluid, 1 pellet, 2 outside
//!   the tube); `Origin` is the grid's corner, `Spacing` the voxel size.
//!
//! Lengths are multiplied by the writer's `scale` (1000: millimetres).

use std::fmt::Write;

use base64::Engine;

use pellet_geom::math::Real;
use pellet_geom::{Bed, TriMesh};

use crate::voxels::VoxelGrid;

/// Appends a binary `DataArray` element holding `bytes`.
fn data_array(out: &mut String, kind: &str, name: &str, components: usize, bytes: &[u8]) {
    let mut blob = Vec::with_capacity(8 + bytes.len());
    blob.extend_from_slice(&(bytes.len() as u64).to_le_bytes());
    blob.extend_from_slice(bytes);
    let _ = write!(
        out,
        "<DataArray type=\"{kind}\" Name=\"{name}\" NumberOfComponents=\"{components}\" format=\"binary\">"
    );
    out.push_str(&base64::engine::general_purpose::STANDARD.encode(&blob));
    out.push_str("</DataArray>\n");
}

fn bytes_f32(values: impl Iterator<Item = Real>) -> Vec<u8> {
    values.flat_map(|v| (v as f32).to_le_bytes()).collect()
}

fn bytes_i32(values: impl Iterator<Item = i32>) -> Vec<u8> {
    values.flat_map(|v| v.to_le_bytes()).collect()
}

fn bytes_i64(values: impl Iterator<Item = i64>) -> Vec<u8> {
    values.flat_map(|v| v.to_le_bytes()).collect()
}

fn open(kind: &str, comment: &str) -> String {
    let mut out = String::from("<?xml version=\"1.0\"?>\n");
    let _ = writeln!(out, "<!-- {} -->", comment.replace("--", "- -"));
    let _ =
        writeln!(out, "<VTKFile type=\"{kind}\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">");
    out
}

/// The surfaces `meshes`, each with its id, as VTK PolyData, coordinates × `scale`.
pub fn polydata(meshes: &[(i32, &TriMesh)], scale: Real, comment: &str) -> Vec<u8> {
    let points: usize = meshes.iter().map(|(_, m)| m.vertices.len()).sum();
    let cells: usize = meshes.iter().map(|(_, m)| m.face_count()).sum();
    let mut out = open("PolyData", comment);
    out.push_str("<PolyData>\n");
    let _ = writeln!(out, "<Piece NumberOfPoints=\"{points}\" NumberOfPolys=\"{cells}\">");
    out.push_str("<Points>\n");
    let coords =
        meshes.iter().flat_map(|(_, m)| m.vertices.iter().flat_map(|v| [v.x * scale, v.y * scale, v.z * scale]));
    data_array(&mut out, "Float32", "Points", 3, &bytes_f32(coords));
    out.push_str("</Points>\n<Polys>\n");
    let mut connectivity = Vec::with_capacity(3 * cells);
    let mut base = 0i64;
    for (_, m) in meshes {
        connectivity.extend(m.triangles.iter().flat_map(|t| t.map(|i| base + i as i64)));
        base += m.vertices.len() as i64;
    }
    data_array(&mut out, "Int64", "connectivity", 1, &bytes_i64(connectivity.into_iter()));
    data_array(&mut out, "Int64", "offsets", 1, &bytes_i64((1..=cells as i64).map(|k| 3 * k)));
    out.push_str("</Polys>\n<CellData Scalars=\"pellet_id\">\n");
    let ids = meshes.iter().flat_map(|(id, m)| std::iter::repeat_n(*id, m.face_count()));
    data_array(&mut out, "Int32", "pellet_id", 1, &bytes_i32(ids));
    out.push_str("</CellData>\n</Piece>\n</PolyData>\n</VTKFile>\n");
    out.into_bytes()
}

/// The centroids of the pellets `indices` of `bed` with their orientation
/// and radial position, as VTK PolyData vertices, lengths × `scale`.
pub fn centres(bed: &Bed, indices: &[usize], scale: Real, comment: &str) -> Vec<u8> {
    let n = indices.len();
    let poses: Vec<_> = indices.iter().map(|&i| &bed.pellets[i]).collect();
    let radius = 0.5 * bed.tube.diameter;
    let mut out = open("PolyData", comment);
    out.push_str("<PolyData>\n");
    let _ = writeln!(out, "<Piece NumberOfPoints=\"{n}\" NumberOfVerts=\"{n}\">");
    out.push_str("<Points>\n");
    data_array(&mut out, "Float32", "Points", 3, &bytes_f32(poses.iter().flat_map(|p| p.position.map(|c| c * scale))));
    out.push_str("</Points>\n<Verts>\n");
    data_array(&mut out, "Int64", "connectivity", 1, &bytes_i64(0..n as i64));
    data_array(&mut out, "Int64", "offsets", 1, &bytes_i64(1..=n as i64));
    out.push_str("</Verts>\n<PointData Scalars=\"pellet_id\" Vectors=\"axis\">\n");
    data_array(&mut out, "Int32", "pellet_id", 1, &bytes_i32(indices.iter().map(|&i| i as i32)));
    let axes = poses.iter().flat_map(|p| {
        let a = p.axis();
        [a.x, a.y, a.z]
    });
    data_array(&mut out, "Float32", "axis", 3, &bytes_f32(axes));
    data_array(&mut out, "Float32", "orientation", 4, &bytes_f32(poses.iter().flat_map(|p| p.orientation)));
    let rho: Vec<Real> = poses.iter().map(|p| p.position[0].hypot(p.position[1])).collect();
    data_array(&mut out, "Float32", "radial_position", 1, &bytes_f32(rho.iter().map(|r| r * scale)));
    data_array(&mut out, "Float32", "wall_distance", 1, &bytes_f32(rho.iter().map(|r| (radius - r) * scale)));
    out.push_str("</PointData>\n</Piece>\n</PolyData>\n</VTKFile>\n");
    out.into_bytes()
}

/// The voxel grid as VTK ImageData (one cell per voxel), lengths × `scale`.
pub fn image(grid: &VoxelGrid, scale: Real, comment: &str) -> Vec<u8> {
    let [nx, ny, nz] = grid.dims;
    let [ox, oy, oz] = grid.origin.map(|c| c * scale);
    let h = grid.spacing * scale;
    let mut out = open("ImageData", comment);
    let _ = writeln!(
        out,
        "<ImageData WholeExtent=\"0 {nx} 0 {ny} 0 {nz}\" Origin=\"{ox} {oy} {oz}\" Spacing=\"{h} {h} {h}\">"
    );
    let _ = writeln!(out, "<Piece Extent=\"0 {nx} 0 {ny} 0 {nz}\">");
    out.push_str("<CellData Scalars=\"solid\">\n");
    data_array(&mut out, "UInt8", "solid", 1, &grid.data);
    out.push_str("</CellData>\n</Piece>\n</ImageData>\n</VTKFile>\n");
    out.into_bytes()
}
