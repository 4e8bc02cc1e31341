//! The narrow phase on several threads (`docs/engine.md`, "Threads"). The contacts of a near
//! pair or wall depend on nothing but the two poses, the gap limit, the pair's features of the
//! last step and its own entry of the sample cache. So each sampled pair's entry is taken out
//! of the cache, the pairs and walls are split into chunks in the serial loop's order, the
//! chunks are collided on the pipeline's team of threads (a thread that is done takes the next chunk),
//! each chunk into its own list, the lists are joined in chunk order and the entries put back:
//! the contacts of the serial loop bit for bit, whichever thread did which chunk.

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
        let contacts = team.in_order(&mut jobs, |chunk, out| {
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
