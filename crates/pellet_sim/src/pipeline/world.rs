//! The serialisable world: bodies, types, container, materials, parameters, time.

use super::ledger::EnergyLedger;
use crate::body::{Body, BodyId, TypeId};
use crate::container::Container;
use crate::error::SimError;
use crate::geometry::narrow_phase::{min_wall_gap, Pellet};
use crate::geometry::samples::GeometryCache;
use crate::math::{Quat, Real, Vec3};
use crate::params::{EngineParams, Material, WallMaterial};
use crate::shape::BodyType;
use serde::{Deserialize, Serialize};

/// Everything that defines a simulation's state. Scratch buffers live in
/// [`crate::Pipeline`], which is not serialised.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct World {
    pub(crate) params: EngineParams,
    pub(crate) container: Container,
    pub(crate) material: Material,
    pub(crate) wall_material: WallMaterial,
    pub(crate) types: Vec<BodyType>,
    pub(crate) bodies: Vec<Body>,
    pub(crate) time: Real,
    /// Dissipation totals since the start.
    pub(crate) totals: EnergyLedger,
    /// Surface samples of the types (derived; rebuilt after deserialisation).
    #[serde(skip)]
    pub(crate) geometry: GeometryCache,
}

/// What changes as a world runs: its bodies, its clock and its dissipation totals. With the
/// world's fixed parts (types, container, materials, parameters) and the pipeline's warm
/// forces ([`crate::Pipeline::warm_forces`]) it continues a run bit for bit (checkpoints).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WorldState {
    /// The bodies, in index order.
    pub bodies: Vec<Body>,
    /// Simulated time, s.
    pub time: Real,
    /// Dissipation totals since the start.
    pub totals: EnergyLedger,
}

impl World {
    /// A world with no bodies. Validates every input.
    pub fn new(
        container: Container,
        material: Material,
        wall_material: WallMaterial,
        params: EngineParams,
    ) -> Result<Self, SimError> {
        params.validate()?;
        material.validate()?;
        wall_material.validate()?;
        container.validate(0.0)?;
        Ok(Self {
            params,
            container,
            material,
            wall_material,
            types: Vec::new(),
            bodies: Vec::new(),
            time: 0.0,
            totals: EnergyLedger::default(),
            geometry: GeometryCache::default(),
        })
    }

    /// Registers a pellet type; fails for invalid shapes or a tube too narrow for it (narrower
    /// than the shape's [`crate::ShapeDesc::fit_radius`]).
    pub fn register_type(&mut self, body_type: BodyType) -> Result<TypeId, SimError> {
        body_type.validate()?;
        self.container.validate(body_type.shape.fit_radius())?;
        self.types.push(body_type);
        self.geometry.sync(&self.types);
        Ok(TypeId(self.types.len() as u32 - 1))
    }

    /// Adds a pellet at `position` with `orientation` and velocities; it must lie inside the
    /// container.
    pub fn add_body(
        &mut self,
        type_id: TypeId,
        position: Vec3,
        orientation: Quat,
        linear_velocity: Vec3,
        angular_velocity: Vec3,
    ) -> Result<BodyId, SimError> {
        let ty = self.types.get(type_id.0 as usize).ok_or(SimError::UnknownBodyType(type_id.0))?;
        let all_finite =
            position.iter().chain(linear_velocity.iter()).chain(angular_velocity.iter()).all(|v| v.is_finite())
                && orientation.coords.iter().all(|v| v.is_finite());
        let outside = SimError::OutsideContainer { x: position.x, y: position.y, z: position.z };
        if !all_finite {
            return Err(outside);
        }
        let density = self.material.density;
        let inertia_body = ty.inertia_per_density_m5 * density;
        let inv_inertia_body = inertia_body.try_inverse().ok_or(SimError::InvalidParameter {
            name: "inertia_per_density_m5",
            value: 0.0,
            reason: "not invertible",
        })?;
        let mass = ty.volume_m3 * density;
        let mut body = Body {
            type_id,
            position,
            orientation,
            linear_momentum: linear_velocity * mass,
            angular_momentum: Vec3::zeros(),
            mass,
            inertia_body,
            inv_inertia_body,
            bounding_radius: ty.bounding_radius_m,
        };
        body.angular_momentum = body.inertia_world() * angular_velocity;
        // Placement check with the exact wall gaps of the shape (a cylinder standing on the
        // floor is inside although its bounding sphere is not), round-off tolerance 1e-9·r.
        self.geometry.sync(&self.types);
        let t = type_id.0 as usize;
        let pellet = Pellet { index: self.bodies.len(), body: &body, shape: &ty.shape, geom: &self.geometry.types[t] };
        if min_wall_gap(&self.container, pellet) < -1e-9 * ty.bounding_radius_m {
            return Err(outside);
        }
        self.bodies.push(body);
        Ok(BodyId(self.bodies.len() as u32 - 1))
    }

