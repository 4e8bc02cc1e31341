//! Broad phase: a uniform grid over swept bounding spheres, built from a sorted list of
//! (cell, body) entries so that the output order is deterministic and no all-pairs loop runs.

use crate::math::{Real, Vec3};

/// Bodies whose swept sphere covers more cells than this are tested against everyone instead.
const MAX_CELLS_PER_BODY: i64 = 64;

/// Reusable scratch for candidate-pair queries.
#[derive(Debug, Default, Clone)]
pub struct BroadPhase {
    entries: Vec<(u64, u32)>,
    /// Counting-sort scratch: entries per dense cell index, then bucket starts.
    counts: Vec<u32>,
    dense: Vec<u32>,
    sorted: Vec<(u64, u32)>,
    /// Each body's lowest cell (unused for oversized bodies).
    lo_cell: Vec<[i64; 3]>,
    oversized: Vec<u32>,
    pairs: Vec<(u32, u32)>,
    /// Scratch of `sort_pairs`.
    pair_starts: Vec<u32>,
    pairs_sorted: Vec<(u32, u32)>,
    /// Scratch of the median radius.
    radii_scratch: Vec<Real>,
}

/// Bits of a cell key per axis.
const AXIS_BITS: u32 = 21;

fn cell_key(ix: i64, iy: i64, iz: i64) -> u64 {
    // AXIS_BITS per axis, offset so that negative cells map to distinct keys.
    let m = (1i64 << AXIS_BITS) - 1;
    let off = 1i64 << (AXIS_BITS - 1);
    (((ix + off) & m) as u64) << (2 * AXIS_BITS) | (((iy + off) & m) as u64) << AXIS_BITS | ((iz + off) & m) as u64
}

/// The offset cell coordinates (x, y, z) of a key, in the key's own order.
fn key_cell(k: u64) -> [i64; 3] {
    let m = (1u64 << AXIS_BITS) - 1;
    [(k >> (2 * AXIS_BITS)) as i64, ((k >> AXIS_BITS) & m) as i64, (k & m) as i64]
}

impl BroadPhase {
    /// Sorts `entries` by (cell, body), as `sort_unstable` would. The entries were pushed in
    /// body order, so a stable counting sort over the cells' dense index (x, y, z within the
    /// occupied box, in the key's own x-major order) gives the same order in linear time; a
    /// comparison sort of the ~8 entries per body was half of the broad phase. A box too big
    /// to count over (bodies spread far apart) falls back to the comparison sort.
    fn sort_entries(&mut self) {
        let (mut lo, mut hi) = ([i64::MAX; 3], [i64::MIN; 3]);
        for &(k, _) in &self.entries {
            let c = key_cell(k);
            for a in 0..3 {
                lo[a] = lo[a].min(c[a]);
                hi[a] = hi[a].max(c[a]);
            }
        }
        let extent = [hi[0] - lo[0] + 1, hi[1] - lo[1] + 1, hi[2] - lo[2] + 1];
        let cells = extent.iter().map(|&e| e as Real).product::<Real>();
        if self.entries.is_empty() || cells > (8 * self.entries.len()).max(1 << 16) as Real {
            self.entries.sort_unstable();
            return;
        }
        let cells = cells as usize;
        self.counts.clear();
        self.counts.resize(cells + 1, 0);
        self.dense.clear();
        for &(k, _) in &self.entries {
            let c = key_cell(k);
            let d = ((c[0] - lo[0]) * extent[1] + (c[1] - lo[1])) * extent[2] + (c[2] - lo[2]);
            self.dense.push(d as u32);
            self.counts[d as usize + 1] += 1;
        }
        for d in 0..cells {
            self.counts[d + 1] += self.counts[d];
        }
        self.sorted.clear();
        self.sorted.resize(self.entries.len(), (0, 0));
        for (&e, &d) in self.entries.iter().zip(&self.dense) {
            let slot = &mut self.counts[d as usize];
            self.sorted[*slot as usize] = e;
            *slot += 1;
        }
        std::mem::swap(&mut self.entries, &mut self.sorted);
    }

    /// Sorts `pairs` by (i, j), as `sort_unstable` would: a counting sort by i (n buckets),
    /// then each body's few partners by j. The comparison sort of all pairs was ~5 % of a
    /// 690-sphere bed (perf).
    fn sort_pairs(&mut self, n: usize) {
        self.pair_starts.clear();
        self.pair_starts.resize(n + 1, 0);
        for &(i, _) in &self.pairs {
            self.pair_starts[i as usize + 1] += 1;
        }
        for k in 0..n {
            self.pair_starts[k + 1] += self.pair_starts[k];
        }
        self.pairs_sorted.clear();
        self.pairs_sorted.resize(self.pairs.len(), (0, 0));
        // Scatter with a running cursor per bucket (the bucket's start, advanced).
        for &(i, j) in &self.pairs {
            let slot = &mut self.pair_starts[i as usize];
            self.pairs_sorted[*slot as usize] = (i, j);
            *slot += 1;
        }
        // Each cursor now sits at its bucket's end, the next bucket's start.
        let mut start = 0;
        for k in 0..n {
            let end = self.pair_starts[k] as usize;
            self.pairs_sorted[start..end].sort_unstable();
            start = end;
        }
        std::mem::swap(&mut self.pairs, &mut self.pairs_sorted);
    }

