//! Energy bookkeeping (checked by `tests/t13_energy.rs`): kinetic and potential energy, and what
//! collisions, friction and position projection removed.

use serde::{Deserialize, Serialize};

/// Energies in joules. "Removed" entries are positive when energy left the system.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct EnergyLedger {
    /// Translational kinetic energy at the end.
    pub kinetic_translational: f64,
    /// Rotational kinetic energy at the end.
    pub kinetic_rotational: f64,
    /// Potential energy −Σ m g·x at the end.
    pub potential: f64,
    /// Kinetic energy removed by normal collision impulses.
    pub removed_by_collisions: f64,
    /// Energy removed by friction (collision impulses and resting-contact forces).
    pub removed_by_friction: f64,
    /// Potential energy removed by position projection (negative if projection lifted bodies).
    pub removed_by_projection: f64,
    /// Work done by resting normal forces, Σ f (n · v̄_rel) δt with v̄_rel the mean of the relative
    /// velocity at the start and end of each substep, J; bounded by `resting_work_bound`.
    pub resting_normal_work: f64,
    /// Σ f εp δt over resting contacts.
    pub resting_work_bound: f64,
    /// Energy the velocity-level stepper's semi-implicit step takes out under gravity: a body
    /// with contacts moves by h·v⁺, not by the mean velocity h·(v⁻ + v⁺)/2 that gravity's work
    /// is counted with, so Σ m g·h (v⁺ − v⁻)/2 per step (zero for a body at rest; the
    /// force-level stepper integrates exactly and leaves it zero).
    #[serde(default)]
    pub removed_by_integrator: f64,
}

impl EnergyLedger {
    /// Kinetic plus potential energy.
    pub fn total(&self) -> f64 {
        self.kinetic_translational + self.kinetic_rotational + self.potential
    }

    /// Adds the dissipation entries of `other` (not the state energies).
    pub fn accumulate(&mut self, other: &EnergyLedger) {
        self.removed_by_collisions += other.removed_by_collisions;
        self.removed_by_friction += other.removed_by_friction;
        self.removed_by_projection += other.removed_by_projection;
        self.resting_normal_work += other.resting_normal_work;
        self.resting_work_bound += other.resting_work_bound;
        self.removed_by_integrator += other.removed_by_integrator;
    }
}
