//! Candidate contact points (hits) grouped into patches of one normal, and each patch reduced
//! to ≤ 4 points (`docs/engine.md`, "Contact generation"): shared by the pellet–pellet and
//! pellet–wall narrow phases.

use super::contact::NormalOwner;
use super::samples::cone_alignment;
use crate::math::{Real, Vec3};

/// Normals closer than this (cosine, ~1.1°) share a patch and its one normal. Hits
/// are grouped by normal only, not by proximity as well.
/// With 0.98, hits up to 11.5° apart (along a curved surface, or at separate places) made one
/// patch reduced to ≤ 4 points, and the touching points the reduction dropped sank while the
/// pellets slid; each was the deepest, so kept, in the next substep, and position projection
/// lifted it. The paper's narrowest cylinder bed (D = 33.65 mm) crept at ~4 mm/s for ever.
/// Measured on that bed restarted at rest (`tests/bed_rest.rs` in pellet_pack): 0.98 and 0.995
/// creep, 0.999 rattles (fastest pellet ~2 mm/s), 0.9998 comes to rest within 0.05 s; 0.98 with
/// each kept point on its own normal creeps as before (so it is the dropped points, not the
/// shared normal). Flat faces give normals equal to round-off: their patches are unchanged.
const PATCH_COS: Real = 0.9998;

/// An edge hit joins a patch if its normal is within ~2.6° of both bodies' normal cones.
pub(crate) const WEDGE_COS: Real = 0.999;

/// Points within this many bounding radii of a patch's smallest gap count as touching when the
/// patch is reduced (2e-3 R_b = δ_c for the default contact distance 1e-3 d, d = 2 R_b).
pub(crate) const NEAR_BAND: Real = 2e-3;
/// A touching point is preferred in the reduction if it adds at least this fraction of the
/// patch's extent (distance, or triangle height).
const SPREAD: Real = 0.05;
/// A point the pair kept in the last step stays in the reduction while it scores at least this
/// fraction of the best point's distance or area...
const KEEP_SCORE: Real = 0.9;
/// ...and, as the patch's first point, while it lies within this many bounding radii of the
/// patch's smallest gap (1e-5 R_b ≈ 0.07 µm for the paper's pellets: the deepest point is never
/// left out by more than that).
const KEEP_DEPTH: Real = 1e-5;

/// Points of one patch closer than this many bounding radii (14 µm for the paper's pellets)
/// are one contact under the velocity-level stepper's rules. Two rows at one place are one row
/// twice: Gauss–Seidel moves load between them a sliver per sweep and never converges. Two
/// standing cylinders side by side with level tops gave the side patch A's top rim on B's side
/// and B's top rim on A's side at one place, one closed (target 0) and one open by 7.5e-10 m
/// (target −6e-7 m/s); every step of the bed at rest ended at the sweep cap with a residual of
/// 6e-7 m/s.
pub(crate) const MERGE: Real = 2e-3;

/// One candidate contact point before patching.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Hit {
    /// A's surface point, world.
    pub pa: Vec3,
    /// B's surface point, world.
    pub pb: Vec3,
    /// Unit normal B → A.
    pub normal: Vec3,
    /// Signed gap, m.
    pub gap: Real,
    /// Feature id (persistent key).
    pub feature: u32,
    /// Body whose SDF gave the normal.
    pub owner: NormalOwner,
    /// For an edge contact (the closest feature of the SDF's body is an edge): the cones of
    /// normals (B → A) that the two bodies' surfaces allow there, (SDF body's, sample body's).
    pub wedge: Option<[(Vec3, Vec3); 2]>,
}

