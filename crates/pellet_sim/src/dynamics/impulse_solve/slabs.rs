//! The contacts of a solve in horizontal slabs of bodies (`docs/engine.md`, "Threads"), so that
//! a sweep can run on several threads and give the same answer for any number of them.
//!
//! Bodies are cut into slabs by the height of their centres, each slab at least as thick as
//! the largest height difference of two bodies in contact, so that a contact joins bodies of
//! one slab or of two neighbouring ones. Slab s's task is the contacts whose lower body lies
//! in slab s: it touches slabs s and s + 1 only. A sweep runs the tasks of even slabs, then
//! those of odd slabs: the tasks of one half share no body, so they may run in any order or at
//! once with the same result. Within a task the contacts go bottom up, as the serial solve's.

use crate::geometry::contact::Contact;
use crate::math::Real;

/// At most this many slabs: bodies spread over a tall tube with few contacts would otherwise
/// give slabs of a handful of contacts each, where the barrier between halves costs more than
/// their work.
const MAX_SLABS: usize = 1024;

/// Where each body and contact goes.
pub(super) struct Layout {
    /// Per slab, its bodies (indices into the solve's bodies), ascending.
    pub slabs: Vec<Vec<usize>>,
    /// Per body, its slab (u32::MAX: in no contact) and its index within the slab.
    pub place: Vec<(u32, u32)>,
    /// Per slab, its task: the contacts (indices) whose lower body lies in the slab, bottom up.
    pub tasks: Vec<Vec<usize>>,
}

impl Layout {
    /// The slabs of the bodies in `contacts`, whose centres are at `height` (m).
    pub fn new(contacts: &[Contact], height: &[Real]) -> Self {
        let mut place = vec![(u32::MAX, 0u32); height.len()];
        if contacts.is_empty() {
            return Self { slabs: Vec::new(), place, tasks: Vec::new() };
        }
        let bodies = |c: &Contact| [Some(c.a), c.b_body()];
        let (mut low, mut high, mut reach) = (Real::INFINITY, Real::NEG_INFINITY, 0.0 as Real);
        for c in contacts {
            for i in bodies(c).into_iter().flatten() {
                low = low.min(height[i]);
                high = high.max(height[i]);
            }
            if let Some(j) = c.b_body() {
                reach = reach.max((height[c.a] - height[j]).abs());
            }
        }
        let mut thickness = reach.max((high - low) / MAX_SLABS as Real);
        if !(thickness > 0.0 && thickness.is_finite()) {
            thickness = 1.0;
        }
        let slab_of = |z: Real, t: Real| (((z - low) / t) as usize).min(MAX_SLABS);
        // Rounding may put two bodies exactly `reach` apart two slabs apart: thicker slabs then.
        while contacts.iter().any(|c| {
            c.b_body().is_some_and(|j| slab_of(height[c.a], thickness).abs_diff(slab_of(height[j], thickness)) > 1)
        }) {
            thickness *= 1.5;
        }
        let mut slabs: Vec<Vec<usize>> = Vec::new();
        for c in contacts {
            for i in bodies(c).into_iter().flatten() {
                place[i].0 = slab_of(height[i], thickness) as u32;
            }
        }
        for (i, p) in place.iter_mut().enumerate() {
            if p.0 != u32::MAX {
                let s = p.0 as usize;
                if slabs.len() <= s {
                    slabs.resize_with(s + 1, Vec::new);
                }
                p.1 = slabs[s].len() as u32;
                slabs[s].push(i);
            }
        }
        let mut tasks: Vec<Vec<usize>> = vec![Vec::new(); slabs.len()];
        for (k, c) in contacts.iter().enumerate() {
            let s = bodies(c).into_iter().flatten().map(|i| place[i].0).min().unwrap_or(0);
            tasks[s as usize].push(k);
        }
        // Bottom up: a pile's weight reaches the floor in few sweeps, not one layer per sweep.
        for task in &mut tasks {
            task.sort_by(|&i, &j| contacts[i].point.z.total_cmp(&contacts[j].point.z).then(i.cmp(&j)));
        }
        Self { slabs, place, tasks }
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::pile;
    use super::*;

    /// Every contact in exactly one task, its bodies in the task's slab and the next, the
    /// tasks bottom up; every body in a contact in exactly one slab.
    #[test]
    fn slabs_hold_each_contact_once_within_two_neighbouring_slabs() {
        let (bodies, contacts, _) = pile();
        let height: Vec<Real> = bodies.iter().map(|b| b.position.z).collect();
        let layout = Layout::new(&contacts, &height);
        assert!(layout.slabs.len() >= 4, "{} slabs", layout.slabs.len());
        let mut seen = vec![0; contacts.len()];
        for (s, task) in layout.tasks.iter().enumerate() {
            for pair in task.windows(2) {
                assert!(contacts[pair[0]].point.z <= contacts[pair[1]].point.z);
            }
            for &k in task {
                seen[k] += 1;
                for i in [Some(contacts[k].a), contacts[k].b_body()].into_iter().flatten() {
                    let (slab, at) = layout.place[i];
                    assert!(
                        slab as usize == s || slab as usize == s + 1,
                        "contact {k} in task {s}, body {i} in {slab}"
                    );
                    assert_eq!(layout.slabs[slab as usize][at as usize], i);
                }
            }
        }
        assert!(seen.iter().all(|&n| n == 1));
        assert_eq!(layout.slabs.iter().map(Vec::len).sum::<usize>(), bodies.len());
    }
}
