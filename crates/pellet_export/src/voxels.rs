//! Solid/fluid voxel grids for lattice-Boltzmann codes.
//!
//! # Format of the raw file and its header
//!
//! The raw file is `nx·ny·nz` unsigned bytes, nothing else (byte order does
//! not arise for one-byte values): **x varies fastest, then y, then z** —
//! the byte of voxel (i, j, k) is at `i + nx·(j + ny·k)`, i.e. a C array
//! `[nz][ny][nx]` or a Fortran / VTK array `(nx, ny, nz)`. Values:
//!
//! | value | meaning |
//! |---|---|
//! | 0 | fluid |
//! | 1 | pellet (solid) |
//! | 2 | outside the tube (the wall: solid for LBM) |
//!
//! Voxel (i, j, k) is the cube whose lower corner is `origin + h·(i, j, k)`;
//! its value is that of its centre. The grid covers the tube's square
//! cross-section (centred on the axis) and the axial range from its bottom
//! in whole voxels (a top part thinner than a voxel is left out).
//!
//! The header ([`header_json`]) is a JSON object: `format`
//! (`"packbed-voxels"`), `version` (1), `raw_file`, `dims` `[nx, ny, nz]`,
//! `order` (`"x fastest, then y, then z"`), `dtype` (`"uint8"`), `values`,
//! `unit`, `voxel_size`, `origin` (the grid corner), `tube_diameter`,
//! `voxels_per_dp`, the counts of each value, `porosity` (fluid voxels /
//! voxels inside the tube) and the tool's provenance.

use pellet_analysis::{Geometry, LineCaster};
use pellet_geom::math::Real;
use pellet_geom::Bed;
use serde_json::{json, Value};

use crate::ExportError;

/// The largest grid built (voxels): 2³¹, 2 GiB of memory.
pub const MAX_VOXELS: u64 = 1 << 31;

/// What a voxel holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum VoxelValue {
    /// Fluid inside the tube.
    Fluid = 0,
    /// Inside a pellet.
    Pellet = 1,
    /// Outside the tube (its wall).
    Outside = 2,
}

/// A uniform grid of voxels (see the module doc for the layout).
#[derive(Clone, Debug, PartialEq)]
pub struct VoxelGrid {
    /// Voxels along x, y, z.
    pub dims: [usize; 3],
    /// Lower corner of voxel (0, 0, 0) (m).
    pub origin: [Real; 3],
    /// Edge of a voxel (m).
    pub spacing: Real,
    /// One [`VoxelValue`] byte per voxel, x fastest.
    pub data: Vec<u8>,
}

impl VoxelGrid {
    /// How many voxels hold `value`.
    pub fn count(&self, value: VoxelValue) -> usize {
        self.data.iter().filter(|&&v| v == value as u8).count()
    }

    /// Fluid voxels over the voxels inside the tube.
    pub fn porosity(&self) -> Real {
        let fluid = self.count(VoxelValue::Fluid);
        fluid as Real / (fluid + self.count(VoxelValue::Pellet)) as Real
    }

    /// The axial range the grid covers (m).
    pub fn z_range(&self) -> (Real, Real) {
        (self.origin[2], self.origin[2] + self.dims[2] as Real * self.spacing)
    }
}