/// Groups hits by normal (cos > `PATCH_COS`), deepest first; each patch's first hit is its deepest
/// face hit. Face hits are grouped first; an edge hit then joins a patch whose normal both
/// bodies' normal cones allow at that point (two nearly coinciding rims: the cap patch), with
/// its gap measured along the patch normal, else it starts its own patch.
/// Sorts `hits` by (edge, gap rounded to 1e-12 m, feature) so the result is deterministic and
/// does not flip on round-off: two equal stacked rims give A's and B's samples at the same
/// place with gaps differing by ~1e-16 m, and an exact-gap order swapped the patch's point (a
/// new key, no warm start) from one substep to the next; in recommended mode that kicked a
/// 5-stack to |v| 1.2e-4 m/s (1.3e-6 with the rounding).
///
/// The keys are computed once and sorted with the hits' indices as the last key (the order of
/// a stable sort, bit for bit), then the hits are moved once: sorting the ~200-byte hits with
/// the key in the comparison was 4 % of a cylinder bed's time (the rounding and the copies).
pub(crate) fn patches(hits: &mut Vec<Hit>) -> Vec<Vec<usize>> {
    let mut keys: Vec<(bool, i64, u32, u32)> = hits
        .iter()
        .enumerate()
        .map(|(i, h)| (h.wedge.is_some(), (h.gap / 1e-12).round() as i64, h.feature, i as u32))
        .collect();
    keys.sort_unstable();
    if keys.iter().enumerate().any(|(k, key)| key.3 as usize != k) {
        *hits = keys.iter().map(|key| hits[key.3 as usize]).collect();
    }
    // Each hit's patch first, the patches' member lists after (each allocated once, members in
    // increasing index as before): growing a list per patch hit by hit was 2.6 % of a
    // cylinder bed.
    let mut heads: Vec<usize> = Vec::with_capacity(4);
    let mut patch_of: Vec<usize> = Vec::with_capacity(hits.len());
    for i in 0..hits.len() {
        let h = hits[i];
        let fits = |n: &Vec3| match &h.wedge {
            Some([c1, c2]) => cone_alignment(n, c1) > WEDGE_COS && cone_alignment(n, c2) > WEDGE_COS,
            None => false,
        };
        let found = heads.iter().position(|&head| {
            let n = hits[head].normal;
            n.dot(&h.normal) > PATCH_COS || fits(&n)
        });
        match found {
            Some(k) => {
                let n = hits[heads[k]].normal;
                if h.wedge.is_some() {
                    hits[i].gap = n.dot(&(h.pa - h.pb));
                }
                patch_of.push(k);
            }
            None => {
                patch_of.push(heads.len());
                heads.push(i);
            }
        }
    }
    let mut sizes = vec![0usize; heads.len()];
    patch_of.iter().for_each(|&k| sizes[k] += 1);
    let mut out: Vec<Vec<usize>> = sizes.iter().map(|&n| Vec::with_capacity(n)).collect();
    for (i, &k) in patch_of.iter().enumerate() {
        out[k].push(i);
    }
    out
}

/// Reduces a patch to ≤ 4 points: the deepest, the farthest from it, the one
/// making the largest triangle, and the one adding the most area outside that triangle.
///
/// Each pick is made first among the points within `band` of the patch's smallest gap (the ones
/// touching now), and among all points only when those add less than `SPREAD` of the patch's
/// extent. Why: the patch holds every hit up to the look-ahead gap δ_c + v_max δt (~1.6e-4 m in
/// a pour), and picking by area alone kept rim samples 1.1–1.4e-4 m away while dropping the
/// refined rim point 3.5e-7 m away that was the patch's second real contact; the pellet then
/// rotated about the one kept contact and that rim point sank 8.3e-5 m within one substep
/// (the pour of `tests/t23_pour_shapes.rs`). A flat patch has all its points in the band:
/// unchanged.
///
/// `kept` (sorted features) are the points the pair had in the last step: each pick takes one
/// of them when it does nearly as well as the best (`KEEP_SCORE`, `KEEP_DEPTH`).
///
/// With `merge` > 0, of the points picked closer together than `merge` only one stays
/// (`MERGE`).
///
/// The third and fourth points must add at least `SPREAD` of the extent as a triangle's height,
/// from whichever points they come: a thin lens of two caps crossing each other kept a point
/// 0.17 mm beside another of a 10 mm patch, on the same normal; their rows were nearly one, and
/// with gaps differing by nanometres the solve moved their load from one to the other by
/// 3e-9 N·s a sweep, never converging (`docs/engine.md`, "Contact generation").
pub(crate) fn reduce(hits: &[Hit], patch: &[usize], n: &Vec3, band: Real, kept: &[u32], merge: Real) -> Reduced {
    let picked = reduce_spread(hits, patch, n, band, kept);
    if merge > 0.0 && picked.len > 1 {
        merged(hits, picked, kept, merge)
    } else {
        picked
    }
}

