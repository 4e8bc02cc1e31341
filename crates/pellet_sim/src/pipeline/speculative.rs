//! The velocity-level stepper's speculative contacts: every contact of a near pair or wall
//! whose gap can close within the step, from the narrow phase or carried from the pair's
//! manifold of an earlier step (`geometry::manifold`; `docs/engine.md`, "Contacts carried with
//! their bodies").

use super::step::Pipeline;
use super::velocity_step::{kept_features, Near};
use super::world::World;
use crate::error::SimError;
use crate::geometry::carried::Pose;
use crate::geometry::contact::{Contact, Counterpart};
use crate::geometry::manifold::{Manifold, Manifolds};
use crate::geometry::narrow_phase::{collide_pair_kept, collide_wall, is_sampled_pair};
use crate::math::Real;
use crate::shape::ShapeDesc;

/// How far beyond the step's gap limit a manifold's narrow phase looks, as a multiple of the
/// drift limit: a manifold serves while the limit plus twice the drift stays within its reach,
/// so a pair at rest whose limit wanders by round-off keeps it, and one drifting the whole
/// limit still has room for a limit that grew by as much.
const REACH_MARGIN: Real = 3.0;

/// Where a near pair's or wall's contacts come from this step.
enum Source {
    /// Carried from its manifold (at this place among the last step's): this range of the
    /// carried contacts.
    Carried(std::ops::Range<usize>, usize),
    /// The narrow phase, looking to `reach`; `keep`: its answer becomes the pair's manifold.
    Found { reach: Real, keep: bool },
}

struct Item {
    a: usize,
    b: Counterpart,
    max_gap: Real,
    source: Source,
}

impl World {
    /// The contacts of `near` whose gap can close within a step of `h`: pairs in `near`'s
    /// order, then walls. Pairs of pellets that are not spheres, and such pellets at a wall,
    /// keep their contacts as manifolds in `pipeline` and carry them while they drift by less
    /// than `VelocityParams::carry_drift`; the rest are found again every step.
    pub(super) fn speculative_contacts(
        &self,
        near: &Near,
        h: Real,
        pipeline: &mut Pipeline,
    ) -> Result<Vec<Contact>, SimError> {
        let delta_c = self.params.contact_distance_factor * self.reference_size();
        let g = self.params.gravity.norm();
        let limit = self.carry_limit();
        let shape = |k: usize| &self.types[self.bodies[k].type_id.0 as usize].shape;
        let pose = |k: usize| Pose::of(&self.bodies[k]);
        pipeline.samples.next_round();
        let old = std::mem::take(&mut pipeline.manifolds);

        let mut carried = Vec::new();
        let mut items = Vec::with_capacity(near.pairs.len() + near.walls.len());
        let source = |a: usize, b: Counterpart, max_gap: Real, keep: bool, carried: &mut Vec<Contact>| {
            if keep {
                let (b_pose, r_b) = match b {
                    Counterpart::Body(j) => (Some(pose(j)), self.bodies[j].bounding_radius),
                    Counterpart::Wall(_) => (None, self.bodies[a].bounding_radius),
                };
                let start = carried.len();
                if let Some(k) = old.index_of(a, b) {
                    if old.as_slice()[k].carry(&pose(a), b_pose.as_ref(), r_b, max_gap, limit, carried) {
                        return Source::Carried(start..carried.len(), k);
                    }
                }
            }
            let reach = if keep { max_gap + REACH_MARGIN * limit } else { max_gap };
            Source::Found { reach, keep }
        };
        let mut carried_pairs = Vec::new();
        for &(i, j, s) in &near.pairs {
            let max_gap = delta_c + s * h;
            let keep = limit > 0.0 && is_sampled_pair(shape(i), shape(j));
            let b = Counterpart::Body(j);
            let source = source(i, b, max_gap, keep, &mut carried);
            if matches!(source, Source::Carried(..)) {
                carried_pairs.push((i, j));
            }
            items.push(Item { a: i, b, max_gap, source });
        }
        for &(k, wall, s) in &near.walls {
            let max_gap = delta_c + s * h + g * h * h;
            let keep = limit > 0.0 && !matches!(shape(k), ShapeDesc::Sphere { .. });
            let b = Counterpart::Wall(wall);
            items.push(Item { a: k, b, max_gap, source: source(k, b, max_gap, keep, &mut carried) });
        }

        // The sample cache keeps a carried pair's samples for when it is next collided.
        carried_pairs.iter().for_each(|&(i, j)| pipeline.samples.keep(i, j));
        let found = self.found_contacts(&items, pipeline)?;
        let mut out = Vec::with_capacity(found.len() + carried.len());
        let mut old = old.into_parts();
        let mut manifolds = Vec::with_capacity(items.len());
        let mut next = 0;
        for item in &items {
            match &item.source {
                Source::Carried(range, k) => {
                    out.extend_from_slice(&carried[range.clone()]);
                    manifolds.extend(old[*k].take());
                }
                Source::Found { reach, keep } => {
                    // A pair's contacts are adjacent and carry its bodies (the narrow phase
                    // emits them pair by pair).
                    let start = next;
                    while found.get(next).is_some_and(|c| c.a == item.a && c.b == item.b) {
                        next += 1;
                    }
                    let group = &found[start..next];
                    if *keep {
                        out.extend(group.iter().filter(|c| c.gap <= item.max_gap).cloned());
                        let b_pose = body(item.b).map(pose);
                        manifolds.push(Manifold::new(item.a, item.b, pose(item.a), b_pose, *reach, group.to_vec()));
                    } else {
                        out.extend_from_slice(group);
                    }
                }
            }
        }
        debug_assert_eq!(next, found.len(), "every contact the narrow phase found belongs to an item");
        pipeline.manifolds = Manifolds::from_unsorted(manifolds);
        Ok(out)
    }

