//! Candidate pairs kept from one substep to the next (a Verlet list): the grid of
//! [`BroadPhase`] is built over spheres inflated by a skin, and while no body has moved (or
//! grown) by more than the skin since, the pairs that overlap now are among those candidates.
//! Filtering the candidates by the same overlap test gives the broad phase's own answer, pair
//! for pair and in the same order, so the cache changes no result, only the cost: a bed at
//! rest rebuilt its grid every substep (16 % of the quiet end of a 690-sphere bed in perf).

use super::broad_phase::BroadPhase;
use crate::math::{Real, Vec3};

/// A body may use this fraction of the skin before the candidates are rebuilt; the rest
/// covers the rounding of the displacement test (lengths of ~0.1 m against skins of ~0.1 mm).
const SKIN_USE: Real = 0.99;

/// The broad phase with its candidates kept across calls. Scratch, not simulation state: a
/// fresh cache gives the same pairs.
#[derive(Debug, Default, Clone)]
pub struct PairCache {
    broad: BroadPhase,
    /// Centres and radii the candidates were built from.
    built_centres: Vec<Vec3>,
    built_radii: Vec<Real>,
    built_skin: Real,
    /// Pairs whose spheres, inflated by the skin, overlapped at the build.
    candidates: Vec<(u32, u32)>,
    inflated: Vec<Real>,
    pairs: Vec<(u32, u32)>,
    /// Grid builds and queries so far (for tests and profiling).
    builds: u64,
    queries: u64,
}

impl PairCache {
    /// Pairs (i < j) whose spheres (centre `centres[i]`, radius `radii[i]`) overlap, sorted:
    /// exactly [`BroadPhase::overlapping_pairs`]. `skin` (m, ≥ 0) trades candidates per
    /// body against rebuilds.
    pub fn overlapping_pairs(&mut self, centres: &[Vec3], radii: &[Real], skin: Real) -> &[(u32, u32)] {
        self.queries += 1;
        if !self.still_valid(centres, radii, skin) {
            self.inflated.clear();
            self.inflated.extend(radii.iter().map(|r| r + skin));
            let candidates = self.broad.overlapping_pairs(centres, &self.inflated);
            self.candidates.clear();
            self.candidates.extend_from_slice(candidates);
            self.built_centres.clear();
            self.built_centres.extend_from_slice(centres);
            self.built_radii.clear();
            self.built_radii.extend_from_slice(radii);
            self.built_skin = skin;
            self.builds += 1;
        }
        self.pairs.clear();
        // The broad phase's own final test, expression for expression.
        self.pairs.extend(self.candidates.iter().filter(|&&(i, j)| {
            let (i, j) = (i as usize, j as usize);
            (centres[i] - centres[j]).norm() <= radii[i] + radii[j]
        }));
        &self.pairs
    }

    /// Grid builds and queries so far.
    #[cfg(test)]
    pub fn counts(&self) -> (u64, u64) {
        (self.builds, self.queries)
    }

    /// Whether every pair overlapping now was a candidate: a pair that was not had
    /// |c_i − c_j| > r_i + r_j + 2s at the build, and each end has since moved by d_k and grown
    /// by g_k with d_k + g_k ≤ s, so it is still apart. A NaN fails the test.
    fn still_valid(&self, centres: &[Vec3], radii: &[Real], skin: Real) -> bool {
        if self.builds == 0 || centres.len() != self.built_centres.len() || skin != self.built_skin {
            return false;
        }
        let budget = SKIN_USE * skin;
        centres.iter().zip(radii).zip(self.built_centres.iter().zip(&self.built_radii)).all(|((c, r), (c0, r0))| {
            let used = (c - c0).norm() + (r - r0).max(0.0);
            used <= budget
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// A cloud of 200 spheres jiggling and growing for 300 steps: the cache's pairs equal a fresh
    /// broad phase's at every step, and most steps reuse the candidates.
    #[test]
    fn cached_pairs_equal_fresh_pairs() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let n = 200;
        let mut centres: Vec<Vec3> = (0..n)
            .map(|_| {
                Vec3::new(rng.random_range(-0.03..0.03), rng.random_range(-0.03..0.03), rng.random_range(0.0..0.1))
            })
            .collect();
        let mut radii: Vec<Real> = (0..n).map(|_| rng.random_range(0.004..0.006)).collect();
        let mut cache = PairCache::default();
        let mut nonempty = 0;
        for step in 0..300 {
            for (c, r) in centres.iter_mut().zip(radii.iter_mut()) {
                *c += Vec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0))
                    * 2e-5;
                *r = (*r + rng.random_range(-1e-5..1e-5)).max(0.001);
            }
            // A body that jumps forces a rebuild.
            if step == 150 {
                centres[3] += Vec3::new(0.0, 0.0, 0.05);
            }
            let want = BroadPhase::default().overlapping_pairs(&centres, &radii).to_vec();
            let got = cache.overlapping_pairs(&centres, &radii, 5e-4).to_vec();
            assert_eq!(got, want, "step {step}");
            nonempty += usize::from(!want.is_empty());
        }
        assert!(nonempty > 250);
        let (builds, queries) = cache.counts();
        assert_eq!(queries, 300);
        assert!((2..60).contains(&builds), "{builds} builds");
    }

    /// A changed body count or skin, or a NaN centre, rebuilds.
    #[test]
    fn count_skin_and_nan_rebuild() {
        let mut cache = PairCache::default();
        let mut centres = vec![Vec3::zeros(), Vec3::new(0.01, 0.0, 0.0)];
        let radii = vec![0.006, 0.006];
        assert_eq!(cache.overlapping_pairs(&centres, &radii, 1e-3), [(0, 1)]);
        assert_eq!(cache.overlapping_pairs(&centres, &radii, 1e-3), [(0, 1)]);
        assert_eq!(cache.counts(), (1, 2));
        assert_eq!(cache.overlapping_pairs(&centres, &radii, 2e-3), [(0, 1)]);
        assert_eq!(cache.counts(), (2, 3));
        centres.push(Vec3::new(0.0, 0.011, 0.0));
        let radii3 = vec![0.006; 3];
        assert_eq!(cache.overlapping_pairs(&centres, &radii3, 2e-3), [(0, 1), (0, 2)]);
        assert_eq!(cache.counts(), (3, 4));
        centres[1].x = Real::NAN;
        assert_eq!(cache.overlapping_pairs(&centres, &radii3, 2e-3), [(0, 2)]);
        assert_eq!(cache.counts(), (4, 5));
    }
}
