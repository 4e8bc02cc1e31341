//! Post-stabilisation: project positions so that every gap is ≥ −s_lop, as
//! nonlinear Gauss–Seidel with inverse-mass weighting. Velocities are left alone, so no kinetic
//! energy is injected; the potential-energy change is reported for the ledger.

use super::rows::{BodyMass, Row};
use crate::body::Body;
use crate::geometry::contact::Contact;
use crate::math::{turn_angle, Quat, Real, Vec3};
use crate::team::Team;

/// Relaxation factor of one projection.
const BETA: Real = 0.8;
/// Largest number of sweeps over the violating contacts (the loop stops as soon as a sweep finds
/// nothing deeper than s_lop). Deep piles need more than the 2–4 sweeps that suffice for small
/// stacks: a correction travels about one contact per sweep against the wrong order.
const SWEEPS: usize = 100;

/// What the projection did.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ProjectionStats {
    /// Largest penetration before projection, m (≥ 0).
    pub max_penetration_before: Real,
    /// Largest penetration after projection, m (≥ 0).
    pub max_penetration_after: Real,
    /// Change of potential energy caused by the projection, J.
    pub potential_change: Real,
    /// Number of corrections applied.
    pub corrections: u32,
}

/// Re-evaluates a contact at the bodies' current poses (the narrow phase for that pair).
pub type ContactEval<'a> = dyn Fn(&[Body], &Contact) -> Option<Contact> + Sync + 'a;

/// How far a contact's gap can fall while its bodies move, so that a contact known to stay
/// open is not evaluated again: the gap falls by at most `lipschitz` · Σ (|Δx_k| + `lever[k]` ·
/// |Δθ_k|) over its two bodies (the SDFs are `lipschitz`-Lipschitz, and every point that a gap
/// is measured from or in lies within `lever[k]` of body k's centre), plus `jump[k]` where the
/// narrow phase switches how it measures (a ring's edge–edge gap, a search that lands in
/// another minimum). Per body, indexed like the bodies (`World::gap_bounds` builds them).
#[derive(Debug, Clone)]
pub struct GapBounds {
    /// Lipschitz constant of the gap in a point's position.
    pub lipschitz: Real,
    /// Lever arm of body k's rotation, m.
    pub lever: Vec<Real>,
    /// Largest jump of a gap measured on or against body k, m.
    pub jump: Vec<Real>,
}

