//! The velocity-level step's collision phase (`docs/engine.md`, "Collisions before the step's
//! solve"): the contacts colliding at the start of the step are solved alone
//! to Newton's law, every other contact left out, as in the force-level stepper's collision
//! passes; a contact that one pass sets closing faster than εp collides in the next. The
//! step's one solve over every contact then follows, inelastic, from the velocities the passes
//! leave. Solving restitution inside that one solve instead makes an impact on a pile bounce
//! off the pile as off one rigid body.

use super::{solve_impulses, NormalTarget, VelocityState, WarmStart};
use crate::geometry::contact::Contact;
use crate::math::{Real, Vec3};
use crate::team::Team;

/// Passes before the step's solve takes over as the final e = 0 solve, as in the force-level
/// stepper's collision phase: a chain of impacts through a pile ends there.
pub const MAX_COLLISION_PASSES: usize = 50;

/// A contact that a pass may set colliding: touching, and not an open contact that was already
/// closing fast at the start of the step (that one is stopped at the touching gap and bounces
/// the step after).
#[derive(Debug, Clone, Copy)]
pub struct Touching {
    /// The contact's index.
    pub index: usize,
    /// Its coefficient of restitution.
    pub cor: Real,
    /// Gravity's increment of its relative normal speed over the step, m/s (against a wall;
    /// zero between two pellets): Newton's law acts on the speed before it.
    pub fall: Real,
}

/// The impulses of the collision passes per contact (N·s, as in `ImpulseSolution`), and how
/// the passes went.
#[derive(Debug, Clone, Default)]
pub struct Collisions {
    pub normal: Vec<Real>,
    pub friction: Vec<Vec3>,
    pub torque: Vec<Vec3>,
    /// Passes run.
    pub passes: usize,
    /// Sweeps of their solves, summed.
    pub sweeps: usize,
    /// Every pass's solve met its stop test.
    pub converged: bool,
    /// Contacts still colliding after `MAX_COLLISION_PASSES` passes (left to the step's solve).
    pub capped: bool,
    /// A pass would have raised its bodies' kinetic energy and was undone; the contacts still
    /// colliding are left to the step's solve.
    pub gained: bool,
}

