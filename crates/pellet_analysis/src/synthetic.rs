//! Beds built in code, with known geometry, for tests and benchmarks:
//! sphere lattices and random non-overlapping placements. They are not
//! physical packings (use `pack` and `settle-check` for those).

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use pellet_geom::math::Real;
use pellet_geom::{Bed, Pellet, PlacedPellet, Tube};

const IDENTITY: [Real; 4] = [1.0, 0.0, 0.0, 0.0];

fn bed(pellet: &Pellet, tube_diameter: Real, positions: Vec<[Real; 3]>) -> Bed {
    Bed {
        tube: Tube { diameter: tube_diameter, lid_height: None },
        pellet_types: vec![pellet.clone()],
        pellets: positions
            .into_iter()
            .map(|position| PlacedPellet { type_index: 0, position, orientation: IDENTITY })
            .collect(),
    }
}

/// Centres of a square lattice of columns (spacing `spacing`, m) whose
/// pellets of footprint radius `reach` fit inside a tube of `tube_diameter`.
pub fn square_columns(tube_diameter: Real, spacing: Real, reach: Real) -> Vec<[Real; 2]> {
    let limit = 0.5 * tube_diameter - reach;
    let n = (limit / spacing).floor() as i64;
    let mut out = Vec::new();
    for i in -n..=n {
        for j in -n..=n {
            let (x, y) = (i as Real * spacing, j as Real * spacing);
            if x.hypot(y) <= limit + 1e-12 {
                out.push([x, y]);
            }
        }
    }
    out
}

/// A simple-cubic stack of `pellet` (upright): columns on a square lattice
/// of `spacing` inside the tube, `layers` layers from z = `spacing`/2.
pub fn simple_cubic(pellet: &Pellet, tube_diameter: Real, spacing: Real, layers: usize) -> Bed {
    let reach = pellet.closed_form.map_or(pellet.mesh.max_radius(), |c| c.bounding_radius());
    let mut positions = Vec::new();
    for k in 0..layers {
        for [x, y] in square_columns(tube_diameter, spacing, reach) {
            positions.push([x, y, (k as Real + 0.5) * spacing]);
        }
    }
    bed(pellet, tube_diameter, positions)
}

/// The first `count` spheres (lowest first) of a close-packed stack of
/// triangular layers in ABC order, spheres `spacing` (m) apart (≥ their
/// diameter), clipped to the tube: a dense, lattice-like bed.
pub fn close_packed_spheres(pellet: &Pellet, tube_diameter: Real, spacing: Real, count: usize) -> Bed {
    let radius = pellet.closed_form.map_or(pellet.mesh.max_radius(), |c| c.bounding_radius());
    let limit = 0.5 * tube_diameter - radius;
    let layer_height = spacing * (2.0 / 3.0 as Real).sqrt();
    let row = spacing * 0.75f64.sqrt();
    let n = (limit / row).ceil() as i64 + 2;
    let mut positions = Vec::new();
    let mut layer = 0usize;
    while positions.len() < count {
        // Each layer shifts by one third of the triangle, cycling A, B, C.
        let shift = [(0.0, 0.0), (0.5 * spacing, row / 3.0), (spacing, 2.0 * row / 3.0)][layer % 3];
        let z = radius + layer as Real * layer_height;
        let mut in_layer = Vec::new();
        for j in -n..=n {
            for i in -n..=n {
                let x = i as Real * spacing + 0.5 * spacing * (j.rem_euclid(2)) as Real + shift.0;
                let y = j as Real * row + shift.1;
                if x.hypot(y) <= limit {
                    in_layer.push([x, y, z]);
                }
            }
        }
        in_layer.sort_by(|a, b| a[0].hypot(a[1]).total_cmp(&b[0].hypot(b[1])));
        positions.extend(in_layer.into_iter().take(count - positions.len()));
        layer += 1;
    }
    bed(pellet, tube_diameter, positions)
}

/// Up to `count` copies of `pellet` placed at random (random sequential
/// addition, seeded) in the tube between z = 0 and `height` (m), with random
/// orientations; no two bounding spheres overlap and none crosses the wall
/// or the floor. Loose (porosity about 0.6–0.7), but the geometry is exact.
pub fn random_placement(pellet: &Pellet, tube_diameter: Real, height: Real, count: usize, seed: u64) -> Bed {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let reach = pellet.closed_form.map_or(pellet.mesh.max_radius(), |c| c.bounding_radius());
    let limit = 0.5 * tube_diameter - reach;
    let mut placed: Vec<PlacedPellet> = Vec::new();
    let mut attempts = 0;
    while placed.len() < count && attempts < 200 * count.max(1) && limit > 0.0 && height > 2.0 * reach {
        attempts += 1;
        let (x, y) = (rng.random_range(-limit..limit), rng.random_range(-limit..limit));
        let z = rng.random_range(reach..height - reach);
        if x.hypot(y) > limit {
            continue;
        }
        let clear = placed.iter().all(|p| {
            let d = [p.position[0] - x, p.position[1] - y, p.position[2] - z];
            (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() >= 2.0 * reach
        });
        if !clear {
            continue;
        }
        // A uniformly random rotation (Shoemake's method).
        let (u1, u2, u3): (Real, Real, Real) = (rng.random(), rng.random(), rng.random());
        let tau = 2.0 * std::f64::consts::PI;
        let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
        let q = [b * (tau * u3).cos(), a * (tau * u2).sin(), a * (tau * u2).cos(), b * (tau * u3).sin()];
        let norm = q.iter().map(|c| c * c).sum::<Real>().sqrt();
        placed.push(PlacedPellet { type_index: 0, position: [x, y, z], orientation: q.map(|c| c / norm) });
    }
    Bed {
        tube: Tube { diameter: tube_diameter, lid_height: None },
        pellet_types: vec![pellet.clone()],
        pellets: placed,
    }
}
