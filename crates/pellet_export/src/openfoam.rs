//! An OpenFOAM case that meshes the fluid of a bed as it is: blockMesh for
//! a background box around the tube, surfaceFeatureExtract, then
//! snappyHexMesh against the pellet surface and the tube (patches `wall`,
//! `inlet`, `outlet`, `pellets`).
//!
//! # Layout
//!
//! - `constant/triSurface/pellets.stl`: the pellets (and bridges) united
//!   into one closed surface ([`crate::unite`]), the ASCII solid `pellets`.
//! - `constant/triSurface/tube.stl`: the tube's inside from the floor minus
//!   the inlet length to the bed top plus the outlet length, as the ASCII
//!   solids `wall`, `inlet` (bottom) and `outlet` (top).
//! - `system/`: `controlDict`, `blockMeshDict`, `surfaceFeatureExtractDict`,
//!   `snappyHexMeshDict`, `meshQualityDict`, `fvSchemes`, `fvSolution`.
//! - `README`: the commands and the OpenFOAM version tested.
//!
//! Coordinates are metres (OpenFOAM reads every length as metres). The
//! background cells are twice the cell size; the pellets are refined one
//! level, to the cell size. `locationInMesh` is [`location_in_mesh`].

use std::fmt::Write;

use pellet_geom::math::{Point, Real};
use pellet_geom::TriMesh;

use crate::stl;

/// The OpenFOAM version the case is tested with.
pub const TESTED_VERSION: &str = "OpenFOAM v1912 (Debian 12's openfoam package, 1912.200626)";

/// What the dictionaries need to know (lengths in m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CaseGeometry {
    /// Tube radius.
    pub radius: Real,
    /// Bottom of the fluid (the floor minus the inlet length).
    pub z0: Real,
    /// Top of the fluid (the bed top plus the outlet length).
    pub z1: Real,
    /// Cell size at the pellets; the background cells are twice as big.
    pub cell: Real,
    /// A point in the fluid (see [`location_in_mesh`]).
    pub location: Point,
}

/// The tube's inside, closed, as the three solids `wall`, `inlet` (at
/// `z0`) and `outlet` (at `z1`): ASCII STL in m.
pub fn tube_stl(radius: Real, z0: Real, z1: Real, segments: usize) -> Vec<u8> {
    let tube = crate::scene::tube_mesh(radius, z0, z1, segments);
    // tube_mesh writes per side: two wall triangles, one bottom, one top.
    let pick = |keep: &[usize]| TriMesh {
        vertices: tube.vertices.clone(),
        triangles: tube
            .triangles
            .iter()
            .enumerate()
            .filter(|(i, _)| keep.contains(&(i % 4)))
            .map(|(_, t)| *t)
            .collect(),
    };
    let (wall, inlet, outlet) = (pick(&[0, 1]), pick(&[2]), pick(&[3]));
    stl::ascii(&[("wall".into(), &wall), ("inlet".into(), &inlet), ("outlet".into(), &outlet)], 1.0)
}

