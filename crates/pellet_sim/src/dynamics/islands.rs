//! Islands: groups of contacts connected through shared dynamic bodies (union-find).
//! Static walls never join islands. Output order is deterministic.

use super::rows::{BodyMass, Row, RowSystem};
use crate::body::Body;
use crate::geometry::contact::Contact;

/// One island: contact indices (in the order given) and its dynamic bodies (sorted).
#[derive(Debug, Clone, Default)]
pub struct Island {
    /// Indices into the contact list.
    pub contacts: Vec<usize>,
    /// Global body indices, ascending.
    pub bodies: Vec<usize>,
    /// Per contact of `contacts`, the local indices (into `bodies`) of its bodies A and B.
    pub ends: Vec<(usize, Option<usize>)>,
}

fn find(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// Splits the contacts `subset` into islands, ordered by their smallest body index.
///
/// In linear time: a component's root is its smallest body (unions keep the smaller root), so
/// islands are numbered by walking the bodies in order, and each island's bodies come out
/// ascending from the same walk (sorting roots and per-island body lists, and a binary search
/// per contact end for its local index, were ~2 % of a 690-sphere bed).
pub fn build_islands(contacts: &[Contact], subset: &[usize], n_bodies: usize) -> Vec<Island> {
    let mut parent: Vec<usize> = (0..n_bodies).collect();
    for &ci in subset {
        let c = &contacts[ci];
        if let Some(b) = c.b_body() {
            let (ra, rb) = (find(&mut parent, c.a), find(&mut parent, b));
            if ra != rb {
                parent[ra.max(rb)] = ra.min(rb);
            }
        }
    }
    const NONE: usize = usize::MAX;
    // Bodies that some contact of the subset touches.
    let mut touched = vec![false; n_bodies];
    for &ci in subset {
        let c = &contacts[ci];
        touched[c.a] = true;
        if let Some(b) = c.b_body() {
            touched[b] = true;
        }
    }
    // Island slot of each root, and each touched body's local index, in body order.
    let mut slot = vec![NONE; n_bodies];
    let mut local = vec![NONE; n_bodies];
    let mut islands: Vec<Island> = Vec::new();
    for k in 0..n_bodies {
        if !touched[k] {
            continue;
        }
        let r = find(&mut parent, k);
        if slot[r] == NONE {
            slot[r] = islands.len();
            islands.push(Island::default());
        }
        let isl = &mut islands[slot[r]];
        local[k] = isl.bodies.len();
        isl.bodies.push(k);
    }
    for &ci in subset {
        let c = &contacts[ci];
        let isl = &mut islands[slot[find(&mut parent, c.a)]];
        isl.contacts.push(ci);
        isl.ends.push((local[c.a], c.b_body().map(|b| local[b])));
    }
    islands
}

impl Island {
    /// Mass data of the island's bodies.
    pub fn masses(&self, bodies: &[Body]) -> Vec<BodyMass> {
        self.bodies.iter().map(|&k| BodyMass::of(&bodies[k])).collect()
    }

    /// The normal rows of the island's contacts.
    pub fn normal_system(&self, contacts: &[Contact], masses: &[BodyMass]) -> RowSystem {
        let rows = self
            .contacts
            .iter()
            .zip(&self.ends)
            .map(|(&ci, &(a, b))| {
                let c = &contacts[ci];
                Row::new(a, b, &c.lever_a, &c.lever_b, &c.normal, masses)
            })
            .collect();
        RowSystem::new(rows, self.bodies.len())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::container::WallId;
    use crate::geometry::contact::{ContactKey, Counterpart};
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn contact(a: usize, b: Option<usize>) -> Contact {
        let b = b.map_or(Counterpart::Wall(WallId::Floor), Counterpart::Body);
        Contact::bare(ContactKey { a: a as u32, b, feature: 0 })
    }

    /// The islands as they were built before (roots sorted, per-island body lists sorted and
    /// deduplicated, local indices by binary search).
    fn reference(contacts: &[Contact], subset: &[usize], n_bodies: usize) -> Vec<(Vec<usize>, Vec<usize>)> {
        let mut parent: Vec<usize> = (0..n_bodies).collect();
        for &ci in subset {
            if let Some(b) = contacts[ci].b_body() {
                let (ra, rb) = (find(&mut parent, contacts[ci].a), find(&mut parent, b));
                if ra != rb {
                    parent[ra.max(rb)] = ra.min(rb);
                }
            }
        }
        let roots: Vec<usize> = subset.iter().map(|&ci| find(&mut parent, contacts[ci].a)).collect();
        let mut keys = roots.clone();
        keys.sort_unstable();
        keys.dedup();
        let mut out = vec![(Vec::new(), Vec::new()); keys.len()];
        for (&r, &ci) in roots.iter().zip(subset) {
            let isl = &mut out[keys.binary_search(&r).unwrap()];
            isl.0.push(ci);
            isl.1.push(contacts[ci].a);
            isl.1.extend(contacts[ci].b_body());
        }
        for isl in &mut out {
            isl.1.sort_unstable();
            isl.1.dedup();
        }
        out
    }

    /// Random contact graphs (pairs and walls, subsets in any order): the same islands, in the
    /// same order, with the same contacts and bodies, and local ends that point at the bodies.
    #[test]
    fn islands_match_the_sorting_construction() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        for _ in 0..200 {
            let n_bodies = rng.random_range(1..60);
            let contacts: Vec<Contact> = (0..rng.random_range(0..120))
                .map(|_| {
                    let a = rng.random_range(0..n_bodies);
                    let b = (n_bodies > 1 && rng.random_range(0..3) != 0)
                        .then(|| (a + rng.random_range(1..n_bodies)) % n_bodies);
                    contact(a, b)
                })
                .collect();
            let subset: Vec<usize> = (0..contacts.len()).filter(|_| rng.random_range(0..4) != 0).collect();
            let islands = build_islands(&contacts, &subset, n_bodies);
            let expected = reference(&contacts, &subset, n_bodies);
            assert_eq!(islands.len(), expected.len());
            for (isl, (cs, bs)) in islands.iter().zip(&expected) {
                assert_eq!((&isl.contacts, &isl.bodies), (cs, bs));
                for (&ci, &(la, lb)) in isl.contacts.iter().zip(&isl.ends) {
                    assert_eq!(isl.bodies[la], contacts[ci].a);
                    assert_eq!(lb.map(|l| isl.bodies[l]), contacts[ci].b_body());
                }
            }
        }
    }
}
