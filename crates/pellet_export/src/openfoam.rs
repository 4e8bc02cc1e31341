//! An OpenFOAM case that meshes the fluid of a bed as it is: blockMesh for
//! a background box around the tube, surfaceFeatureExtract, then
//! snappyHexMesh against the pellet surface and the tube (patches `wall`,
//! `inlet`, `outlet`, `pellets`); then simpleFoam for a steady laminar flow
//! along +z ([`Flow`]) whose pressure drop over the packed section is logged.
//!
//! # Layout
//!
//! - `constant/triSurface/pellets.stl`: the pellets (and bridges) united
//!   into one closed surface ([`crate::unite`]), the ASCII solid `pellets`.
//! - `constant/triSurface/tube.stl`: the tube's inside from the floor minus
//!   the inlet length to the bed top plus the outlet length, as the ASCII
//!   solids `wall`, `inlet` (bottom) and `outlet` (top).
//! - `system/`: `controlDict` (simpleFoam, with the pressure function
//!   objects), `blockMeshDict`, `surfaceFeatureExtractDict`,
//!   `snappyHexMeshDict`, `meshQualityDict`, `fvSchemes`, `fvSolution`.
//! - `constant/transportProperties` (Newtonian, ν), `constant/turbulenceProperties`
//!   (laminar), `0/U` (m/s) and `0/p` (kinematic, m²/s²).
//! - `README`: the commands and the OpenFOAM version tested.
//!
//! Coordinates are metres (OpenFOAM reads every length as metres). The
//! background cells are twice the cell size; the pellets are refined one
//! level, to the cell size, and each treated contact is refined further
//! inside a small sphere ([`ContactRefinement`]) so that the cells there fit
//! the gap the treatment leaves. `locationInMesh` is [`location_in_mesh`].

use std::fmt::Write;

use pellet_geom::math::{Point, Real};
use pellet_geom::TriMesh;

use crate::stl;

mod flow;
pub use flow::{
    field_p, field_u, fv_schemes, fv_solution, transport_properties, turbulence_properties, Flow, Fluid, MAX_REYNOLDS,
    WATER_20C,
};

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

/// The most refinement levels a contact region gets above the background cells (a cell edge of
/// 2·cell / 2^3 = cell / 4): each level multiplies the cells in a region by 8. On the 20-sphere
/// test bed (0.5 mm cells, 74 contacts) level 3 meshed in 2.5 min to 126 000 cells; level 4
/// had 342 000 cells and was still snapping after 9 min.
pub const MAX_CONTACT_LEVEL: u32 = 3;

/// Refinement at the treated contacts: a sphere around each, refined to one level.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ContactRefinement {
    /// snappyHexMesh's level of the spheres (background cells divided by 2^level).
    pub level: u32,
    /// The spheres (centre, radius), m.
    pub spheres: Vec<(Point, Real)>,
}

/// The refinement level whose cells fit `gap` with background cells of `2 cell`: the smallest
/// level L with 2·cell / 2^L ≤ gap, at least 1 (the pellets' own level) and at most
/// [`MAX_CONTACT_LEVEL`]. Returns the level and whether the cap left its cells wider than the gap.
pub fn contact_level(cell: Real, gap: Real) -> (u32, bool) {
    // The tolerance keeps an exact power of two (cell 0.5 mm, gap 0.25 mm: level 2) from
    // rounding up a level.
    let wanted = ((2.0 * cell / gap).log2() - 1e-9).ceil().max(1.0);
    if wanted > MAX_CONTACT_LEVEL as Real {
        (MAX_CONTACT_LEVEL, true)
    } else {
        (wanted as u32, false)
    }
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
/// outlet), searched on a grid of `step`, then moved off that grid by
/// `OFF_GRID` (a few thousandths of a step): snappyHexMesh keeps the cells connected to it and stops
/// when the point lies on a face of the mesh, and the search grid's points
/// lie on the background mesh's faces when `step` is a whole number of its
/// cells. Distances to a pellet are to its mesh vertices (close for the fine
/// meshes pellets have); points inside a pellet are skipped. `None` if
/// every grid point is inside a pellet.
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
    best.map(|(_, p)| p + OFF_GRID * step)
}

/// How far [`location_in_mesh`] moves its grid point, in search steps: each
/// component 0.37–0.63 of 1/64 of a step away from the multiples of 1/64, so
/// the point lies on no face of a background mesh whose cells divide the
/// step at any of snappyHexMesh's refinement levels up to 5 (at least 0.0058
/// step away, 6 µm at the search step of two 0.5 mm cells), and moves far
/// less than the point's distance to every surface.
const OFF_GRID: pellet_geom::math::Vector = pellet_geom::math::Vector::new(1.37 / 64.0, 2.63 / 64.0, 1.81 / 64.0);