    /// A copy of the state that changes as the world runs.
    pub fn state(&self) -> WorldState {
        WorldState { bodies: self.bodies.clone(), time: self.time, totals: self.totals }
    }

    /// Replaces the bodies, clock and totals by `state` (taken from a world with the same
    /// types). Refused if a body names an unregistered type or is not finite.
    pub fn restore(&mut self, state: WorldState) -> Result<(), SimError> {
        for (k, b) in state.bodies.iter().enumerate() {
            if b.type_id.0 as usize >= self.types.len() {
                return Err(SimError::UnknownBodyType(b.type_id.0));
            }
            if !b.is_finite() {
                return Err(SimError::NonFiniteState(k as u32));
            }
        }
        if !state.time.is_finite() {
            return Err(SimError::InvalidParameter { name: "time", value: state.time, reason: "must be finite" });
        }
        self.bodies = state.bodies;
        self.time = state.time;
        self.totals = state.totals;
        Ok(())
    }

    /// Read access to the bodies.
    pub fn bodies(&self) -> &[Body] {
        &self.bodies
    }

    /// One body.
    pub fn body(&self, id: BodyId) -> Option<&Body> {
        self.bodies.get(id.0 as usize)
    }

    /// Mutable access for tests and set-up (e.g. to change a velocity between steps).
    pub fn body_mut(&mut self, id: BodyId) -> Option<&mut Body> {
        self.bodies.get_mut(id.0 as usize)
    }

    /// Registered types.
    pub fn types(&self) -> &[BodyType] {
        &self.types
    }

    /// The container.
    pub fn container(&self) -> &Container {
        &self.container
    }

    /// Parameters.
    pub fn params(&self) -> &EngineParams {
        &self.params
    }

    /// Replaces the parameters (e.g. to switch modes between steps); validated first.
    pub fn set_params(&mut self, params: EngineParams) -> Result<(), SimError> {
        params.validate()?;
        self.params = params;
        Ok(())
    }

    /// Simulated time, s.
    pub fn time(&self) -> Real {
        self.time
    }

    /// Total kinetic energy, J.
    pub fn kinetic_energy(&self) -> Real {
        self.bodies.iter().map(|b| b.kinetic_translational() + b.kinetic_rotational()).sum()
    }

    /// Total potential energy −Σ m g·x, J.
    pub fn potential_energy(&self) -> Real {
        self.bodies.iter().map(|b| b.potential(&self.params.gravity)).sum()
    }

    /// Current energies plus the dissipation totals since the start.
    pub fn energy(&self) -> EnergyLedger {
        let mut l = self.totals;
        l.kinetic_translational = self.bodies.iter().map(Body::kinetic_translational).sum();
        l.kinetic_rotational = self.bodies.iter().map(Body::kinetic_rotational).sum();
        l.potential = self.potential_energy();
        l
    }

    /// Reference pellet size d = twice the largest bounding radius (0 without types).
    pub fn reference_size(&self) -> Real {
        2.0 * self.types.iter().map(|t| t.bounding_radius_m).fold(0.0, Real::max)
    }

    /// Nominal pellet size for the penetration bound: twice the smallest
    /// [`crate::ShapeDesc::fit_radius`] over the types (the diameter; the same as
    /// [`World::reference_size`] for spheres). The bound "penetration < 1 % of d" means this d:
    /// for a 10 × 10 mm cylinder it is 10 mm, while the bounding diameter is 14.1 mm, so
    /// `pen_max` was 1.41e-4 m and the 40-pellet pour reached 1.39e-4 m without a rewind.
    pub fn nominal_size(&self) -> Real {
        let r = self.types.iter().map(|t| t.shape.fit_radius()).fold(Real::INFINITY, Real::min);
        if r.is_finite() {
            2.0 * r
        } else {
            0.0
        }
    }
}