/// `picked` without the points that lie within `merge` of an earlier one (deepest first): one
/// place, one row. Of two such points the earlier stays, unless only the later was kept from
/// the last step.
fn merged(hits: &[Hit], picked: Reduced, kept: &[u32], merge: Real) -> Reduced {
    let was_kept = |i: usize| kept.binary_search(&hits[i].feature).is_ok();
    let mut out = Reduced { kept: [0; 4], len: 0 };
    for i in picked {
        let close = out.kept[..out.len].iter().position(|&j| (hits[i].pa - hits[j].pa).norm() < merge);
        match close {
            None => {
                out.kept[out.len] = i;
                out.len += 1;
            }
            Some(k) if was_kept(i) && !was_kept(out.kept[k]) => out.kept[k] = i,
            Some(_) => {}
        }
    }
    out
}

fn reduce_spread(hits: &[Hit], patch: &[usize], n: &Vec3, band: Real, kept: &[u32]) -> Reduced {
    if patch.len() <= 4 {
        return Reduced::of(patch);
    }
    let p = |k: usize| hits[patch[k]].pa;
    let gap = |k: usize| hits[patch[k]].gap;
    let g_min = patch.iter().map(|&k| hits[k].gap).fold(Real::INFINITY, Real::min);
    let near = |k: usize| hits[patch[k]].gap <= g_min + band;
    let was_kept = |k: usize| kept.binary_search(&hits[patch[k]].feature).is_ok();
    let best = |f: &dyn Fn(usize) -> Real, pick: &dyn Fn(usize) -> bool| {
        let top = (0..patch.len()).filter(|&k| pick(k)).fold((0, Real::NEG_INFINITY), |best, k| {
            if f(k) > best.1 {
                (k, f(k))
            } else {
                best
            }
        });
        // A point kept from the last step that does nearly as well stays (its key and impulse
        // with it): a bed at rest rocks by round-off, and which of two equal points scores
        // higher then flips from step to step.
        if kept.is_empty() || top.1 <= 0.0 {
            return top;
        }
        (0..patch.len())
            .filter(|&k| pick(k) && was_kept(k) && f(k) >= KEEP_SCORE * top.1)
            .fold(None, |b: Option<(usize, Real)>, k| match b {
                Some(b) if b.1 >= f(k) => Some(b),
                _ => Some((k, f(k))),
            })
            .unwrap_or(top)
    };
    // The best near point if it adds at least `floor`, else the best of all points.
    let argmax = |f: &dyn Fn(usize) -> Real, floor: Real| {
        let b = best(f, &near);
        if b.1 > floor {
            b
        } else {
            best(f, &|_| true)
        }
    };
    // The deepest point, or a kept point within `KEEP_DEPTH` bounding radii of its depth (the
    // band is `NEAR_BAND` of the smaller bounding radius).
    let depth_margin = KEEP_DEPTH * (band / NEAR_BAND);
    let i0 = (0..patch.len())
        .filter(|&k| was_kept(k) && gap(k) <= g_min + depth_margin)
        .min_by(|&i, &j| gap(i).total_cmp(&gap(j)).then(i.cmp(&j)))
        .unwrap_or(0);
    let extent = best(&|k| (p(k) - p(i0)).norm(), &|_| true).1;
    let (i1, d1) = argmax(&|k| (p(k) - p(i0)).norm_squared(), (SPREAD * extent).powi(2));
    if d1 <= 0.0 {
        return Reduced::of(&[patch[i0]]);
    }
    let area = |u: usize, v: usize, q: usize| n.dot(&(p(v) - p(u)).cross(&(p(q) - p(u))));
    let floor = SPREAD * extent * d1.sqrt();
    let (i2, a2) = argmax(&|k| area(i0, i1, k).abs(), floor);
    if a2 <= floor {
        return Reduced::of(&[patch[i0], patch[i1]]);
    }
    let sigma = area(i0, i1, i2).signum();
    // Area outside each edge of the triangle (positive on the side away from the triangle).
    let outside = |k: usize| {
        [(i0, i1), (i1, i2), (i2, i0)].iter().map(|&(u, v)| -sigma * area(u, v, k)).fold(Real::NEG_INFINITY, Real::max)
    };
    let (i3, a3) = argmax(&outside, floor);
    if a3 > floor {
        Reduced::of(&[patch[i0], patch[i1], patch[i2], patch[i3]])
    } else {
        Reduced::of(&[patch[i0], patch[i1], patch[i2]])
    }
}