fn header(class: &str, object: &str) -> String {
    format!(
        "FoamFile\n{{\n    version     2.0;\n    format      ascii;\n    class       {class};\n    object      {object};\n}}\n\n"
    )
}

/// Iterations simpleFoam runs at most (it stops earlier when the residuals fall below the
/// controls in fvSolution).
pub const MAX_ITERATIONS: usize = 2000;

/// `system/controlDict`: simpleFoam, one time step per iteration, the fields written at the
/// end, and surfaceFieldValue function objects that log the area-averaged kinematic pressure
/// p / ρ (m²/s²) on the inlet and outlet patches and on the planes across the tube at the
/// floor (`bedBottom`) and at the bed top (`bedTop`), and the volumetric flow rate through
/// the outlet (m³/s). The meshing utilities read the same file and ignore all of it.
pub fn control_dict(flow: &Flow) -> String {
    let mut s = header("dictionary", "controlDict")
        + &format!(
            "application     simpleFoam;\nstartFrom       latestTime;\nstartTime       0;\nstopAt          endTime;\n\
           endTime         {MAX_ITERATIONS};\ndeltaT          1;\nwriteControl    timeStep;\nwriteInterval   {MAX_ITERATIONS};\n\
           purgeWrite      0;\nwriteFormat     binary;\nwritePrecision  8;\nwriteCompression off;\ntimeFormat      general;\n\
           timePrecision   6;\nrunTimeModifiable false;\n\n\
           // Pressure on the inlet, the outlet and the two ends of the packed section: kinematic\n\
           // (p / rho, m2/s2), area-averaged, logged every iteration to postProcessing/NAME/0/.\n\
           functions\n{{\n"
        );
    for (name, patch) in [("inlet", "inlet"), ("outlet", "outlet")] {
        let _ = writeln!(
            s,
            "    {name}\n    {{\n        type            surfaceFieldValue;\n        libs            (\"libfieldFunctionObjects.so\");\n\
             \x20       writeControl    timeStep;\n        writeInterval   1;\n        log             false;\n        writeFields     false;\n\
             \x20       regionType      patch;\n        name            {patch};\n        operation       areaAverage;\n        fields          (p);\n    }}"
        );
    }
    for (name, z) in [("bedBottom", flow.packed.0), ("bedTop", flow.packed.1)] {
        let _ = writeln!(
            s,
            "    {name}\n    {{\n        type            surfaceFieldValue;\n        libs            (\"libfieldFunctionObjects.so\");\n\
             \x20       writeControl    timeStep;\n        writeInterval   1;\n        log             false;\n        writeFields     false;\n\
             \x20       regionType      sampledSurface;\n        name            {name};\n        sampledSurfaceDict\n        {{\n\
             \x20           type        plane;\n            planeType   pointAndNormal;\n\
             \x20           pointAndNormalDict {{ point (0 0 {z:.9e}); normal (0 0 1); }}\n\
             \x20           interpolate false;\n        }}\n        operation       areaAverage;\n        fields          (p);\n    }}"
        );
    }
    s + "    flowRate\n    {\n        type            surfaceFieldValue;\n        libs            (\"libfieldFunctionObjects.so\");\n\
        \x20       writeControl    timeStep;\n        writeInterval   1;\n        log             false;\n        writeFields     false;\n\
        \x20       regionType      patch;\n        name            outlet;\n        operation       sum;\n        fields          (phi);\n    }\n}\n"
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

/// `system/snappyHexMeshDict`: castellate and snap, no layers; the contacts' spheres are
/// searchableSphere geometries `contact_00000`, … refined inside to `refine.level`.
pub fn snappy_hex_mesh_dict(g: &CaseGeometry, refine: &ContactRefinement) -> String {
    let p = g.location;
    let mut spheres = String::new();
    let mut regions = String::new();
    for (k, (c, r)) in refine.spheres.iter().enumerate() {
        let _ = write!(
            spheres,
            "    contact_{k:05}\n    {{\n        type searchableSphere;\n        centre ({:.9e} {:.9e} {:.9e});\n        radius {r:.9e};\n    }}\n",
            c.x, c.y, c.z
        );
        let _ = writeln!(regions, "        contact_{k:05} {{ mode inside; levels ((1e15 {})); }}", refine.level);
    }
    let regions = if regions.is_empty() {
        "    refinementRegions {}\n".to_string()
    } else {
        format!(
            "    // The treated contacts: inside each sphere, cells of 2 cell / 2^{} ({:.6e} m).\n    refinementRegions\n    {{\n{regions}    }}\n",
            refine.level,
            2.0 * g.cell / Real::from(1u32 << refine.level)
        )
    };
    let mut s = header("dictionary", "snappyHexMeshDict");
    let _ = write!(
        s,
        "castellatedMesh true;\nsnap            true;\naddLayers       false;\n\n\
geometry\n{{\n    tube.stl\n    {{\n        type triSurfaceMesh;\n        name tube;\n        regions\n        {{\n\
            wall   {{ name wall; }}\n            inlet  {{ name inlet; }}\n            outlet {{ name outlet; }}\n        }}\n    }}\n\
    pellets.stl\n    {{\n        type triSurfaceMesh;\n        name pellets;\n        regions\n        {{\n\
            pellets {{ name pellets; }}\n        }}\n    }}\n{spheres}}}\n\n\
castellatedMeshControls\n{{\n    maxLocalCells       2000000;\n    maxGlobalCells      10000000;\n\
    minRefinementCells  0;\n    maxLoadUnbalance    0.10;\n    nCellsBetweenLevels 2;\n\
    features\n    (\n        {{ file \"tube.eMesh\"; level 1; }}\n        {{ file \"pellets.eMesh\"; level 1; }}\n    );\n\
    refinementSurfaces\n    {{\n        tube\n        {{\n            level (0 0);\n            regions\n            {{\n\
                wall   {{ level (0 0); patchInfo {{ type wall; }} }}\n\
                inlet  {{ level (0 0); patchInfo {{ type patch; }} }}\n\
                outlet {{ level (0 0); patchInfo {{ type patch; }} }}\n            }}\n        }}\n\
        pellets\n        {{\n            level (1 1);\n            // One level more in the narrow gaps along the pellets' line contacts (with each\n            // other and the wall), which fewer cells would leave out of the fluid.\n            gapLevelIncrement 1;\n            patchInfo {{ type wall; }}\n        }}\n    }}\n\
    resolveFeatureAngle 30;\n{regions}\
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

/// The case's README: what is where and the commands.
pub fn readme(g: &CaseGeometry, flow: &Flow, source: &str, treatment: &str) -> String {
    let (f, u) = (flow.fluid, flow.velocity());
    format!(
        "OpenFOAM case of the packed bed {source}, written by packbed bedexport {}.\n\n\
Tested with {TESTED_VERSION}.\n\
All lengths are metres. The tube's inside runs from z = {:.6} m to z = {:.6} m (radius {:.6} m);\n\
cells are {:.6} m at the pellets and twice that elsewhere. Contact treatment: {treatment}.\n\n\
Mesh the fluid (from this directory):\n\n\x20   blockMesh\n    surfaceFeatureExtract\n    snappyHexMesh -overwrite\n\n\
then `checkMesh` should end in \"Mesh OK\". Patches: inlet (bottom), outlet (top), wall (tube), pellets.\n\
With Debian's openfoam package, set FOAM_INST_DIR=/usr/share/openfoam and\n\
WM_PROJECT_DIR=/usr/share/openfoam in the environment first.\n\n\
Flow: steady, incompressible, laminar, along +z, of {} (nu = {:e} m2/s, rho = {} kg/m3),\n\
at the particle Reynolds number Re_p = rho u_s dp / mu = u_s dp / nu = {}, with dp = {:.6e} m the\n\
pellets' volume-equivalent diameter and u_s the superficial velocity: u_s = Re_p nu / dp = {:.6e} m/s,\n\
uniform on the inlet (0/U). p = 0 on the outlet; no slip on the wall and the pellets.\n\
simpleFoam's p is the kinematic pressure p / rho in m2/s2: multiply by rho = {} kg/m3 for Pa.\n\n\
Run it (after meshing):\n\n\x20   simpleFoam > log.simpleFoam\n\n\
It stops when the initial residuals fall below the controls in system/fvSolution (p 1e-4, U 1e-5)\n\
or after {MAX_ITERATIONS} iterations, and writes U and p to the last iteration's directory.\n\n\
Pressure drop: the function objects in system/controlDict log, every iteration, the area-averaged\n\
kinematic pressure on the inlet and outlet patches and on the planes z = {:.6} m (bedBottom,\n\
the floor) and z = {:.6} m (bedTop: one pellet size below the bed's highest point, leaving\n\
out the loose top layer, as voidprof's porosity does; the whole bed if under two sizes tall), in\n\
postProcessing/NAME/0/surfaceFieldValue.dat (columns: iteration, areaAverage(p)), and the\n\
outlet's flow rate in postProcessing/flowRate/0/surfaceFieldValue.dat (sum(phi), m3/s; the\n\
inlet's is {:.6e} m3/s). The packed bed's pressure drop is\n\n\x20   dp_bed = rho * (p(bedBottom) - p(bedTop))   [Pa] over L = {:.6} m,\n\n\
from the last lines of the two files; inlet minus outlet adds the empty tube below and above\n\
the bed (developing flow, so not Hagen-Poiseuille's). Ergun's correlation for comparison:\n\
dp/L = 150 mu u_s (1 - eps)^2 / (eps^3 dp^2) + 1.75 rho u_s^2 (1 - eps) / (eps^3 dp), eps the\n\
porosity of the packed section (bedexport prints it and Ergun's value).\n",
        env!("CARGO_PKG_VERSION"),
        g.z0,
        g.z1,
        g.radius,
        g.cell,
        f.name,
        f.nu,
        f.rho,
        flow.reynolds,
        flow.dp,
        u,
        f.rho,
        flow.packed.0,
        flow.packed.1,
        u * std::f64::consts::PI * g.radius * g.radius,
        flow.packed.1 - flow.packed.0,
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
        // On no face of that background mesh (cells of 2 mm from −11 mm in x and y, from −1 mm
        // in z) or of its cells refined up to five times: snappyHexMesh stops on such a point.
        for (coordinate, low) in [(p.x, -0.011), (p.y, -0.011), (p.z, -0.001)] {
            let k = (coordinate - low) / (0.002 / 32.0);
            assert!((k - k.round()).abs() > 0.2, "{p:?}: {k} finest cells from the mesh's corner");
        }
        assert!(snappy_hex_mesh_dict(&g, &ContactRefinement::default()).contains("locationInMesh ("));
        assert!(snappy_hex_mesh_dict(&g, &ContactRefinement::default()).contains("refinementRegions {}"));
        let refine = ContactRefinement { level: 3, spheres: vec![(Point::new(0.0, 0.0, 0.01), 0.001)] };
        let dict = snappy_hex_mesh_dict(&g, &refine);
        assert!(dict.contains("contact_00000\n    {\n        type searchableSphere;"), "{dict}");
        assert!(
            dict.contains("radius 1.000000000e-3;")
                && dict.contains("contact_00000 { mode inside; levels ((1e15 3)); }")
        );
        assert!(dict.contains("cells of 2 cell / 2^3 (2.500000e-4 m)"), "{dict}");
        assert!(dict.contains("level (1 1);\n            // One level more in the narrow gaps"), "{dict}");
        assert!(dict.contains("gapLevelIncrement 1;\n            patchInfo { type wall; }"), "{dict}");
    }

    #[test]
    fn contact_levels_fit_the_gap() {
        // Background cells 2 mm (cell 1 mm): a 0.25 mm gap needs 2 / 2^3.
        assert_eq!(contact_level(1e-3, 0.25e-3), (3, false));
        assert_eq!(contact_level(1e-3, 0.3e-3), (3, false));
        assert_eq!(contact_level(1e-3, 0.5e-3), (2, false));
        // 0.1 mm would need level 5: capped, and said so.
        assert_eq!(contact_level(1e-3, 0.1e-3), (MAX_CONTACT_LEVEL, true));
        assert_eq!(contact_level(0.5e-3, 0.1e-3), (MAX_CONTACT_LEVEL, true));
        // A gap wider than the pellets' cells still gets the pellets' level.
        assert_eq!(contact_level(0.5e-3, 2e-3), (1, false));
    }

    #[test]
    fn flow_velocity_ergun_and_files() {
        let flow = Flow { fluid: WATER_20C, reynolds: 20.0, dp: 0.005, packed: (0.0, 0.03) };
        // u_s = Re ν / dp.
        assert!((flow.velocity() - 20.0 * 1.0034e-6 / 0.005).abs() < 1e-15);
        // Ergun by hand at ε = 0.4: μ = ν ρ, u = 4.0136e-3 m/s.
        let (mu, u) = (1.0034e-6 * 998.2, flow.velocity());
        let by_hand = 150.0 * mu * u * 0.36 / (0.064 * 25e-6) + 1.75 * 998.2 * u * u * 0.6 / (0.064 * 0.005);
        assert!((flow.ergun(0.4) / by_hand - 1.0).abs() < 1e-12);
        let u_file = field_u(&flow);
        assert!(u_file.contains(&format!("value           uniform (0 0 {:.9e});", flow.velocity())), "{u_file}");
        for patch in ["inlet", "outlet", "wall", "pellets"] {
            assert!(u_file.contains(&format!("    {patch}\n")) && field_p().contains(&format!("    {patch}\n")));
        }
        assert!(transport_properties(&flow).contains("nu              [0 2 -1 0 0 0 0] 1.0034e-6;"));
        let control = control_dict(&flow);
        assert!(control.contains("application     simpleFoam;") && control.contains("point (0 0 3.000000000e-2)"));
        assert_eq!(control.matches("type            surfaceFieldValue;").count(), 5);
    }
}
