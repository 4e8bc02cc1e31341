//! The contact-generation interface: dispatch over shape kinds.
//!
//! A later issue adds cylinders, hollow cylinders and meshes by filling the match arms below;
//! the rest of the engine only sees [`Contact`] records.

use super::contact::Contact;
use super::contact_sphere_sphere::sphere_sphere;
use super::contact_sphere_wall::sphere_wall;
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
}

/// Appends the contacts between pellets `a` and `b` with gap ≤ `max_gap` to `out`.
pub fn collide_pair(a: Pellet<'_>, b: Pellet<'_>, max_gap: Real, out: &mut Vec<Contact>) -> Result<(), SimError> {
    match (a.shape, b.shape) {
        (ShapeDesc::Sphere { radius: ra }, ShapeDesc::Sphere { radius: rb }) => {
            out.extend(sphere_sphere(a.index, &a.body.position, *ra, b.index, &b.body.position, *rb, max_gap));
            Ok(())
        }
        (ShapeDesc::Sphere { .. }, other) | (other, _) => {
            Err(SimError::UnsupportedShape(format!("no contact generation for {}", other.kind_name())))
        }
    }
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
            Ok(())
        }
        other => Err(SimError::UnsupportedShape(format!("no wall contact generation for {}", other.kind_name()))),
    }
}