/// The ≤ 4 hit indices [`reduce`] keeps, in its order, without a heap allocation: a vector per
/// patch (and its growth from 3 to 4) was most of the allocations under `sampled_pair`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Reduced {
    kept: [usize; 4],
    len: usize,
}

impl Reduced {
    fn of(kept: &[usize]) -> Self {
        let mut out = Self { kept: [0; 4], len: kept.len() };
        out.kept[..kept.len()].copy_from_slice(kept);
        out
    }
}

impl IntoIterator for Reduced {
    type Item = usize;
    type IntoIter = std::iter::Take<std::array::IntoIter<usize, 4>>;
    fn into_iter(self) -> Self::IntoIter {
        self.kept.into_iter().take(self.len)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hit(x: Real, y: Real, gap: Real, feature: u32) -> Hit {
        let pa = Vec3::new(x, y, 0.0);
        Hit { pa, pb: pa - Vec3::z() * gap, normal: Vec3::z(), gap, feature, owner: NormalOwner::B, wedge: None }
    }

    fn reduced(hits: &[Hit], kept: &[u32], merge: Real) -> Vec<u32> {
        let patch: Vec<usize> = (0..hits.len()).collect();
        reduce(hits, &patch, &Vec3::z(), 1e-5, kept, merge).into_iter().map(|k| hits[k].feature).collect()
    }

    #[test]
    fn points_at_one_place_merge_into_the_deepest() {
        // Two rims meeting at one place (1 µm apart) and a third point 8 mm away.
        let hits = [hit(0.0, 0.0, -3e-7, 1), hit(1e-6, 0.0, 7e-10, 2), hit(8e-3, 0.0, -1e-7, 3)];
        assert_eq!(reduced(&hits, &[], 0.0), vec![1, 2, 3], "no merging asked: all three");
        assert_eq!(reduced(&hits, &[], 1.4e-5), vec![1, 3]);
    }

    #[test]
    fn a_merged_place_keeps_the_point_kept_from_the_last_step() {
        let hits = [hit(0.0, 0.0, -3e-7, 1), hit(1e-6, 0.0, 7e-10, 2), hit(8e-3, 0.0, -1e-7, 3)];
        assert_eq!(reduced(&hits, &[2, 3], 1.4e-5), vec![2, 3]);
    }

    #[test]
    fn a_large_patch_reduced_to_four_spread_points_loses_none_to_merging() {
        let mut hits = Vec::new();
        for (k, (x, y)) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0), (0.5, 0.5), (0.5, 0.0)].iter().enumerate() {
            hits.push(hit(x * 1e-2, y * 1e-2, -1e-7 * (k as Real + 1.0), k as u32));
        }
        let plain = reduced(&hits, &[], 0.0);
        assert_eq!(plain.len(), 4);
        assert_eq!(reduced(&hits, &[], 1.4e-5), plain);
    }
}
