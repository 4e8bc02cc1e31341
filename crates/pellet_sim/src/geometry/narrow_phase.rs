//! The contact-generation interface: dispatch over shape kinds (`docs/engine.md`, "Contact
//! generation").
//!
//! Sphere pairs and sphere–wall contacts are closed form; a sphere against any other shape puts
//! its centre into that shape's SDF; every other pair is sampled both ways against the SDFs
//! (closed form for cylinders and rings, a sampled grid for meshes); cylinders and rings meet
//! the walls analytically, meshes through their samples. The rest of the engine only sees
//! [`Contact`] records.

use super::contact::{Contact, ContactKey, Counterpart};
use super::contact_sampled::{sampled_feature, sampled_pair, sphere_shape};
use super::contact_shape_wall::{shape_wall, shape_wall_feature};
use super::contact_sphere_sphere::sphere_sphere;
use super::contact_sphere_wall::sphere_wall;
use super::sample_cache::{PairSamples, SampleCache};
use super::samples::TypeGeometry;
use crate::body::Body;
use crate::container::{Container, WallId};
use crate::error::SimError;
use crate::math::Real;
use crate::shape::ShapeDesc;

/// A dynamic pellet as the narrow phase sees it.
#[derive(Debug, Clone, Copy)]
pub struct Pellet<'a> {
    /// Body index in the world.
    pub index: usize,
    /// Its state.
    pub body: &'a Body,
    /// Its shape.
    pub shape: &'a ShapeDesc,
    /// Its type's samples and rims.
    pub geom: &'a TypeGeometry,
}

/// Appends the contacts between pellets `a` and `b` with gap ≤ `max_gap` to `out`.
pub fn collide_pair(a: Pellet<'_>, b: Pellet<'_>, max_gap: Real, out: &mut Vec<Contact>) -> Result<(), SimError> {
    collide(a, b, max_gap, None, &[], false, out)
}

/// [`collide_pair`] with the sampled pairs' candidate samples kept in `cache` across calls
/// (`sample_cache`): the same contacts, less work while the pair's relative pose hardly changes.
pub fn collide_pair_cached(
    a: Pellet<'_>,
    b: Pellet<'_>,
    max_gap: Real,
    cache: &mut SampleCache,
    out: &mut Vec<Contact>,
) -> Result<(), SimError> {
    collide(a, b, max_gap, Some(cache), &[], false, out)
}

/// [`collide_pair_cached`] for the velocity-level stepper: it keeps the points of the pair's
/// last contacts (where one of `kept`, features sorted, is as good a choice for a patch's point
/// as the best up to a small margin, `patch::reduce`, it is the one taken, so that the contacts
/// of a pair at rest keep their keys and impulses from step to step), and a rim crossing a
/// convex side gives only its refined deepest point.
pub fn collide_pair_kept(
    a: Pellet<'_>,
    b: Pellet<'_>,
    max_gap: Real,
    cache: &mut SampleCache,
    kept: &[u32],
    out: &mut Vec<Contact>,
) -> Result<(), SimError> {
    collide(a, b, max_gap, Some(cache), kept, true, out)
}

/// Whether pair (a, b) is sampled (neither is a sphere): the pairs whose contacts use a
/// [`PairSamples`] entry of the sample cache.
pub fn is_sampled_pair(a: &ShapeDesc, b: &ShapeDesc) -> bool {
    !matches!(a, ShapeDesc::Sphere { .. }) && !matches!(b, ShapeDesc::Sphere { .. })
}

/// [`collide_pair_cached`] (`lean`: [`collide_pair_kept`]) with the pair's own entry of the
/// sample cache, taken out of it (`None` for a pair that [`is_sampled_pair`] says is not
/// sampled, or to keep nothing): the same contacts, with no shared state, so that pairs can be
/// collided on several threads.
pub fn collide_pair_with(
    a: Pellet<'_>,
    b: Pellet<'_>,
    max_gap: Real,
    samples: Option<&mut PairSamples>,
    kept: &[u32],
    lean: bool,
    out: &mut Vec<Contact>,
) -> Result<(), SimError> {
    match sphere_pair(a, b, max_gap) {
        Some(one) => out.extend(one),
        None => sampled_pair(a, b, max_gap, samples, kept, lean, out),
    }
    Ok(())
}