/// The fluid point farthest from every surface (pellets, wall, inlet,
/// outlet), searched on a grid of `step`: snappyHexMesh keeps the cells
/// connected to it, and a point far from all surfaces is never on a face
/// of the background mesh by accident. Distances to a pellet are to its
/// mesh vertices (close for the fine meshes pellets have); points inside a
/// pellet are skipped. `None` if every grid point is inside a pellet.
pub fn location_in_mesh(meshes: &[TriMesh], radius: Real, z0: Real, z1: Real, step: Real) -> Option<Point> {
    // Bounding spheres give a lower bound that skips most pellets for each point.
    let bounds: Vec<(Point, Real)> = meshes
        .iter()
        .map(|m| {
            let n = m.vertices.len().max(1) as Real;
            let c = Point::from(m.vertices.iter().fold(pellet_geom::math::Vector::zeros(), |s, v| s + v.coords) / n);
            let r = m.vertices.iter().map(|v| (v - c).norm()).fold(0.0, Real::max);
            (c, r)
        })
        .collect();
    let n_r = (radius / step).ceil() as i64;
    let n_z = ((z1 - z0) / step).ceil() as i64;
    let mut best: Option<(Real, Point)> = None;
    for iz in 0..n_z {
        // Half a step off the grid of the background mesh's faces.
        let z = z0 + (iz as Real + 0.5) * step * (z1 - z0) / (n_z as Real * step);
        for ix in -n_r..n_r {
            for iy in -n_r..n_r {
                let p = Point::new((ix as Real + 0.5) * step, (iy as Real + 0.5) * step, z);
                let mut d = (radius - p.x.hypot(p.y)).min(z - z0).min(z1 - z);
                if d <= best.map_or(0.0, |b| b.0) {
                    continue;
                }
                let mut inside = false;
                for (m, (c, r)) in meshes.iter().zip(&bounds) {
                    let centre = (p - c).norm();
                    if centre - r >= d {
                        continue;
                    }
                    let near = m.vertices.iter().map(|v| (v - p).norm()).fold(Real::INFINITY, Real::min);
                    if centre < *r && m.contains(&p) {
                        inside = true;
                        break;
                    }
                    d = d.min(near);
                }
                if !inside && d > best.map_or(0.0, |b| b.0) {
                    best = Some((d, p));
                }
            }
        }
    }
    best.map(|b| b.1)
}

fn header(class: &str, object: &str) -> String {
    format!(
        "FoamFile\n{{\n    version     2.0;\n    format      ascii;\n    class       {class};\n    object      {object};\n}}\n\n"
    )
}

/// `system/controlDict`: enough for the meshing utilities.
pub fn control_dict() -> String {
    header("dictionary", "controlDict")
        + "application     snappyHexMesh;\nstartFrom       startTime;\nstartTime       0;\nstopAt          endTime;\n\
           endTime         1;\ndeltaT          1;\nwriteControl    timeStep;\nwriteInterval   1;\n\
           writeFormat     binary;\nwritePrecision  8;\nwriteCompression off;\ntimeFormat      general;\n\
           timePrecision   6;\nrunTimeModifiable false;\n"
}

/// `system/blockMeshDict`: a box just around the tube, cubic cells of twice the cell size.
pub fn block_mesh_dict(g: &CaseGeometry) -> String {
    let h = 2.0 * g.cell;
    // Half a background cell of margin keeps the tube wall off the box faces.
    let n_xy = ((2.0 * g.radius + h) / h).ceil() as usize;
    let half = 0.5 * n_xy as Real * h;
    let n_z = ((g.z1 - g.z0 + h) / h).ceil() as usize;
    let (zlo, zhi) = (0.5 * (g.z0 + g.z1) - 0.5 * n_z as Real * h, 0.5 * (g.z0 + g.z1) + 0.5 * n_z as Real * h);
    let mut s = header("dictionary", "blockMeshDict");
    let _ = writeln!(s, "scale 1;\n\nvertices\n(");
    for (x, y, z) in [
        (-half, -half, zlo),
        (half, -half, zlo),
        (half, half, zlo),
        (-half, half, zlo),
        (-half, -half, zhi),
        (half, -half, zhi),
        (half, half, zhi),
        (-half, half, zhi),
    ] {
        let _ = writeln!(s, "    ({x:.9e} {y:.9e} {z:.9e})");
    }
    let _ = write!(
        s,
        ");\n\nblocks\n(\n    hex (0 1 2 3 4 5 6 7) ({n_xy} {n_xy} {n_z}) simpleGrading (1 1 1)\n);\n\n\
         edges ();\n\nboundary\n(\n    box\n    {{\n        type patch;\n        faces\n        (\n\
         \x20           (0 3 2 1) (4 5 6 7) (0 1 5 4) (1 2 6 5) (2 3 7 6) (3 0 4 7)\n        );\n    }}\n);\n"
    );
    s
}