    /// The narrow phase's contacts of the items it has to look at, in their order, on the
    /// pipeline's threads.
    fn found_contacts(&self, items: &[Item], pipeline: &mut Pipeline) -> Result<Vec<Contact>, SimError> {
        let to_find = || {
            items.iter().filter_map(|item| match item.source {
                Source::Found { reach, .. } => Some((item.a, item.b, reach)),
                Source::Carried(..) => None,
            })
        };
        let pairs = to_find().filter_map(|(a, b, reach)| body(b).map(|j| (a, j, reach)));
        let walls = to_find().filter_map(|(a, b, reach)| match b {
            Counterpart::Wall(w) => Some((a, w, reach)),
            Counterpart::Body(_) => None,
        });
        if pipeline.team.threads() > 1 {
            let memory = Some(pipeline.impulses.as_slice());
            return self.contacts_on_threads(pairs, walls, &mut pipeline.samples, memory, &pipeline.team);
        }
        let mut out = Vec::new();
        let mut kept = Vec::new();
        for (i, j, reach) in pairs {
            let (ti, tj) = (self.bodies[i].type_id.0 as usize, self.bodies[j].type_id.0 as usize);
            let pa = self.pellet(&self.bodies, i, ti);
            let pb = self.pellet(&self.bodies, j, tj);
            kept_features(&pipeline.impulses, i, j, &mut kept);
            collide_pair_kept(pa, pb, reach, &mut pipeline.samples, &kept, &mut out)?;
        }
        for (k, wall, reach) in walls {
            let t = self.bodies[k].type_id.0 as usize;
            collide_wall(&self.container, wall, self.pellet(&self.bodies, k, t), reach, &mut out)?;
        }
        Ok(out)
    }
}

fn body(b: Counterpart) -> Option<usize> {
    match b {
        Counterpart::Body(j) => Some(j),
        Counterpart::Wall(_) => None,
    }
}
