//! Contacts between pellets and the orientation of their axes.

use pellet_geom::math::{Point, Real};
use pellet_geom::{Bed, ClosedForm, ShapeSpec};

/// Pellet–pellet contacts of the pellets whose centroid lies in a window.
#[derive(Clone, Debug, PartialEq)]
pub struct Coordination {
    /// Mean number of neighbours in contact.
    pub mean: Real,
    /// Pellets counted (centroid in the window).
    pub pellets: usize,
    /// `histogram[k]`: pellets with k contacts.
    pub histogram: Vec<usize>,
    /// Surface gap below which two pellets are in contact (m).
    pub gap: Real,
}

/// Contacts per pellet for pellets with their centroid in `window` (m):
/// two pellets touch when the gap between their surfaces is below `gap`
/// (m). Spheres are exact; cylinders and rings use the exact signed
/// distance of one pellet at the mesh vertices of the other, both ways, so
/// an edge-to-edge contact between vertices can be missed by up to the
/// vertex spacing. `None` for shapes without a closed form.
pub fn coordination(bed: &Bed, window: (Real, Real), gap: Real) -> Option<Coordination> {
    let n = bed.pellets.len();
    let mut contacts = vec![0usize; n];
    for_pairs_within(bed, gap, |i, j| {
        contacts[i] += 1;
        contacts[j] += 1;
    })?;
    let counted: Vec<usize> =
        (0..n).filter(|&i| (window.0..window.1).contains(&bed.pellets[i].position[2])).map(|i| contacts[i]).collect();
    let max = counted.iter().copied().max().unwrap_or(0);
    let mut histogram = vec![0usize; max + 1];
    counted.iter().for_each(|&k| histogram[k] += 1);
    let mean = if counted.is_empty() { 0.0 } else { counted.iter().sum::<usize>() as Real / counted.len() as Real };
    Some(Coordination { mean, pellets: counted.len(), histogram, gap })
}

/// Pairs of pellets that overlap by more than `depth` (m), measured as in [`coordination`]
/// (a surface gap below −`depth`), and the pellets in at least one such pair. `None` for
/// shapes without a closed form.
pub fn overlapping_pairs(bed: &Bed, depth: Real) -> Option<(usize, usize)> {
    let mut pairs = 0;
    let mut involved = vec![false; bed.pellets.len()];
    for_pairs_within(bed, -depth, |i, j| {
        pairs += 1;
        involved[i] = true;
        involved[j] = true;
    })?;
    Some((pairs, involved.iter().filter(|&&b| b).count()))
}

/// Calls `f(i, j)` for every pair whose surface gap is below `gap` (m, negative: an
/// overlap); `None` for shapes without a closed form.
fn for_pairs_within(bed: &Bed, gap: Real, mut f: impl FnMut(usize, usize)) -> Option<()> {
    if bed.pellet_types.iter().any(|p| p.closed_form.is_none()) {
        return None;
    }
    let n = bed.pellets.len();
    let reach: Vec<Real> = bed
        .pellets
        .iter()
        .map(|p| bed.pellet_types[p.type_index as usize].closed_form.map_or(0.0, |c| c.bounding_radius()))
        .collect();
    // Sort along z so that only pellets within reach in z are compared.
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| bed.pellets[a].position[2].total_cmp(&bed.pellets[b].position[2]));
    let max_reach = reach.iter().copied().fold(0.0, Real::max);
    for (oi, &i) in order.iter().enumerate() {
        for &j in &order[oi + 1..] {
            let (pi, pj) = (&bed.pellets[i], &bed.pellets[j]);
            if pj.position[2] - pi.position[2] > 2.0 * max_reach + gap.max(0.0) {
                break;
            }
            if (pi.centre() - pj.centre()).norm() > reach[i] + reach[j] + gap.max(0.0) {
                continue;
            }
            if touching(bed, i, j, gap) {
                f(i, j);
            }
        }
    }
    Some(())
}

fn touching(bed: &Bed, i: usize, j: usize, gap: Real) -> bool {
    let (pi, pj) = (&bed.pellets[i], &bed.pellets[j]);
    let (ti, tj) = (&bed.pellet_types[pi.type_index as usize], &bed.pellet_types[pj.type_index as usize]);
    let (Some(ci), Some(cj)) = (ti.closed_form, tj.closed_form) else { return false };
    if let (ClosedForm::Sphere { radius: a }, ClosedForm::Sphere { radius: b }) = (ci, cj) {
        return (pi.centre() - pj.centre()).norm() - a - b < gap;
    }
    // The other's centroid too: two coincident pellets have no vertex inside each other.
    let near = |shape: &ClosedForm, pose: &pellet_geom::PlacedPellet, other: &pellet_geom::Pellet, other_pose| {
        other.mesh.vertices.iter().chain([&Point::origin()]).any(|v: &Point| {
            let world = pellet_geom::PlacedPellet::to_world(other_pose, v);
            shape.signed_distance(&pose.to_body(&world)) < gap
        })
    };
    near(&ci, pi, tj, pj) || near(&cj, pj, ti, pi)
}