/// Projects positions. `contacts` were generated with the bodies at the poses of `generated_at`
/// (the substep's start, before integration moved them to `bodies`). `max_step` caps one
/// correction's displacement (≈ 0.01 d). `bounds` lets a contact whose gap provably stays
/// positive go without re-evaluation: the same corrections. The first evaluations of the
/// contacts run on `team`'s threads, with the same answer for any number of them.
#[allow(clippy::too_many_arguments)]
pub fn project_positions(
    bodies: &mut [Body],
    contacts: &[Contact],
    generated_at: &[Body],
    eval: &ContactEval<'_>,
    bounds: &GapBounds,
    slop: Real,
    max_step: Real,
    gravity: &Vec3,
    team: &Team,
) -> ProjectionStats {
    let mut st = ProjectionStats::default();
    // A contact's gap is a function of its two bodies' poses only, so it is evaluated again
    // only after one of them moved: a sweep late in a deep pile moves few bodies, and
    // re-running the narrow phase for every contact on every sweep was 13 % of a 690-sphere
    // pour (perf). Each body's drift starts with its motion since the contacts were generated,
    // so a contact the narrow phase found open by more than that motion can close is not
    // evaluated at all (the first pass evaluated every contact: ~40 % of the evaluations left
    // in a wide cylinder bed at rest).
    let mut moves = vec![0u32; bodies.len()];
    let drift = bodies.iter().zip(generated_at).enumerate().map(|(k, (now, then))| {
        (now.position - then.position).norm() + bounds.lever[k] * turn_angle(&now.orientation, &then.orientation)
    });
    let mut cache = ContactCache {
        eval,
        contacts,
        bounds,
        drift: drift.collect(),
        slot: vec![NO_ENTRY; contacts.len()],
        entries: Vec::new(),
    };
    cache.first_evaluations(bodies, team);
    st.max_penetration_before = cache.max_penetration(bodies, &moves);
    if st.max_penetration_before <= slop {
        st.max_penetration_after = st.max_penetration_before;
        return st;
    }
    // Bottom-up order (ascending height of the contact point, ties by index): in a pile a
    // correction then reaches the top in one sweep, the cheap form of shock propagation.
    // Sorted as (height, index) pairs, not indices that look the heights up in the contacts
    // per comparison (1.9 % of a cylinder bed); the order is a total one, so the same.
    let mut keyed: Vec<(Real, usize)> = contacts.iter().enumerate().map(|(i, c)| (c.point.z, i)).collect();
    keyed.sort_unstable_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
    let order: Vec<usize> = keyed.into_iter().map(|(_, i)| i).collect();
    // Per contact, its bodies' correction counts when a sweep last found it needing none: until
    // one of them moves, it needs none again (the cache would give the same answer), so the
    // sweep passes it by without asking. A projection takes 15 sweeps over ~2000 contacts on
    // average in a 690-sphere bed, most of them about nothing.
    let mut quiet: Vec<(u32, u32)> = vec![(u32::MAX, u32::MAX); contacts.len()];
    for _ in 0..SWEEPS {
        let mut any = false;
        for &i in &order {
            let stamp = (moves[contacts[i].a], contacts[i].b_body().map_or(0, |b| moves[b]));
            if quiet[i] == stamp {
                continue;
            }
            // The cached evaluation is the contact at the current poses (its bodies have not
            // moved since), so it is not evaluated a second time for the correction.
            let c = match cache.contact(bodies, &moves, i) {
                Some(c) if c.gap < -slop => c.clone(),
                _ => {
                    quiet[i] = stamp;
                    continue;
                }
            };
            any = true;
            let b = c.b_body();
            let masses =
                [BodyMass::of(&bodies[c.a]), b.map_or(BodyMass::of(&bodies[c.a]), |k| BodyMass::of(&bodies[k]))];
            let row = Row::new(0, b.map(|_| 1), &c.lever_a, &c.lever_b, &c.normal, &masses);
            let mut dmu = -BETA * (c.gap + 0.5 * slop) / row.diag;
            // Cap the displacement of the lighter side.
            let disp = dmu * masses[0].inv_mass.max(if b.is_some() { masses[1].inv_mass } else { 0.0 });
            if disp > max_step {
                dmu *= max_step / disp;
            }
            // Local indices 0 (A) and 1 (B): the row writes delta[0..6] and, with B, [6..12].
            let mut delta = [0.0; 12];
            row.add_response(dmu, &mut delta);
            st.corrections += 1;
            for (slot, k) in [Some(c.a), b].into_iter().enumerate().filter_map(|(s, k)| Some((s, k?))) {
                let dx = Vec3::new(delta[6 * slot], delta[6 * slot + 1], delta[6 * slot + 2]);
                let dth = Vec3::new(delta[6 * slot + 3], delta[6 * slot + 4], delta[6 * slot + 5]);
                moves[k] += 1;
                cache.drift[k] += dx.norm() + bounds.lever[k] * dth.norm();
                let body = &mut bodies[k];
                body.position += dx;
                st.potential_change -= body.mass * gravity.dot(&dx);
                if dth.norm_squared() > 0.0 {
                    body.orientation =
                        Quat::new_normalize(*Quat::from_scaled_axis(dth).quaternion() * *body.orientation.quaternion());
                }
            }
        }
        if !any {
            break;
        }
    }
    st.max_penetration_after = cache.max_penetration(bodies, &moves);
    st
}

/// Contacts at the current poses, each evaluated again only when one of its bodies has moved
/// since (`moves[k]` counts body k's corrections; an entry remembers the counts it was
/// evaluated at, and `None` in it means the feature no longer exists) and its gap may have
/// closed since (`drift[k]` adds up body k's motion bound since the contacts were generated,
/// `GapBounds`). A contact without an entry has not been evaluated since the narrow phase:
/// its gap then is the generated one, at drift zero.
struct ContactCache<'a, 'e> {
    eval: &'a ContactEval<'e>,
    contacts: &'a [Contact],
    bounds: &'a GapBounds,
    drift: Vec<Real>,
    /// Per contact, its entry in `entries`, or `NO_ENTRY`: only the contacts evaluated again get
    /// one (an entry per contact, mostly empty, was a ~0.4 MB fill per projection).
    slot: Vec<u32>,
    entries: Vec<CachedContact>,
}

/// A contact without an entry in `ContactCache::entries`.
const NO_ENTRY: u32 = u32::MAX;

/// A re-evaluated contact, the correction counts of its two bodies and their drifts when it
/// was evaluated.
#[derive(Clone)]
struct CachedContact {
    stamp: (u32, u32),
    drift: (Real, Real),
    contact: Option<Contact>,
}

