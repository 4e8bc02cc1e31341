//! Position projection as both steppers call it: the bounds on how fast a gap can close, and
//! the re-evaluation of a contact at moved poses (`dynamics::stabilize` does the projecting).

use super::step::StepReport;
use super::world::World;
use crate::body::Body;
use crate::container::Container;
use crate::dynamics::stabilize::{project_positions, GapBounds, ProjectionStats};
use crate::error::SimError;
use crate::geometry::carried::{carriable, carried, pair_drift, Pose};
use crate::geometry::contact::Contact;
use crate::geometry::contact_sampled::gap_jump;
use crate::geometry::narrow_phase::{collide_feature, Pellet};
use crate::geometry::samples::GeometryCache;
use crate::geometry::sdf::lipschitz;
use crate::math::Real;
use crate::params::Stepper;
use crate::shape::{BodyType, ShapeDesc};
use crate::team::Team;

impl World {
    /// The projection's bounds on how fast a gap can close (`GapBounds`): a point a gap is
    /// measured from or in lies within the two bodies' bounding radii of either centre (plus a
    /// gap of up to the largest radius, far above any contact's look-ahead). A sphere's turn
    /// changes none of its gaps (each is a function of its centre), so its lever is zero.
    pub fn gap_bounds(&self) -> GapBounds {
        let shape = |b: &Body| &self.types[b.type_id.0 as usize].shape;
        let radius = |b: &Body| self.types[b.type_id.0 as usize].bounding_radius_m;
        let r_max = self.bodies.iter().map(radius).fold(0.0, Real::max);
        let lean = self.params.stepper == Stepper::Velocity;
        let lever = |b: &Body| match shape(b) {
            ShapeDesc::Sphere { .. } => 0.0,
            _ => radius(b) + 2.0 * r_max,
        };
        GapBounds {
            lipschitz: self.types.iter().map(|t| lipschitz(&t.shape)).fold(1.0, Real::max),
            lever: self.bodies.iter().map(lever).collect(),
            jump: self.bodies.iter().map(|b| gap_jump(shape(b), radius(b), lean)).collect(),
        }
    }

    /// The largest drift (m) over which the velocity-level stepper carries a pair's contacts
    /// (`VelocityParams::carry_drift`), or 0. A carried point on a curved surface stays where
    /// it was on the body while the true contact rolls on: its lever errs by up to the drift,
    /// a rolling torque within the patch's own (`patch_radius`, seven times the default drift)
    /// but one that contact points turning freely must not have: a cylinder lying across
    /// another, spun about their contact, lost 2 % of its spin in 1 s as the lower one rolled
    /// on its carried floor line. So without patches nothing is carried.
    pub(super) fn carry_limit(&self) -> Real {
        let v = &self.params.velocity;
        if v.patch_radius > 0.0 {
            v.carry_drift * self.reference_size()
        } else {
            0.0
        }
    }

    /// Position projection of the bodies, moved from `generated_at` where `contacts` were
    /// found (shared by both steppers), down to the slop, timed into `report`.
    fn project(
        &mut self,
        contacts: &[Contact],
        generated_at: &[Body],
        bounds: &GapBounds,
        team: &Team,
        report: &mut StepReport,
    ) -> ProjectionStats {
        let d = self.reference_size();
        let slop = self.params.slop_factor * d;
        let g = self.params.gravity;
        let (types, geometry, container) = (&self.types, &self.geometry, &self.container);
        let lean = self.params.stepper == Stepper::Velocity;
        // A negative limit carries nothing.
        let carry = match self.carry_limit() {
            limit if lean && limit > 0.0 => limit,
            _ => -1.0,
        };
        let eval = |bodies: &[Body], c: &Contact| {
            carry_or_reevaluate(generated_at, bodies, c, carry)
                .unwrap_or_else(|| reevaluate(types, geometry, container, bodies, c, lean))
        };
        let mut bodies = std::mem::take(&mut self.bodies);
        let clock = std::time::Instant::now();
        let proj = project_positions(&mut bodies, contacts, generated_at, &eval, bounds, slop, 0.01 * d, &g, team);
        report.wall_seconds[3] += clock.elapsed().as_secs_f64();
        self.bodies = bodies;
        proj
    }

    /// [`Self::project`], unless the penetration before it exceeds the largest allowed
    /// (`max_penetration_factor` of the pellet size) while rewinds are left: then the bodies go
    /// back to `saved` (the substep's start), the rewind is counted, and `None` asks the caller
    /// to halve its step and try again. A body left non-finite is an error.
    pub(super) fn project_or_rewind(
        &mut self,
        contacts: &[Contact],
        saved: &[Body],
        bounds: &GapBounds,
        rewinds: &mut u32,
        team: &Team,
        report: &mut StepReport,
    ) -> Result<Option<ProjectionStats>, SimError> {
        let pen_max = self.params.max_penetration_factor * self.nominal_size();
        let proj = self.project(contacts, saved, bounds, team, report);
        if proj.max_penetration_before > pen_max && *rewinds < self.params.max_rewinds {
            self.bodies.clone_from_slice(saved);
            *rewinds += 1;
            report.rewinds += 1;
            return Ok(None);
        }
        if let Some(k) = self.bodies.iter().position(|b| !b.is_finite()) {
            return Err(SimError::NonFiniteState(k as u32));
        }
        Ok(Some(proj))
    }
}

/// `c` carried from `generated_at` to `bodies` (`geometry::carried`) if its pair has moved by
/// no more than `limit` (m) relative to each other since; `None` to evaluate it again. `Some`
/// holds the carried contact.
fn carry_or_reevaluate(generated_at: &[Body], bodies: &[Body], c: &Contact, limit: Real) -> Option<Option<Contact>> {
    if !carriable(c) {
        return None;
    }
    let pose = |set: &[Body], k: usize| Pose::of(&set[k]);
    let (a_then, a_now) = (pose(generated_at, c.a), pose(bodies, c.a));
    let b = c.b_body().map(|b| (pose(generated_at, b), pose(bodies, b)));
    let b = b.as_ref().map(|(then, now)| (then, now));
    let r = bodies[c.b_body().unwrap_or(c.a)].bounding_radius;
    if pair_drift((&a_then, &a_now), b, r) > limit {
        return None;
    }
    carried(c, &a_then, &a_now, b).map(Some)
}

/// Re-evaluates one contact's feature at the given poses (the narrow phase for that feature).
fn reevaluate(
    types: &[BodyType],
    geometry: &GeometryCache,
    container: &Container,
    bodies: &[Body],
    c: &Contact,
    lean: bool,
) -> Option<Contact> {
    let pellet = |k: usize| {
        let t = bodies[k].type_id.0 as usize;
        Pellet { index: k, body: &bodies[k], shape: &types[t].shape, geom: &geometry.types[t] }
    };
    collide_feature(container, pellet(c.a), c.b_body().map(pellet), &c.key, lean)
}
