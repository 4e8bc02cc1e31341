//! Contact manifolds kept from step to step (`docs/engine.md`, "Contacts carried with their
//! bodies"): the contacts the narrow phase found for a pair of pellets (or a pellet and a
//! wall), with the poses it found them at and the gap limit it looked to. While the pair has
//! moved by no more than a drift δ relative to each other since, and the gap limit asked now
//! plus 2δ stays within the one looked to, the same contacts carried to the current poses
//! (`carried`) stand for the narrow phase's answer: no point that lay beyond the reach can have
//! come within the limit (the points a patch's reduction dropped are its kept points' to stand
//! for, as in a fresh answer), and no carried gap errs by more than 2δ.

use super::carried::{carried, pair_drift, Pose};
use super::contact::{Contact, Counterpart};
use crate::math::Real;
use serde::{Deserialize, Serialize};

/// One pair's (or pellet and wall's) contacts as the narrow phase found them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Manifold {
    /// Pellet A.
    pub a: u32,
    /// Pellet B or a wall.
    pub b: Counterpart,
    /// A's pose when the contacts were found.
    a_pose: Pose,
    /// B's pose then (`None` for a wall).
    b_pose: Option<Pose>,
    /// The gap limit the narrow phase looked to (m).
    reach: Real,
    /// Every contact it found within `reach`, at those poses.
    contacts: Vec<Contact>,
}

impl Manifold {
    /// The contacts `contacts` of pellet `a` with `b`, found at poses `a_pose`, `b_pose` out
    /// to gap `reach`.
    pub(crate) fn new(
        a: usize,
        b: Counterpart,
        a_pose: Pose,
        b_pose: Option<Pose>,
        reach: Real,
        contacts: Vec<Contact>,
    ) -> Self {
        Self { a: a as u32, b, a_pose, b_pose, reach, contacts }
    }

    /// The key manifolds are sorted by.
    fn key(&self) -> (u32, Counterpart) {
        (self.a, self.b)
    }

    /// The contacts carried to `a_now` and `b_now` with gap ≤ `max_gap`, appended to `out`, if
    /// the pair has moved by at most `drift_limit` (m) relative to each other since they were
    /// found and `max_gap` + twice that motion stays within the reach; `false` (nothing
    /// appended) otherwise. `r_b`: B's bounding radius (A's for a wall).
    pub(crate) fn carry(
        &self,
        a_now: &Pose,
        b_now: Option<&Pose>,
        r_b: Real,
        max_gap: Real,
        drift_limit: Real,
        out: &mut Vec<Contact>,
    ) -> bool {
        if self.b_pose.is_some() != b_now.is_some() {
            return false;
        }
        let b = self.b_pose.as_ref().zip(b_now);
        let drift = pair_drift((&self.a_pose, a_now), b, r_b);
        if drift > drift_limit || max_gap + 2.0 * drift > self.reach {
            return false;
        }
        let start = out.len();
        for c in &self.contacts {
            match carried(c, &self.a_pose, a_now, b) {
                Some(c) if c.gap <= max_gap => out.push(c),
                Some(_) => {}
                None => {
                    out.truncate(start);
                    return false;
                }
            }
        }
        true
    }
}

/// The manifolds of the last step, sorted by pair.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct Manifolds {
    sorted: Vec<Manifold>,
}

impl Manifolds {
    /// Manifolds in any order.
    pub(crate) fn from_unsorted(mut list: Vec<Manifold>) -> Self {
        list.sort_unstable_by_key(Manifold::key);
        list.dedup_by_key(|m| m.key());
        Self { sorted: list }
    }

    /// The place of the manifold of `a` and `b` among [`Self::as_slice`], if kept.
    pub(crate) fn index_of(&self, a: usize, b: Counterpart) -> Option<usize> {
        let key = (a as u32, b);
        self.sorted.binary_search_by(|m| m.key().cmp(&key)).ok()
    }

    /// The manifolds one by one, each to be taken out once (none is cloned).
    pub(crate) fn into_parts(self) -> Vec<Option<Manifold>> {
        self.sorted.into_iter().map(Some).collect()
    }

    /// All of them, sorted by pair.
    pub(crate) fn as_slice(&self) -> &[Manifold] {
        &self.sorted
    }

    /// Forgets them all.
    pub(crate) fn clear(&mut self) {
        self.sorted.clear();
    }
}