impl ContactCache<'_, '_> {
    /// The contact at the current poses, or None if it does not exist or its gap is positive
    /// (where neither the sweep nor the penetration measure needs it: re-evaluating contacts
    /// that stay open was most of the projection's cost in a wide cylinder bed at rest).
    fn contact(&mut self, bodies: &[Body], moves: &[u32], i: usize) -> Option<&Contact> {
        let contacts = self.contacts;
        let c = &contacts[i];
        let stamp = (moves[c.a], c.b_body().map_or(0, |b| moves[b]));
        let slot = self.slot[i];
        let fresh = match self.entries.get(slot as usize) {
            None if self.stays_open(c, c.gap, (0.0, 0.0)) => return None,
            Some(e) if e.stamp == stamp => true,
            Some(CachedContact { drift: d0, contact: Some(old), .. }) if self.stays_open(c, old.gap, *d0) => {
                return None
            }
            _ => false,
        };
        if !fresh {
            let entry = CachedContact { stamp, drift: self.drift_of(c), contact: (self.eval)(bodies, c) };
            if slot == NO_ENTRY {
                self.slot[i] = self.entries.len() as u32;
                self.entries.push(entry);
            } else {
                self.entries[slot as usize] = entry;
            }
        }
        self.entries[self.slot[i] as usize].contact.as_ref()
    }

    /// Evaluates at the current poses, on `team`'s threads, every contact that the first
    /// penetration pass would evaluate (those whose gap may have closed since the narrow phase),
    /// and keeps them as that pass would: the same entries for any number of threads. The
    /// evaluations are the projection's main cost in beds of non-spheres (a feature's narrow
    /// phase each).
    fn first_evaluations(&mut self, bodies: &[Body], team: &Team) {
        if team.threads() < 2 || !self.entries.is_empty() {
            return;
        }
        let (eval, contacts) = (self.eval, self.contacts);
        let mut due: Vec<usize> =
            (0..contacts.len()).filter(|&i| !self.stays_open(&contacts[i], contacts[i].gap, (0.0, 0.0))).collect();
        let Ok(found) = team.in_order(&mut due, |chunk, out| {
            out.extend(chunk.iter().map(|&i| eval(bodies, &contacts[i])));
            Ok::<(), std::convert::Infallible>(())
        });
        for (&i, contact) in due.iter().zip(found) {
            self.slot[i] = self.entries.len() as u32;
            self.entries.push(CachedContact { stamp: (0, 0), drift: self.drift_of(&contacts[i]), contact });
        }
    }

    /// The drift bounds of `c`'s two bodies since the contacts were generated, m.
    fn drift_of(&self, c: &Contact) -> (Real, Real) {
        (self.drift[c.a], c.b_body().map_or(0.0, |b| self.drift[b]))
    }

    /// A gap of `c` measured when its bodies' drifts were `d0` provably stays open now.
    fn stays_open(&self, c: &Contact, gap: Real, d0: (Real, Real)) -> bool {
        let drift = self.drift_of(c);
        let jump = self.bounds.jump[c.a] + c.b_body().map_or(0.0, |b| self.bounds.jump[b]);
        gap - (self.bounds.lipschitz * ((drift.0 - d0.0) + (drift.1 - d0.1)) + jump) > 0.0
    }