/// Distribution of the angle between pellet axes and the tube axis.
#[derive(Clone, Debug, PartialEq)]
pub struct OrientationHistogram {
    /// Bin edges in degrees, 0 (axis vertical) to 90 (axis horizontal).
    pub edges_deg: Vec<Real>,
    /// Pellets in each bin.
    pub counts: Vec<usize>,
    /// Pellets counted (centroid in the window).
    pub pellets: usize,
    /// ⟨cos²⟩ of the angle: 1/3 for isotropic orientations.
    pub mean_cos2: Real,
    /// Order parameter (3⟨cos²⟩ − 1)/2: 1 all vertical, 0 isotropic, −½ all horizontal.
    pub order_parameter: Real,
}

/// Orientation of the symmetry axes of pellets with their centroid in
/// `window` (m), in bins of `bin_deg` degrees; `None` for spheres and user
/// meshes, which have no axis.
pub fn orientation(bed: &Bed, window: (Real, Real), bin_deg: Real) -> Option<OrientationHistogram> {
    let axial = |s: &ShapeSpec| !matches!(s, ShapeSpec::Sphere { .. } | ShapeSpec::UserMesh { .. });
    if !(bed.pellet_types.iter().all(|p| axial(&p.shape)) && bin_deg > 0.0 && bin_deg <= 90.0) {
        return None;
    }
    let bins = (90.0 / bin_deg).ceil() as usize;
    let mut edges_deg: Vec<Real> = (0..bins).map(|k| k as Real * bin_deg).collect();
    edges_deg.push(90.0);
    let mut counts = vec![0usize; bins];
    let (mut n, mut cos2) = (0usize, 0.0);
    for p in bed.pellets.iter().filter(|p| (window.0..window.1).contains(&p.position[2])) {
        let c = p.axis().z.abs().min(1.0);
        let angle = c.acos().to_degrees();
        counts[((angle / bin_deg) as usize).min(bins - 1)] += 1;
        cos2 += c * c;
        n += 1;
    }
    let mean_cos2 = if n > 0 { cos2 / n as Real } else { Real::NAN };
    Some(OrientationHistogram {
        edges_deg,
        counts,
        pellets: n,
        mean_cos2,
        order_parameter: 0.5 * (3.0 * mean_cos2 - 1.0),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use pellet_geom::{Pellet, PlacedPellet, Resolution, Tube};

    fn bed(positions_mm: &[[Real; 3]], orientation: [Real; 4]) -> Bed {
        let cyl =
            Pellet::build(ShapeSpec::Cylinder { diameter_mm: 10.0, height_mm: 10.0 }, Resolution::default()).unwrap();
        Bed {
            tube: Tube { diameter: 0.05, lid_height: None },
            pellet_types: vec![cyl],
            pellets: positions_mm
                .iter()
                .map(|p| PlacedPellet { type_index: 0, position: p.map(|c| c * 1e-3), orientation })
                .collect(),
        }
    }

    #[test]
    fn overlaps_deeper_than_the_depth_are_counted_and_contacts_are_not() {
        let upright = [1.0, 0.0, 0.0, 0.0];
        // Touching face to face, coincident (no vertex inside the other), 1 mm deep.
        let b =
            bed(&[[0.0, 0.0, 5.0], [0.0, 0.0, 15.0], [20.0, 0.0, 5.0], [20.0, 0.0, 5.0], [0.0, 0.0, 24.0]], upright);
        assert_eq!(overlapping_pairs(&b, 1e-4), Some((2, 4)));
        assert_eq!(overlapping_pairs(&b, 2e-3), Some((1, 2)));
    }

    #[test]
    fn stacked_cylinders_touch_and_separated_ones_do_not() {
        let upright = [1.0, 0.0, 0.0, 0.0];
        // Face to face (gap 0), then 1 mm apart.
        let stack = bed(&[[0.0, 0.0, 5.0], [0.0, 0.0, 15.0], [0.0, 0.0, 26.0]], upright);
        let c = coordination(&stack, (0.0, 0.03), 1e-4).unwrap();
        assert_eq!(c.histogram, vec![1, 2], "one pellet with no contact, two with one: {c:?}");
        assert!((c.mean - 2.0 / 3.0).abs() < 1e-12);
        // Side by side along x, 0.05 mm apart: within a 0.1 mm gap.
        let row = bed(&[[0.0, 0.0, 5.0], [10.05, 0.0, 5.0]], upright);
        assert_eq!(coordination(&row, (0.0, 0.01), 1e-4).unwrap().mean, 1.0);
        assert_eq!(coordination(&row, (0.0, 0.01), 1e-5).unwrap().mean, 0.0);
    }

    #[test]
    fn lying_cylinders_have_order_parameter_minus_one_half() {
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let lying = bed(&[[0.0, 0.0, 5.0], [12.0, 0.0, 5.0]], [s, 0.0, s, 0.0]);
        let o = orientation(&lying, (0.0, 0.01), 10.0).unwrap();
        assert_eq!(o.counts, vec![0, 0, 0, 0, 0, 0, 0, 0, 2]);
        assert!((o.order_parameter + 0.5).abs() < 1e-12);
        let upright = bed(&[[0.0, 0.0, 5.0]], [1.0, 0.0, 0.0, 0.0]);
        assert_eq!(orientation(&upright, (0.0, 0.01), 10.0).unwrap().counts[0], 1);
    }
}