fn collide(
    a: Pellet<'_>,
    b: Pellet<'_>,
    max_gap: Real,
    cache: Option<&mut SampleCache>,
    kept: &[u32],
    lean: bool,
    out: &mut Vec<Contact>,
) -> Result<(), SimError> {
    // Only a sampled pair has an entry: a sphere pair's would be made for nothing.
    let samples = cache.filter(|_| is_sampled_pair(a.shape, b.shape)).map(|c| c.entry(a.index, b.index));
    collide_pair_with(a, b, max_gap, samples, kept, lean, out)
}

/// The one contact of a pair with a sphere in it (`Some(None)`: farther apart than `max_gap`);
/// `None` if neither pellet is a sphere.
fn sphere_pair(a: Pellet<'_>, b: Pellet<'_>, max_gap: Real) -> Option<Option<Contact>> {
    Some(match (a.shape, b.shape) {
        (ShapeDesc::Sphere { radius: ra }, ShapeDesc::Sphere { radius: rb }) => {
            sphere_sphere(a.index, &a.body.position, *ra, b.index, &b.body.position, *rb, max_gap)
        }
        (ShapeDesc::Sphere { radius }, _) => sphere_shape(a, *radius, b, true, max_gap),
        (_, ShapeDesc::Sphere { radius }) => sphere_shape(b, *radius, a, false, max_gap),
        _ => return None,
    })
}

/// Appends the contacts of pellet `a` with wall `wall` (gap ≤ `max_gap`) to `out`.
pub fn collide_wall(
    container: &Container,
    wall: WallId,
    a: Pellet<'_>,
    max_gap: Real,
    out: &mut Vec<Contact>,
) -> Result<(), SimError> {
    match a.shape {
        ShapeDesc::Sphere { radius } => {
            out.extend(sphere_wall(container, wall, a.index, &a.body.position, *radius, max_gap));
        }
        _ => shape_wall(container, wall, a, max_gap, out),
    }
    Ok(())
}

/// Re-evaluates the one contact with `key` between `a` and `b` (or a's wall) at the current
/// poses, with no gap limit; its normal is that feature's own (not the patch's). `lean`: the
/// contact came from [`collide_pair_kept`] (the velocity-level stepper's rules).
pub fn collide_feature(
    container: &Container,
    a: Pellet<'_>,
    b: Option<Pellet<'_>>,
    key: &ContactKey,
    lean: bool,
) -> Option<Contact> {
    match (key.b, b) {
        (Counterpart::Body(_), Some(b)) => match sphere_pair(a, b, Real::INFINITY) {
            Some(one) => one,
            None => sampled_feature(a, b, key.feature, lean),
        },
        (Counterpart::Wall(w), _) => match a.shape {
            ShapeDesc::Sphere { radius } => {
                sphere_wall(container, w, a.index, &a.body.position, *radius, Real::INFINITY)
            }
            _ => shape_wall_feature(container, w, a, key.feature),
        },
        _ => None,
    }
}

/// Smallest gap between pellet `a` and any wall (negative if it pokes through one).
pub fn min_wall_gap(container: &Container, a: Pellet<'_>) -> Real {
    let mut out = Vec::new();
    let mut walls = Vec::new();
    container.wall_gaps(&a.body.position, a.body.bounding_radius, |w, _| walls.push(w));
    for w in walls {
        // Infallible for every shape kind.
        let _ = collide_wall(container, w, a, Real::INFINITY, &mut out);
    }
    out.iter().map(|c| c.gap).fold(Real::INFINITY, Real::min)
}