    fn max_penetration(&mut self, bodies: &[Body], moves: &[u32]) -> Real {
        (0..self.contacts.len())
            .filter_map(|i| self.contact(bodies, moves, i).map(|c| c.gap))
            .map(|gap| (-gap).max(0.0))
            .fold(0.0, Real::max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::TypeId;
    use crate::geometry::contact_sphere_sphere::sphere_sphere;
    use crate::math::Mat3;
    use std::sync::atomic::{AtomicUsize, Ordering};

    const R: Real = 0.005;

    #[test]
    fn small_turns_are_measured_not_rounded_to_zero() {
        let axis = nalgebra::Unit::new_normalize(Vec3::new(0.3, -0.5, 0.8));
        let then = Quat::from_axis_angle(&nalgebra::Unit::new_normalize(Vec3::new(1.0, 2.0, 3.0)), 0.7);
        for angle in [1e-9, 1e-8, 1e-6, 0.3, 2.0] {
            let now = Quat::from_axis_angle(&axis, angle) * then;
            let measured = turn_angle(&now, &then);
            assert!((measured - angle).abs() <= 1e-6 * angle, "{angle:e} rad measured as {measured:e}");
        }
    }

    fn sphere(x: Vec3) -> Body {
        let inertia = Mat3::from_diagonal_element(0.4 * 1e-3 * R * R);
        Body {
            type_id: TypeId(0),
            position: x,
            orientation: Quat::identity(),
            linear_momentum: Vec3::zeros(),
            angular_momentum: Vec3::zeros(),
            mass: 1e-3,
            inertia_body: inertia,
            inv_inertia_body: inertia.try_inverse().unwrap(),
            bounding_radius: R,
        }
    }

    /// Projects a row of spheres whose pairs the narrow phase found at `generated` (gaps of
    /// 3–40 µm, open) and which then moved to `moved` (some now overlap); returns the bodies,
    /// the stats and the number of contact evaluations.
    fn project(
        generated: &[Body],
        moved: &[Body],
        told: &[Body],
        bounds: &GapBounds,
        team: &Team,
    ) -> (Vec<Body>, ProjectionStats, usize) {
        let contacts: Vec<Contact> = (0..generated.len() - 1)
            .filter_map(|k| {
                let (a, b) = (&generated[k + 1], &generated[k]);
                sphere_sphere(k + 1, &a.position, R, k, &b.position, R, 1.0)
            })
            .collect();
        let evaluations = AtomicUsize::new(0);
        let eval = |bodies: &[Body], c: &Contact| {
            evaluations.fetch_add(1, Ordering::Relaxed);
            let b = c.b_body().unwrap();
            sphere_sphere(c.a, &bodies[c.a].position, R, b, &bodies[b].position, R, Real::INFINITY)
        };
        let mut bodies = moved.to_vec();
        let st = project_positions(
            &mut bodies,
            &contacts,
            told,
            &eval,
            bounds,
            1e-6,
            1e-4,
            &Vec3::new(0.0, 0.0, -9.81),
            team,
        );
        (bodies, st, evaluations.into_inner())
    }

    /// Skipping contacts the narrow phase found open by more than their bodies moved since
    /// changes nothing, and it does skip; told the wrong poses (no motion since), it skips a
    /// contact that closed and the projection misses an overlap.
    #[test]
    fn contacts_open_by_more_than_the_motion_since_the_narrow_phase_are_skipped_exactly() {
        let gaps = [8e-6, 40e-6, 3e-6, 25e-6, 30e-6, 2e-6, 40e-6];
        let mut z = R;
        let mut generated = vec![sphere(Vec3::new(0.0, 0.0, z))];
        for g in gaps {
            z += 2.0 * R + g;
            generated.push(sphere(Vec3::new(0.0, 0.0, z)));
        }
        // Integration: every other sphere drops by 12 µm and tilts (a turn moves no sphere gap).
        let moved: Vec<Body> = generated
            .iter()
            .enumerate()
            .map(|(k, b)| {
                let mut b = b.clone();
                if k % 2 == 1 {
                    b.position.z -= 12e-6;
                    b.orientation = Quat::from_axis_angle(&Vec3::x_axis(), 1e-3);
                }
                b
            })
            .collect();
        let n = generated.len();
        let never = GapBounds { lipschitz: 1.0, lever: vec![3.0 * R; n], jump: vec![Real::INFINITY; n] };
        let skip = GapBounds { lipschitz: 1.0, lever: vec![3.0 * R; n], jump: vec![0.0; n] };
        let (reference, st_ref, evals_ref) = project(&generated, &moved, &generated, &never, &Team::default());
        assert!(st_ref.max_penetration_before > 1e-6 && st_ref.corrections > 0);
        let (skipped, st_skip, evals_skip) = project(&generated, &moved, &generated, &skip, &Team::default());
        // The first evaluations on threads: the same projection.
        for threads in [2, 3] {
            let (on_threads, st_threads, _) = project(&generated, &moved, &generated, &never, &Team::new(threads));
            assert_eq!((on_threads, st_threads), (reference.clone(), st_ref), "{threads} threads");
        }
        assert_eq!(skipped, reference);
        assert_eq!(st_skip, st_ref);
        assert!(evals_skip < evals_ref, "nothing skipped: {evals_skip} evaluations against {evals_ref}");
        // Told that nothing moved since the narrow phase, the 8 and 3 µm gaps that closed to
        // −4 and −9 µm are taken as still open.
        let (wrong, st_wrong, _) = project(&generated, &moved, &moved, &skip, &Team::default());
        assert_ne!(wrong, reference);
        assert!(st_wrong.max_penetration_before < st_ref.max_penetration_before);
    }
}