    /// Pairs (i < j) whose spheres (centre `centres[i]`, radius `radii[i]`) overlap, sorted.
    pub fn overlapping_pairs(&mut self, centres: &[Vec3], radii: &[Real]) -> &[(u32, u32)] {
        self.entries.clear();
        self.lo_cell.clear();
        self.lo_cell.resize(centres.len(), [0; 3]);
        self.oversized.clear();
        self.pairs.clear();
        let n = centres.len();
        if n < 2 {
            return &self.pairs;
        }
        // Cell size: twice the median radius keeps typical bodies in ≤ 8 cells.
        self.radii_scratch.clear();
        self.radii_scratch.extend_from_slice(radii);
        let (_, median, _) = self.radii_scratch.select_nth_unstable_by(n / 2, |a, b| a.total_cmp(b));
        let cell = (2.0 * *median).max(1e-9);
        for (i, (c, &r)) in centres.iter().zip(radii).enumerate() {
            let lo = ((c - Vec3::repeat(r)) / cell).map(Real::floor);
            let hi = ((c + Vec3::repeat(r)) / cell).map(Real::floor);
            // Counted in floating point: a body flung far (or a huge swept radius) must not
            // overflow the integer cell range; such a body is tested against everyone. A NaN
            // centre or radius fails the `far` test too.
            let count = (hi - lo).add_scalar(1.0).product();
            let far = !lo.iter().chain(hi.iter()).all(|v| v.abs() < 1e6);
            if far || count > MAX_CELLS_PER_BODY as Real {
                self.oversized.push(i as u32);
                continue;
            }
            let (x0, y0, z0) = (lo.x as i64, lo.y as i64, lo.z as i64);
            let (x1, y1, z1) = (hi.x as i64, hi.y as i64, hi.z as i64);
            self.lo_cell[i] = [x0, y0, z0];
            for ix in x0..=x1 {
                for iy in y0..=y1 {
                    for iz in z0..=z1 {
                        self.entries.push((cell_key(ix, iy, iz), i as u32));
                    }
                }
            }
        }
        self.sort_entries();
        let mut start = 0;
        while start < self.entries.len() {
            let key = self.entries[start].0;
            let mut end = start + 1;
            while end < self.entries.len() && self.entries[end].0 == key {
                end += 1;
            }
            // Two bodies share every cell of the intersection of their cell ranges; the pair is
            // taken only in its lowest one (the larger of the two lowest cells on each axis), so
            // it is found once, not in up to 8 cells and then sorted out again.
            for p in start..end {
                for q in p + 1..end {
                    let (i, j) = (self.entries[p].1, self.entries[q].1);
                    let (li, lj) = (self.lo_cell[i as usize], self.lo_cell[j as usize]);
                    let lowest = cell_key(li[0].max(lj[0]), li[1].max(lj[1]), li[2].max(lj[2]));
                    if lowest == key {
                        self.pairs.push((i.min(j), i.max(j)));
                    }
                }
            }
            start = end;
        }
        for &i in &self.oversized {
            for j in 0..n as u32 {
                if j != i {
                    self.pairs.push((i.min(j), i.max(j)));
                }
            }
        }
        self.sort_pairs(n);
        // Two oversized bodies list their pair twice.
        self.pairs.dedup();
        self.pairs.retain(|&(i, j)| {
            let (i, j) = (i as usize, j as usize);
            (centres[i] - centres[j]).norm() <= radii[i] + radii[j]
        });
        &self.pairs
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_matches_all_pairs() {
        let mut centres = Vec::new();
        let mut radii = Vec::new();
        for i in 0..60 {
            let t = i as Real;
            centres.push(Vec3::new((t * 0.37).sin(), (t * 0.91).cos(), (t * 0.13).sin() * 2.0));
            radii.push(0.1 + 0.05 * ((t * 1.7).sin().abs()) + if i == 7 { 3.0 } else { 0.0 });
        }
        let mut bp = BroadPhase::default();
        let got = bp.overlapping_pairs(&centres, &radii).to_vec();
        let mut want = Vec::new();
        for i in 0..60 {
            for j in i + 1..60 {
                if (centres[i] - centres[j]).norm() <= radii[i] + radii[j] {
                    want.push((i as u32, j as u32));
                }
            }
        }
        assert_eq!(got, want);
        assert!(!want.is_empty());
    }

    /// The counting sort orders the entries exactly as a comparison sort would, in a compact
    /// box (counted) and in a sparse one (the fallback).
    #[test]
    fn counting_sort_matches_comparison_sort() {
        for spread in [1.0, 1e4] {
            let mut bp = BroadPhase::default();
            for i in 0..300u32 {
                let t = i as Real;
                let c = [(t * 0.37).sin() * spread, (t * 0.91).cos() * spread, (t * 0.13).sin() * 3.0 * spread];
                let cell = |v: Real| (v / 0.2).floor() as i64;
                for d in 0..2 {
                    bp.entries.push((cell_key(cell(c[0]) + d, cell(c[1]) - d, cell(c[2]) + 2 * d), i));
                }
            }
            let mut want = bp.entries.clone();
            want.sort_unstable();
            bp.sort_entries();
            assert_eq!(bp.entries, want, "spread {spread}");
        }
    }

    /// A body with an enormous swept radius or far away (a solver gone wrong upstream) must
    /// neither overflow the cell arithmetic nor allocate cells for its whole extent: it was an
    /// 8 GiB allocation before.
    #[test]
    fn huge_or_distant_spheres_do_not_blow_up_the_grid() {
        let centres = vec![Vec3::zeros(), Vec3::new(0.5, 0.0, 0.0), Vec3::new(1e300, 0.0, 0.0), Vec3::zeros()];
        let radii = vec![0.3, 0.3, 0.3, 1e200];
        let mut bp = BroadPhase::default();
        let got = bp.overlapping_pairs(&centres, &radii).to_vec();
        assert_eq!(got, vec![(0, 1), (0, 3), (1, 3)]);
    }
}
