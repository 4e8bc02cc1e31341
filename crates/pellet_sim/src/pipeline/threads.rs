//! The narrow phase on several threads (`docs/engine.md`, "Threads"). The contacts of a near
//! pair or wall depend on nothing but the two poses, the gap limit, the pair's features of the
//! last step and its own entry of the sample cache. So each sampled pair's entry is taken out
//! of the cache, the pairs and walls are split into chunks in the serial loop's order, the
//! chunks are collided on the pipeline's team of threads (a thread that is done takes the next chunk),
//! each chunk into its own list, the lists are joined in chunk order and the entries put back:
//! the contacts of the serial loop bit for bit, whichever thread did which chunk.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Mutex, PoisonError};

use super::step::WarmImpulse;
use super::velocity_step::kept_features;
use super::world::World;
use crate::container::WallId;
use crate::error::SimError;
use crate::geometry::contact::Contact;
use crate::geometry::narrow_phase::{collide_pair_with, collide_wall, is_sampled_pair};
use crate::geometry::sample_cache::{PairSamples, SampleCache};
use crate::math::Real;
use crate::team::Team;

/// Fewest jobs in a chunk: a bed of a few pellets is collided on the calling thread alone,
/// where starting a thread would cost more than its share of the work.
const MIN_CHUNK: usize = 16;

/// Chunks per thread: pairs differ in cost (a sphere pair is closed form, a ring pair samples
/// hundreds of points), so the work is handed out in a few chunks per thread.
const CHUNKS_PER_THREAD: usize = 4;

/// One near pair or wall of the narrow phase: body `a` and `b`, gap limit `max_gap` (m), and
/// the pair's entry of the sample cache while it is out (`None` for a wall, or a pair with a
/// sphere in it).
struct Job {
    a: usize,
    b: Other,
    max_gap: Real,
    samples: Option<PairSamples>,
}

/// What a body of a job meets.
enum Other {
    Body(usize),
    Wall(WallId),
}

impl World {
    /// The contacts of `pairs` (i, j, gap limit) and then `walls` (body, wall, gap limit), in
    /// that order, as the serial loops give them, collided on `team`'s threads.
    /// `memory`: the velocity-level stepper's impulses of the last step, sorted by key (its
    /// rules: `collide_pair_kept`); `None` for the force-level stepper's
    /// (`collide_pair_cached`). Call `cache.next_round()` first, as for the serial loops.
    pub(super) fn contacts_on_threads(
        &self,
        pairs: impl Iterator<Item = (usize, usize, Real)>,
        walls: impl Iterator<Item = (usize, WallId, Real)>,
        cache: &mut SampleCache,
        memory: Option<&[WarmImpulse]>,
        team: &Team,
    ) -> Result<Vec<Contact>, SimError> {
        let shape = |k: usize| &self.types[self.bodies[k].type_id.0 as usize].shape;
        let mut jobs: Vec<Job> = pairs
            .map(|(a, b, max_gap)| Job {
                a,
                b: Other::Body(b),
                max_gap,
                samples: is_sampled_pair(shape(a), shape(b)).then(|| cache.take(a, b)),
            })
            .chain(walls.map(|(a, wall, max_gap)| Job { a, b: Other::Wall(wall), max_gap, samples: None }))
            .collect();
        let pellet = |k: usize| self.pellet(&self.bodies, k, self.bodies[k].type_id.0 as usize);
        let contacts = in_order(team, &mut jobs, |chunk, out| {
            let mut kept = Vec::new();
            for job in chunk {
                match job.b {
                    Other::Body(b) => {
                        if let Some(memory) = memory {
                            kept_features(memory, job.a, b, &mut kept);
                        }
                        let lean = memory.is_some();
                        collide_pair_with(
                            pellet(job.a),
                            pellet(b),
                            job.max_gap,
                            job.samples.as_mut(),
                            &kept,
                            lean,
                            out,
                        )?;
                    }
                    Other::Wall(wall) => collide_wall(&self.container, wall, pellet(job.a), job.max_gap, out)?,
                }
            }
            Ok(())
        });
        for job in jobs {
            if let (Other::Body(b), Some(samples)) = (job.b, job.samples) {
                cache.put(job.a, b, samples);
            }
        }
        contacts
    }
}

/// What `work` appends for `items`, on `team`'s threads: the items are split into
/// chunks in order, each chunk's output is kept apart, and the outputs are joined in chunk
/// order, so the result is the serial one whichever thread ran which chunk. An error is the
/// first in that order (a chunk stops at its first, as the serial loop does).
fn in_order<T: Send, R: Send>(
    team: &Team,
    items: &mut [T],
    work: impl Fn(&mut [T], &mut Vec<R>) -> Result<(), SimError> + Sync,
) -> Result<Vec<R>, SimError> {
    let chunks = (items.len() / MIN_CHUNK).clamp(1, team.threads() * CHUNKS_PER_THREAD);
    let workers = team.threads().clamp(1, chunks);
    if workers == 1 {
        let mut out = Vec::with_capacity(items.len());
        work(items, &mut out)?;
        return Ok(out);
    }
    let size = items.len().div_ceil(chunks);
    type Slot<'a, T, R> = Mutex<(&'a mut [T], Vec<R>, Result<(), SimError>)>;
    let slots: Vec<Slot<'_, T, R>> =
        items.chunks_mut(size).map(|c| Mutex::new((c, Vec::with_capacity(size), Ok(())))).collect();
    let next = AtomicUsize::new(0);
    let run = || {
        while let Some(slot) = slots.get(next.fetch_add(1, Ordering::Relaxed)) {
            let mut slot = slot.lock().unwrap_or_else(PoisonError::into_inner);
            let (chunk, out, result) = &mut *slot;
            *result = work(chunk, out);
        }
    };
    team.run(workers, |_, _| run());
    let parts: Vec<_> = slots.into_iter().map(|s| s.into_inner().unwrap_or_else(PoisonError::into_inner)).collect();
    let mut joined = Vec::with_capacity(parts.iter().map(|(_, out, _)| out.len()).sum());
    for (_, out, result) in parts {
        result?;
        joined.extend(out);
    }
    Ok(joined)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chunks_are_joined_in_order_for_any_thread_count() {
        let serial: Vec<u64> = (0..1000u64).flat_map(|k| 0..k % 5).collect();
        for threads in [1, 2, 3, 8] {
            let mut items: Vec<u64> = (0..1000).collect();
            let out = in_order(&Team::new(threads), &mut items, |chunk, out| {
                for k in chunk.iter_mut() {
                    out.extend(0..*k % 5);
                    *k += 1;
                }
                Ok(())
            })
            .unwrap();
            assert_eq!(out, serial, "{threads} threads");
            assert!(items.iter().enumerate().all(|(k, &v)| v == k as u64 + 1), "each item once");
        }
    }

    #[test]
    fn the_first_error_in_order_is_returned() {
        let mut items: Vec<u32> = (0..500).collect();
        let err = in_order(&Team::new(3), &mut items, |chunk, out: &mut Vec<u32>| {
            for &mut k in chunk {
                if k == 123 || k == 400 {
                    return Err(SimError::InvalidParameter { name: "k", value: k as Real, reason: "test" });
                }
                out.push(k);
            }
            Ok(())
        })
        .unwrap_err();
        assert!(err.to_string().contains("123"), "{err}");
    }
}