/// Voxelises `bed` with voxels of edge `spacing` (m) over the axial `range`
/// (m): a voxel is pellet when its centre is inside any pellet (exact
/// vertical chords for closed forms, mesh crossings otherwise, the same
/// lines `voidprof` integrates), outside when its centre is farther from the
/// axis than the tube radius. `progress(done, total)` is called as pellets
/// are processed.
pub fn voxelise(
    bed: &Bed,
    spacing: Real,
    range: (Real, Real),
    progress: &mut dyn FnMut(usize, usize),
) -> Result<VoxelGrid, ExportError> {
    let radius = 0.5 * bed.tube.diameter;
    if !(spacing.is_finite() && spacing > 0.0) {
        return Err(ExportError::BadParameter(format!("the voxel size must be > 0 (got {} mm)", spacing * 1e3)));
    }
    let n_xy = (bed.tube.diameter / spacing).ceil() as u64;
    let n_z = ((range.1 - range.0) / spacing).floor() as u64;
    if n_z == 0 {
        return Err(ExportError::BadParameter(format!(
            "the voxel size {} mm exceeds the height of the range ({} mm); choose smaller voxels",
            spacing * 1e3,
            (range.1 - range.0) * 1e3
        )));
    }
    let total = n_xy * n_xy * n_z;
    if total > MAX_VOXELS {
        return Err(ExportError::BadParameter(format!(
            "{n_xy} × {n_xy} × {n_z} = {total} voxels is more than {MAX_VOXELS}; choose larger voxels or a smaller --window"
        )));
    }
    let (nx, nz) = (n_xy as usize, n_z as usize);
    let origin = [-0.5 * nx as Real * spacing, -0.5 * nx as Real * spacing, range.0];
    let centre = |i: usize, o: Real| o + (i as Real + 0.5) * spacing;
    let mut data = vec![VoxelValue::Fluid as u8; nx * nx * nz];
    // Columns outside the tube are wall from bottom to top.
    let mut outside = vec![false; nx * nx];
    for j in 0..nx {
        for i in 0..nx {
            outside[i + nx * j] = centre(i, origin[0]).hypot(centre(j, origin[1])) > radius;
        }
    }
    for k in 0..nz {
        let layer = &mut data[k * nx * nx..(k + 1) * nx * nx];
        for (v, &out) in layer.iter_mut().zip(&outside) {
            if out {
                *v = VoxelValue::Outside as u8;
            }
        }
    }
    let (z_lo, z_hi) = (origin[2], origin[2] + nz as Real * spacing);
    let mut chords = Vec::new();
    for (done, pose) in bed.pellets.iter().enumerate() {
        progress(done, bed.pellets.len());
        let caster = LineCaster::new(&bed.pellet_types[pose.type_index as usize], pose, Geometry::Auto);
        let c = caster.centre();
        if c.z + caster.half_extent_z() < z_lo || c.z - caster.half_extent_z() > z_hi {
            continue;
        }
        let reach = caster.footprint();
        let index = |x: Real, o: Real| ((x - o) / spacing - 0.5).max(0.0);
        let (i0, i1) = (
            index(c.x - reach, origin[0]).ceil() as usize,
            (index(c.x + reach, origin[0]).floor() as usize).min(nx - 1),
        );
        let (j0, j1) = (
            index(c.y - reach, origin[1]).ceil() as usize,
            (index(c.y + reach, origin[1]).floor() as usize).min(nx - 1),
        );
        for j in j0..=j1 {
            for i in i0..=i1 {
                if outside[i + nx * j] {
                    continue;
                }
                chords.clear();
                caster.intervals(centre(i, origin[0]), centre(j, origin[1]), &mut chords);
                for &(lo, hi) in &chords {
                    // Voxels whose centre z lies in [lo, hi].
                    let k0 = ((lo - z_lo) / spacing - 0.5).ceil().max(0.0) as usize;
                    let k1 = ((hi - z_lo) / spacing - 0.5).floor();
                    if k1 < 0.0 {
                        continue;
                    }
                    for k in k0..=(k1 as usize).min(nz - 1) {
                        data[i + nx * (j + nx * k)] = VoxelValue::Pellet as u8;
                    }
                }
            }
        }
    }
    progress(bed.pellets.len(), bed.pellets.len());
    Ok(VoxelGrid { dims: [nx, nx, nz], origin, spacing, data })
}