/// `system/surfaceFeatureExtractDict`: the edges sharper than 30° of both surfaces.
pub fn surface_feature_extract_dict() -> String {
    let mut s = header("dictionary", "surfaceFeatureExtractDict");
    for name in ["tube.stl", "pellets.stl"] {
        let _ = writeln!(
            s,
            "{name}\n{{\n    extractionMethod    extractFromSurface;\n    extractFromSurfaceCoeffs\n    {{\n        \
             includedAngle   150;\n    }}\n    subsetFeatures\n    {{\n        nonManifoldEdges yes;\n        \
             openEdges       yes;\n    }}\n    writeObj            no;\n}}\n"
        );
    }
    s
}

/// `system/snappyHexMeshDict`: castellate and snap, no layers.
pub fn snappy_hex_mesh_dict(g: &CaseGeometry) -> String {
    let p = g.location;
    let mut s = header("dictionary", "snappyHexMeshDict");
    let _ = write!(
        s,
        "castellatedMesh true;\nsnap            true;\naddLayers       false;\n\n\
geometry\n{{\n    tube.stl\n    {{\n        type triSurfaceMesh;\n        name tube;\n        regions\n        {{\n\
            wall   {{ name wall; }}\n            inlet  {{ name inlet; }}\n            outlet {{ name outlet; }}\n        }}\n    }}\n\
    pellets.stl\n    {{\n        type triSurfaceMesh;\n        name pellets;\n        regions\n        {{\n\
            pellets {{ name pellets; }}\n        }}\n    }}\n}}\n\n\
castellatedMeshControls\n{{\n    maxLocalCells       2000000;\n    maxGlobalCells      10000000;\n\
    minRefinementCells  0;\n    maxLoadUnbalance    0.10;\n    nCellsBetweenLevels 2;\n\
    features\n    (\n        {{ file \"tube.eMesh\"; level 1; }}\n        {{ file \"pellets.eMesh\"; level 1; }}\n    );\n\
    refinementSurfaces\n    {{\n        tube\n        {{\n            level (0 0);\n            regions\n            {{\n\
                wall   {{ level (0 0); patchInfo {{ type wall; }} }}\n\
                inlet  {{ level (0 0); patchInfo {{ type patch; }} }}\n\
                outlet {{ level (0 0); patchInfo {{ type patch; }} }}\n            }}\n        }}\n\
        pellets\n        {{\n            level (1 1);\n            patchInfo {{ type wall; }}\n        }}\n    }}\n\
    resolveFeatureAngle 30;\n    refinementRegions {{}}\n\
    locationInMesh ({:.9e} {:.9e} {:.9e});\n    allowFreeStandingZoneFaces true;\n}}\n\n\
snapControls\n{{\n    nSmoothPatch 3;\n    tolerance    2.0;\n    nSolveIter   50;\n    nRelaxIter   5;\n\
    nFeatureSnapIter 10;\n    implicitFeatureSnap false;\n    explicitFeatureSnap true;\n    multiRegionFeatureSnap false;\n}}\n\n\
addLayersControls\n{{\n    relativeSizes true;\n    layers {{}}\n    expansionRatio 1.0;\n    finalLayerThickness 0.3;\n\
    minThickness 0.1;\n    nGrow 0;\n    featureAngle 60;\n    nRelaxIter 3;\n    nSmoothSurfaceNormals 1;\n\
    nSmoothNormals 3;\n    nSmoothThickness 10;\n    maxFaceThicknessRatio 0.5;\n    maxThicknessToMedialRatio 0.3;\n\
    minMedialAxisAngle 90;\n    nBufferCellsNoExtrude 0;\n    nLayerIter 50;\n}}\n\n\
meshQualityControls\n{{\n    #include \"meshQualityDict\"\n}}\n\n\
mergeTolerance 1e-6;\n",
        p.x, p.y, p.z
    );
    s
}

