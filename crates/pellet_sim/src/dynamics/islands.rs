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
}

fn find(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// Splits the contacts `subset` into islands, ordered by their smallest body index.
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
    // Map each root to an island slot, in order of first appearance by smallest body index.
    let mut roots: Vec<(usize, usize)> = Vec::new(); // (root, ci)
    for &ci in subset {
        let r = find(&mut parent, contacts[ci].a);
        roots.push((r, ci));
    }
    let mut keys: Vec<usize> = roots.iter().map(|&(r, _)| r).collect();
    keys.sort_unstable();
    keys.dedup();
    let mut islands = vec![Island::default(); keys.len()];
    for &(r, ci) in &roots {
        let k = keys.binary_search(&r).expect("root is present");
        let isl = &mut islands[k];
        isl.contacts.push(ci);
        isl.bodies.push(contacts[ci].a);
        if let Some(b) = contacts[ci].b_body() {
            isl.bodies.push(b);
        }
    }
    for isl in &mut islands {
        isl.bodies.sort_unstable();
        isl.bodies.dedup();
    }
    islands
}

impl Island {
    /// Local index of a global body.
    pub fn local(&self, body: usize) -> usize {
        self.bodies.binary_search(&body).expect("body belongs to the island")
    }

    /// Mass data of the island's bodies.
    pub fn masses(&self, bodies: &[Body]) -> Vec<BodyMass> {
        self.bodies.iter().map(|&k| BodyMass::of(&bodies[k])).collect()
    }

    /// The normal rows of the island's contacts.
    pub fn normal_system(&self, contacts: &[Contact], masses: &[BodyMass]) -> RowSystem {
        let rows = self
            .contacts
            .iter()
            .map(|&ci| {
                let c = &contacts[ci];
                Row::new(self.local(c.a), c.b_body().map(|b| self.local(b)), &c.lever_a, &c.lever_b, &c.normal, masses)
            })
            .collect();
        RowSystem::new(rows, self.bodies.len())
    }
}