/// The header of a raw voxel file (see the module doc), lengths × `scale`
/// in `unit`; `dp` (m) gives `voxels_per_dp`; `extra` is merged in
/// (provenance, the exact porosity).
pub fn header_json(
    grid: &VoxelGrid,
    raw_file: &str,
    scale: Real,
    unit: &str,
    tube_diameter: Real,
    dp: Real,
    extra: Value,
) -> Value {
    let mut header = json!({
        "format": "packbed-voxels",
        "version": 1,
        "raw_file": raw_file,
        "dims": grid.dims,
        "order": "x fastest, then y, then z: byte i + nx*(j + ny*k)",
        "dtype": "uint8",
        "values": { "0": "fluid", "1": "pellet", "2": "outside the tube (wall)" },
        "unit": unit,
        "voxel_size": grid.spacing * scale,
        "origin": grid.origin.map(|c| c * scale),
        "origin_is": "the lower corner of voxel (0, 0, 0); a voxel's value is that of its centre",
        "tube_diameter": tube_diameter * scale,
        "voxels_per_dp": dp / grid.spacing,
        "counts": {
            "fluid": grid.count(VoxelValue::Fluid),
            "pellet": grid.count(VoxelValue::Pellet),
            "outside": grid.count(VoxelValue::Outside),
        },
        "porosity": grid.porosity(),
    });
    if let (Some(h), Value::Object(more)) = (header.as_object_mut(), extra) {
        h.extend(more);
    }
    header
}

#[cfg(test)]
mod tests {
    use super::*;
    use pellet_analysis::bulk_porosity;
    use pellet_analysis::synthetic::random_placement;
    use pellet_geom::{Pellet, Resolution, ShapeSpec};

    /// |voxel − exact| porosity at 5, 10, 20 and 40 voxels per dp.
    fn errors(pellet: &Pellet, seed: u64) -> Vec<Real> {
        let bed = random_placement(pellet, 0.04, 0.04, 40, seed);
        [5.0, 10.0, 20.0, 40.0]
            .iter()
            .map(|per_dp| {
                let top = pellet_analysis::bed_top(&bed).min(0.03);
                let grid = voxelise(&bed, 0.01 / per_dp, (0.0, top), &mut |_, _| {}).unwrap();
                let exact = bulk_porosity(&bed, grid.z_range(), Geometry::Auto).unwrap().porosity;
                (grid.porosity() - exact).abs()
            })
            .collect()
    }

    #[test]
    fn voxel_porosity_converges_to_the_exact_porosity() {
        let sphere = Pellet::build(ShapeSpec::Sphere { diameter_mm: 10.0 }, Resolution::default()).unwrap();
        let ring = Pellet::build(
            ShapeSpec::Ring { outer_diameter_mm: 10.0, inner_diameter_mm: 6.0, height_mm: 10.0 },
            Resolution::default(),
        )
        .unwrap();
        for pellet in [sphere, ring] {
            let e = errors(&pellet, 7);
            assert!(e[3] < 0.002, "{e:?}");
            assert!(e[3] < e[0], "{e:?}");
            assert!(e[0] < 0.03, "{e:?}");
        }
    }

    #[test]
    fn layout_is_x_fastest_and_the_wall_is_marked() {
        let sphere = Pellet::build(ShapeSpec::Sphere { diameter_mm: 10.0 }, Resolution::default()).unwrap();
        let mut bed = random_placement(&sphere, 0.02, 0.02, 1, 1);
        bed.pellets[0].position = [0.004, 0.0, 0.005];
        let grid = voxelise(&bed, 0.001, (0.0, 0.01), &mut |_, _| {}).unwrap();
        assert_eq!(grid.dims, [20, 20, 10]);
        let at = |i: usize, j: usize, k: usize| grid.data[i + 20 * (j + 20 * k)];
        // The sphere's centre (4, 0, 5) mm is at voxel (14, 10, 5) (corner at −10 mm); the corner voxel is wall.
        assert_eq!(at(14, 10, 5), VoxelValue::Pellet as u8);
        assert_eq!(at(5, 10, 5), VoxelValue::Fluid as u8);
        assert_eq!(at(0, 0, 0), VoxelValue::Outside as u8);
    }
}