/// `system/meshQualityDict`: the limits OpenFOAM's own caseDicts use, except
/// that boundary faces are held to checkMesh's skewness limit (4) rather than
/// the caseDicts' 20, so that snappyHexMesh never leaves a face checkMesh
/// fails (a pellet's boundary face at skewness 4.65 did, on a cylinder bed).
pub fn mesh_quality_dict() -> String {
    header("dictionary", "meshQualityDict")
        + "maxNonOrtho 65;\nmaxBoundarySkewness 4;\nmaxInternalSkewness 4;\nmaxConcave 80;\n\
           minVol 1e-13;\nminTetQuality 1e-15;\nminArea -1;\nminTwist 0.02;\nminDeterminant 0.001;\n\
           minFaceWeight 0.05;\nminVolRatio 0.01;\nminTriangleTwist -1;\nnSmoothScale 4;\nerrorReduction 0.75;\n\
           relaxed\n{\n    maxNonOrtho 75;\n}\n"
}

/// `system/fvSchemes` and `system/fvSolution`: empty, as the meshing utilities need them to exist.
pub fn fv_schemes() -> String {
    header("dictionary", "fvSchemes")
        + "ddtSchemes {}\ngradSchemes {}\ndivSchemes {}\nlaplacianSchemes {}\ninterpolationSchemes {}\nsnGradSchemes {}\n"
}

/// See [`fv_schemes`].
pub fn fv_solution() -> String {
    header("dictionary", "fvSolution")
}

/// The case's README: what is where and the commands.
pub fn readme(g: &CaseGeometry, source: &str, treatment: &str) -> String {
    format!(
        "OpenFOAM case of the packed bed {source}, written by packbed bedexport {}.\n\n\
Tested with {TESTED_VERSION}.\n\
All lengths are metres. The tube's inside runs from z = {:.6} m to z = {:.6} m (radius {:.6} m);\n\
cells are {:.6} m at the pellets and twice that elsewhere. Contact treatment: {treatment}.\n\n\
Mesh the fluid (from this directory):\n\n\
    blockMesh\n    surfaceFeatureExtract\n    snappyHexMesh -overwrite\n\n\
then `checkMesh` should end in \"Mesh OK\". Patches: inlet (bottom), outlet (top), wall (tube), pellets.\n\
With Debian's openfoam package, set FOAM_INST_DIR=/usr/share/openfoam and\n\
WM_PROJECT_DIR=/usr/share/openfoam in the environment first.\n",
        env!("CARGO_PKG_VERSION"),
        g.z0,
        g.z1,
        g.radius,
        g.cell
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tube_regions_and_location() {
        let text = String::from_utf8(tube_stl(0.01, -0.005, 0.02, 16)).unwrap();
        let solids: Vec<&str> = text.lines().filter_map(|l| l.strip_prefix("solid ")).collect();
        assert_eq!(solids, ["wall", "inlet", "outlet"]);
        assert_eq!(text.matches("facet normal").count(), 64);
        // One sphere filling the lower half: the farthest fluid point is above it.
        let sphere = pellet_geom::Pellet::build(
            pellet_geom::ShapeSpec::Sphere { diameter_mm: 20.0 },
            pellet_geom::Resolution::default(),
        )
        .unwrap();
        let mut mesh = sphere.mesh.clone();
        mesh.translate(&pellet_geom::math::Vector::new(0.0, 0.0, 0.01));
        let p = location_in_mesh(&[mesh], 0.01, 0.0, 0.04, 0.001).unwrap();
        assert!(p.z > 0.02 && p.x.hypot(p.y) < 0.005, "{p:?}");
        let g = CaseGeometry { radius: 0.01, z0: 0.0, z1: 0.04, cell: 0.001, location: p };
        assert!(block_mesh_dict(&g).contains("(11 11 21)"));
        assert!(snappy_hex_mesh_dict(&g).contains("locationInMesh ("));
    }
}