/// Runs the collision passes on the free velocities `st` (changed in place): first the contacts
/// of `first` (index, restitution target u_n⁺ ≥ t, m/s), then, pass after pass, those of
/// `touching` on a body the pass before moved whose relative normal speed then closes faster
/// than `eps_p`, each to −e times that speed.
#[allow(clippy::too_many_arguments)]
pub fn collision_passes(
    contacts: &[Contact],
    targets: &[NormalTarget],
    first: &[(usize, Real)],
    touching: &[Touching],
    eps_p: Real,
    st: &mut VelocityState,
    tolerance: Real,
    max_sweeps: usize,
    team: &Team,
) -> Collisions {
    let n = contacts.len();
    let mut out = Collisions {
        normal: vec![0.0; n],
        friction: vec![Vec3::zeros(); n],
        torque: vec![Vec3::zeros(); n],
        converged: true,
        ..Collisions::default()
    };
    let by_body = Incidence::new(contacts, touching, st.v.len());
    let mut seen = vec![usize::MAX; touching.len()];
    let mut set: Vec<(usize, Real)> = first.to_vec();
    while !set.is_empty() {
        if out.passes == MAX_COLLISION_PASSES {
            out.capped = true;
            break;
        }
        let sub: Vec<Contact> = set.iter().map(|&(k, _)| contacts[k].clone()).collect();
        // An impact meets at a point: the patch that lets a contact at rest resist spin and
        // rolling is left to the step's solve (with it, a nearly elastic pour loses the spin
        // that compacts it, as the force-level stepper's impacts do not).
        let sub_targets: Vec<NormalTarget> =
            set.iter().map(|&(k, t)| NormalTarget { min_speed: t, patch: 0.0, ..targets[k] }).collect();
        let cold = vec![WarmStart::default(); sub.len()];
        // Newton's law on the contacts of a later pass, all at once, can ask for more energy
        // than their impacts had (a pellet wedged between two that strike it), and a solve
        // that cannot meet such targets pumps it up pass after pass, without bound. No impact
        // creates energy: such a pass is undone and the step's solve, inelastic, ends the
        // collision, as at the pass cap. The first pass is exempt: its pending bounces give
        // back what stopping their contacts at the touching gap took the step before.
        let before: Option<Vec<(usize, Vec3, Vec3)>> = (out.passes > 0).then(|| {
            let mut moved: Vec<usize> = sub.iter().flat_map(|c| [Some(c.a), c.b_body()]).flatten().collect();
            moved.sort_unstable();
            moved.dedup();
            moved.into_iter().map(|i| (i, st.v[i], st.w[i])).collect()
        });
        let pass = solve_impulses(&sub, &sub_targets, &cold, st, tolerance, max_sweeps, team);
        if let Some(before) = before {
            // The pass's gain of kinetic energy is the work of its impulses, Σ j·(u⁻ + u⁺)/2,
            // exact for velocities linear in them (no patch torques: the passes have none).
            // The solve's stop test allows each impulse times the tolerance on its velocity.
            let (mut gain, mut slack) = (0.0, 0.0);
            for (i, c) in sub.iter().enumerate() {
                let j = c.normal * pass.normal[i] + pass.friction[i];
                gain += j.dot(&(0.5 * (pass.relative_before[i] + pass.relative_after[i])));
                slack += tolerance * (pass.normal[i].abs() + pass.friction[i].norm());
            }
            if gain > slack {
                for (i, v, w) in before {
                    st.v[i] = v;
                    st.w[i] = w;
                }
                out.passes += 1;
                out.gained = true;
                break;
            }
        }
        for (i, &(k, _)) in set.iter().enumerate() {
            out.normal[k] += pass.normal[i];
            out.friction[k] += pass.friction[i];
            out.torque[k] += pass.torque[i];
        }
        out.sweeps += pass.sweeps;
        out.converged &= pass.converged;
        let round = out.passes;
        out.passes += 1;
        let mut next: Vec<usize> = Vec::new();
        for c in &sub {
            for body in [Some(c.a), c.b_body()].into_iter().flatten() {
                for &t in by_body.of(body) {
                    if seen[t] != round {
                        seen[t] = round;
                        next.push(t);
                    }
                }
            }
        }
        next.sort_unstable();
        set = next
            .into_iter()
            .filter_map(|t| {
                let Touching { index: k, cor, fall } = touching[t];
                let approach = contacts[k].normal.dot(&st.relative(&contacts[k])) - fall;
                (approach < -eps_p).then_some((k, -cor * approach + fall))
            })
            .collect();
    }
    out
}

/// The touching contacts of each body, as indices of `touching` (compressed rows).
struct Incidence {
    start: Vec<usize>,
    items: Vec<usize>,
}

impl Incidence {
    fn new(contacts: &[Contact], touching: &[Touching], bodies: usize) -> Self {
        let ends = |t: &Touching| {
            let c = &contacts[t.index];
            [Some(c.a), c.b_body()].into_iter().flatten()
        };
        let mut start = vec![0usize; bodies + 1];
        for t in touching {
            for b in ends(t) {
                start[b + 1] += 1;
            }
        }
        for b in 0..bodies {
            start[b + 1] += start[b];
        }
        let mut fill = start.clone();
        let mut items = vec![0; start[bodies]];
        for (k, t) in touching.iter().enumerate() {
            for b in ends(t) {
                items[fill[b]] = k;
                fill[b] += 1;
            }
        }
        Self { start, items }
    }

    fn of(&self, body: usize) -> &[usize] {
        &self.items[self.start[body]..self.start[body + 1]]
    }
}
