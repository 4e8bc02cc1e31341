//! The samples of a sampled pair that can touch, kept from one substep to the next.
//!
//! The sampled narrow phase (`contact_sampled`) tests each body's surface samples against the
//! other's signed distance φ, both ways: hundreds of samples per pair, culled by clusters. In a
//! bed at rest the pairs hardly move, and the few samples near the contact are the only ones
//! that matter. So the full sweep is run with a gap limit raised by a margin (`bound`), its
//! samples are kept, and later substeps test only those — while that is provably the same: a
//! sample left out had φ > bound (a rim sample: bound + its rim spacing) at the build; φ is
//! L-Lipschitz in the sample's position in the other body's frame, p = m s + t, which has since
//! moved by at most ‖Δm‖_F r + |Δt| (|s| ≤ r, the bounding radius); so while
//! L (‖Δm‖_F r + |Δt|) + max_gap ≤ bound it is still beyond the limit, and the kept samples,
//! visited in the sweep's order, give the sweep's hits exactly. Cache, not state: a fresh one
//! gives the same contacts.

use crate::math::{Mat3, Real, Vec3};

/// The margin of a build, × the smaller bounding radius of the pair (70 µm for the paper's
/// 10 mm cylinders): room for the pair to move before the next full sweep.
pub(crate) const SAMPLE_CACHE_MARGIN: Real = 0.01;

/// Safety factor on the motion bound, for the rounding of φ and of the bound itself.
const ROUNDING: Real = 1.01;

/// One pair's kept samples: for A's samples in B's field and B's in A's.
#[derive(Debug, Clone, Default)]
pub struct PairSamples {
    /// The src → dst maps (m, t) of both directions at the build.
    poses: [(Mat3, Vec3); 2],
    /// The gap limit the candidates were collected for (m).
    bound: Real,
    candidates: [Vec<u32>; 2],
    /// Full sweeps so far (0: nothing kept yet).
    builds: u64,
}

impl PairSamples {
    /// Whether the kept candidates still give every hit at `max_gap` for the maps `poses`
    /// (direction k: samples of the body with bounding radius `radii[k]` in a field of
    /// Lipschitz constant `lipschitz[k]`).
    pub(crate) fn covers(
        &self,
        poses: &[(Mat3, Vec3); 2],
        lipschitz: &[Real; 2],
        radii: &[Real; 2],
        max_gap: Real,
    ) -> bool {
        if self.builds == 0 {
            return false;
        }
        (0..2).all(|k| {
            let (m0, t0) = &self.poses[k];
            let (m, t) = &poses[k];
            let moved = (m - m0).norm() * radii[k] + (t - t0).norm();
            // Written so that a NaN fails it.
            ROUNDING * lipschitz[k] * moved + max_gap <= self.bound
        })
    }

    /// Starts over at `poses` with the candidates for gap limit `bound`, collected by
    /// `collect(direction, list)`.
    pub(crate) fn rebuild(
        &mut self,
        poses: [(Mat3, Vec3); 2],
        bound: Real,
        mut collect: impl FnMut(usize, &mut Vec<u32>),
    ) {
        self.poses = poses;
        self.bound = bound;
        for (k, list) in self.candidates.iter_mut().enumerate() {
            collect(k, list);
        }
        self.builds += 1;
    }

    /// Full sweeps so far.
    pub fn builds(&self) -> u64 {
        self.builds
    }

    /// The kept samples of both directions.
    pub(crate) fn candidates(&self) -> &[Vec<u32>; 2] {
        &self.candidates
    }
}

/// The kept samples of every sampled pair of the last substep, by pair.
#[derive(Debug, Clone, Default)]
pub struct SampleCache {
    pairs: std::collections::HashMap<(usize, usize), (u64, PairSamples)>,
    round: u64,
    lookups: u64,
}

impl SampleCache {
    /// Call once per narrow phase: pairs not looked up since the last call are dropped then.
    pub fn next_round(&mut self) {
        let round = self.round;
        self.pairs.retain(|_, (seen, _)| *seen == round);
        self.round += 1;
    }

    /// (full sweeps, lookups) summed over the pairs still kept: how often the cache was rebuilt.
    pub fn counts(&self) -> (u64, u64) {
        (self.pairs.values().map(|(_, p)| p.builds()).sum(), self.lookups)
    }

    /// The entry of pair (i, j) taken out of the cache (empty if new), counted as a lookup:
    /// to be worked on apart from the cache and [`Self::put`] back in the same round.
    pub fn take(&mut self, i: usize, j: usize) -> PairSamples {
        self.lookups += 1;
        self.pairs.remove(&(i, j)).map(|(_, p)| p).unwrap_or_default()
    }

    /// Puts back the entry of pair (i, j) taken with [`Self::take`], as looked up this round.
    pub fn put(&mut self, i: usize, j: usize, samples: PairSamples) {
        self.pairs.insert((i, j), (self.round, samples));
    }

    /// Keeps the entry of pair (i, j), if any, through the next [`Self::next_round`] although
    /// it was not looked up: its pair's contacts were carried this round (`manifold`), and
    /// the samples serve when it is next collided.
    pub fn keep(&mut self, i: usize, j: usize) {
        let round = self.round;
        if let Some(e) = self.pairs.get_mut(&(i, j)) {
            e.0 = round;
        }
    }

    /// The entry of pair (i, j), created empty if new.
    pub fn entry(&mut self, i: usize, j: usize) -> &mut PairSamples {
        self.lookups += 1;
        let round = self.round;
        let e = self.pairs.entry((i, j)).or_insert_with(|| (round, PairSamples::default()));
        e.0 = round;
        &mut e.1
    }
}
