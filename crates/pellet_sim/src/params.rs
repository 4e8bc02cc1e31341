//! Engine parameters and switches. `Default` is what `pack` runs when given no engine flags: the
//! velocity-level stepper, and for the force-level one the recommended contact model (static
//! friction, stick clamp, velocity bias) with the solver settings below, εp = εf = 5e-3 m/s and
//! δt_cap = 2.5e-4 s, so that g·δt_cap ≤ εp/2. [`EngineParams::paper`] is the paper's
//! formulation: the force-level stepper with the paper's contact model.

use crate::error::SimError;
use crate::math::{Real, Vec3, STANDARD_GRAVITY};
use crate::shape::positive;
use serde::{Deserialize, Serialize};

/// How a friction impulse that would reverse the sliding direction is clamped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum FrictionClamp {
    /// Replace it by the impulse that brings the tangential velocity exactly to zero.
    Stick,
    /// Drop the friction part altogether (the literal reading of the paper).
    Zero,
}

/// Which iterative solver handles islands larger than `exact_solver_max_rows`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum IterativeSolver {
    /// Accelerated projected gradient descent (Nesterov), PGS as fallback.
    Apgd,
    /// MPRGP (conjugate gradients with proportioning and projections), PGS as fallback.
    Mprgp,
}

/// The approach-speed bound v_max of the substep rule δt = 0.2λ/v_max.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum ApproachBound {
    /// The bound for any shape: |v_A − v_B| + |ω_A|ρ_A + |ω_B|ρ_B per pair,
    /// |v| + |ω|ρ + |g|δt_cap against a wall.
    Speed,
    /// `Speed` for pairs and walls that touch or may touch within the substep (gap ≤ δ_c + 0.2λ:
    /// the bound then also limits how far their contacts slip, which the bed's porosity was
    /// measured to need) and for every near pair of non-spheres. A near pair of spheres that
    /// does not touch counts only the closing speed of their centres −(v_A − v_B)·ĉ (a sphere's
    /// spin moves none of its surface); a body near a wall it does not touch counts its velocity
    /// into the wall (the tube wall: radial, plus what tangential motion and, for non-spheres,
    /// the turn of the wall normal across the body add) plus its spin term unless it is a
    /// sphere. Pairs and walls farther than λ limit the free flight by the closing speed of the
    /// bounding spheres alone, for any shape. So spheres falling beside the wall or their
    /// neighbours no longer shrink everyone's substep: the first 0.3 s of a batch pour of 690
    /// spheres (D = 79.9 mm) take 4883 substeps instead of 5262 (`pipeline/proximity.rs` has
    /// the porosity check).
    Normal,
}

/// The time-stepping scheme (`docs/engine.md`, "Time stepping"). [`EngineParams::default`] has
/// `Velocity`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Stepper {
    /// The paper's force-level scheme: substeps of δt = 0.2λ/v_max capped at `dt_cap`, collision
    /// passes of impulses, then an acceleration-level LCP of the resting contacts
    /// ([`AccelerationParams`]).
    Acceleration,
    /// Velocity-level time stepping: one complementarity solve on impulses per step for the
    /// colliding and resting contacts together, steps sized by kinematics
    /// ([`VelocityParams`]).
    Velocity,
}

impl Stepper {
    /// The scheme of parameters and archives recorded before there was a choice: `Acceleration`,
    /// the one that ran them.
    pub fn recorded_default() -> Self {
        Self::Acceleration
    }
}

/// Largest island solved by Baraff's dense pivoting method by default. Measured (`perf
/// record`, `pack` with the force-level stepper, 20 spheres of 10 mm in a 40 mm tube): with 64
/// rows, the paper formulation's ([`AccelerationParams::paper`]), 80 % of the time went to the
/// dense solver and 3 s of simulated time took 29.9 s; with 16 rows it took 1.96 s.
pub const EXACT_SOLVER_MAX_ROWS: usize = 16;

/// Largest island that Baraff solves again by default when the iterative solver ends
/// unconverged. Without it a cylinder bed never comes to rest: 20 cylinders of 10 mm in a 40 mm
/// tube (`pack --pellet c.pellet --tube-diameter 40 --count 20 --seed 1 --max-time 8`, force-level
/// stepper) still crept after 8 s (pellets moving 0.1–0.5 mm and turning up to 9° per second,
/// KE 3.2e-8 J, 136 s of CPU); with every island solved by Baraff the same bed was at rest
/// (KE 1e-17 J) by 2 s, but slowly. With the fallback up to 64 rows it settles at 2.19 s
/// simulated in 26 s of CPU; up to 96 rows, at 5.09 s in 107 s. Unconverged islands are rare in
/// sphere beds, so they pay almost nothing for it.
pub const EXACT_FALLBACK_MAX_ROWS: usize = 64;

/// The force-level stepper's parameters: its substep rule, the collision passes, the resting
/// contacts' friction model and the complementarity solvers behind both phases. `Default` is
/// what `pack --stepper acceleration` runs: the recommended contact model (static friction,
/// stick clamp, velocity bias), islands up to [`EXACT_SOLVER_MAX_ROWS`] rows by Baraff's
/// method and unconverged ones up to [`EXACT_FALLBACK_MAX_ROWS`] again by it; [`Self::paper`]
/// is the paper's. The velocity-level stepper reads none of these.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AccelerationParams {
    /// εf: tangential speed below which a contact does not slide, m/s.
    pub eps_f: Real,
    /// Upper bound on the substep, s (choose g·cap ≤ εp/2).
    pub dt_cap: Real,
    /// Static friction at resting contacts whose slip is below εf (off = paper mode).
    pub static_friction: bool,
    /// Clamp rule for friction that would reverse sliding.
    pub friction_clamp: FrictionClamp,
    /// Velocity bias at resting contacts: their target zeroes the approach speed within the substep
    /// and lets an open gap close without force, so they cannot drift (off = paper mode).
    pub velocity_bias: bool,
    /// Collision passes before the final e = 0 solve.
    pub collision_pass_cap: u32,
    /// Largest island solved by Baraff's exact method.
    pub exact_solver_max_rows: usize,
    /// Largest island that Baraff solves again when the iterative solver ends unconverged
    /// (0: never). Serialised parameters from before it existed read as 0.
    #[serde(default)]
    pub exact_fallback_max_rows: usize,
    /// Solver for larger islands.
    pub iterative_solver: IterativeSolver,
    /// Sweep cap of the coupled normal-and-friction Gauss–Seidel that polishes an iteratively
    /// solved island whose frictional contacts are all static and whose friction fixed point
    /// ended unconverged (0: never). Serialised parameters from before it existed read as 0.
    #[serde(default)]
    pub coupled_friction_sweeps: usize,
    /// A nonsmooth conjugate-gradient step (NNCG) after each forward–backward pair of the
    /// coupled polish's sweeps: the same answer in fewer sweeps on jammed piles. Serialised
    /// parameters from before it existed read as false, the polish they were run with.
    #[serde(default)]
    pub coupled_friction_nncg: bool,
    /// Residual tolerance of the iterative solvers as a factor of |g| (or of 9.81 if g = 0).
    pub solver_tolerance_factor: Real,
    /// Iteration cap of APGD and of MPRGP.
    pub apgd_max_iterations: usize,
    /// Iteration cap of PGS.
    pub pgs_max_iterations: usize,
    /// The approach-speed bound of the substep rule. Serialised parameters from before it
    /// existed read as `Speed`, the bound they were run with.
    #[serde(default = "ApproachBound::speed")]
    pub approach_bound: ApproachBound,
    /// The substep rule's slip: δt = `slip_fraction` · λ / v_max (then capped at `dt_cap`).
    /// Serialised parameters from before it existed read as 0.2, the rule they were run with.
    #[serde(default = "AccelerationParams::recorded_slip_fraction")]
    pub slip_fraction: Real,
}

impl Default for AccelerationParams {
    fn default() -> Self {
        Self {
            // εf = εp (`EngineParams::with_resting_band`).
            eps_f: 5e-3,
            dt_cap: 2.5e-4,
            static_friction: true,
            friction_clamp: FrictionClamp::Stick,
            velocity_bias: true,
            collision_pass_cap: 50,
            exact_solver_max_rows: EXACT_SOLVER_MAX_ROWS,
            exact_fallback_max_rows: EXACT_FALLBACK_MAX_ROWS,
            iterative_solver: IterativeSolver::Apgd,
            coupled_friction_sweeps: 1000,
            coupled_friction_nncg: true,
            solver_tolerance_factor: 1e-4,
            apgd_max_iterations: 200,
            pgs_max_iterations: 500,
            approach_bound: ApproachBound::Normal,
            slip_fraction: 0.2,
        }
    }
}

impl AccelerationParams {
    fn recorded_slip_fraction() -> Real {
        0.2
    }

    /// These parameters with the paper's contact model: dynamic friction only (none below εf),
    /// the zero clamp, no velocity bias.
    pub fn with_paper_contact_model(self) -> Self {
        Self { static_friction: false, friction_clamp: FrictionClamp::Zero, velocity_bias: false, ..self }
    }

    /// The paper's formulation: its contact model, every island up to 64 rows solved by
    /// Baraff's method, no exact fallback.
    pub fn paper() -> Self {
        Self { exact_solver_max_rows: 64, exact_fallback_max_rows: 0, ..Self::default().with_paper_contact_model() }
    }

    /// Rejects non-finite or non-positive values.
    pub fn validate(&self) -> Result<(), SimError> {
        positive("acceleration.eps_f", self.eps_f)?;
        positive("acceleration.dt_cap", self.dt_cap)?;
        positive("acceleration.solver_tolerance_factor", self.solver_tolerance_factor)?;
        if self.collision_pass_cap == 0 || self.apgd_max_iterations == 0 || self.pgs_max_iterations == 0 {
            return Err(SimError::InvalidParameter {
                name: "acceleration iteration caps",
                value: 0.0,
                reason: "must be >= 1",
            });
        }
        Ok(())
    }
}

/// The velocity-level stepper's parameters, in one place for `pack`, the benchmark and the
/// tests. Lengths are factors of the reference pellet size `d`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct VelocityParams {
    /// Longest step, s.
    pub max_step: Real,
    /// Largest relative surface travel of a near pair or wall over one step, factor of `d`:
    /// the step is `travel · d / s` with `s` the fastest near pair's bound.
    pub travel: Real,
    /// The solve stops when a sweep changes no contact's relative velocity by more than this
    /// factor of εp, or by more than `relative_tolerance` of the fastest pellet's speed if
    /// that is more: a bed in motion needs no better, and a bed coming to rest gets this. It
    /// also stops when eight sweeps move no body's velocity by more than a tenth of that
    /// tolerance (`dynamics/impulse_solve/sweep.rs`).
    pub tolerance_factor: Real,
    /// The solve's tolerance as a fraction of the fastest pellet's speed (see
    /// `tolerance_factor`).
    pub relative_tolerance: Real,
    /// Largest number of Gauss–Seidel sweeps per step.
    pub max_sweeps: usize,
    /// Radius of the patch each contact point stands for, factor of the nominal pellet size
    /// (`World::nominal_size`): it bounds the contact's spin torque at (3π/16) μ a λ_n and,
    /// except between two spheres, its rolling torque at a λ_n. 0: contact points turn freely.
    pub patch_radius: Real,
    /// Largest relative motion of a pair (or of a pellet against a wall) since its contacts
    /// were found over which position projection carries them with the bodies instead of
    /// evaluating them again, factor of `d` (`docs/engine.md`, "Contacts carried with their
    /// bodies"): a carried gap errs by at most twice that motion, a carried point's lever by
    /// that motion. 0, or `patch_radius` 0: always evaluated again.
    pub carry_drift: Real,
}

impl Default for VelocityParams {
    fn default() -> Self {
        Self {
            max_step: 1.25e-3,
            // Converged on a 300-cylinder pile where 0.025 was not (`docs/engine.md`,
            // "Convergence in the step").
            travel: 0.0125,
            tolerance_factor: 2e-7,
            relative_tolerance: 1e-2,
            max_sweeps: 1000,
            // A Hertz contact between 10 mm ceramic pellets under a few pellets' weight is about
            // that wide (`docs/engine.md`, "Contact points as small patches").
            patch_radius: 1e-3,
            // 1.4 µm for a 10 × 10 mm cylinder (d = 14.1 mm): twice it, the most a carried gap
            // errs by, is below the slop (2.5e-4 d) that projection leaves anyway.
            carry_drift: 1e-4,
        }
    }
}

impl VelocityParams {
    /// Rejects non-finite or non-positive values.
    pub fn validate(&self) -> Result<(), SimError> {
        positive("velocity.max_step", self.max_step)?;
        positive("velocity.travel", self.travel)?;
        positive("velocity.tolerance_factor", self.tolerance_factor)?;
        positive("velocity.relative_tolerance", self.relative_tolerance)?;
        if !(self.carry_drift >= 0.0 && self.carry_drift.is_finite()) {
            return Err(SimError::InvalidParameter {
                name: "velocity.carry_drift",
                value: self.carry_drift,
                reason: "must be finite and >= 0",
            });
        }
        if self.max_sweeps == 0 {
            return Err(SimError::InvalidParameter { name: "velocity.max_sweeps", value: 0.0, reason: "must be >= 1" });
        }
        Ok(())
    }
}

/// All tunables, SI units: the ones both steppers read, then each stepper's own. Lengths that
/// scale with the pellet are given as factors of the reference pellet size `d` = twice the
/// largest registered bounding radius. Nothing stores them (checkpoints hold the world's state,
/// not its parameters), so this layout need not read parameters serialised in the earlier one,
/// which had the two steppers' fields side by side.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EngineParams {
    /// Gravity, m/s². Default (0, 0, −9.81).
    pub gravity: Vec3,
    /// εp: normal-velocity band of resting contacts, m/s.
    pub eps_p: Real,
    /// λ as a factor of the bounding radius (proximity distance of the broad phase).
    pub proximity_factor: Real,
    /// Contact generation distance δ_c as a factor of `d`.
    pub contact_distance_factor: Real,
    /// Allowed penetration s_lop left alone by position projection, factor of `d`.
    pub slop_factor: Real,
    /// Penetration after a substep that triggers rewind-and-halve, factor of the nominal pellet
    /// size (`World::nominal_size`, the diameter; not the bounding diameter `d`).
    pub max_penetration_factor: Real,
    /// Largest |ω|·δt of one rotation sub-step.
    pub max_rotation_per_substep: Real,
    /// Largest number of rewind-and-halve attempts for one substep.
    pub max_rewinds: u32,
    /// The time-stepping scheme. Serialised parameters from before it existed read as
    /// `Acceleration`, the scheme they were run with.
    #[serde(default = "Stepper::recorded_default")]
    pub stepper: Stepper,
    /// Parameters of the force-level stepper (unused by the other).
    pub acceleration: AccelerationParams,
    /// Parameters of the velocity-level stepper (unused by the other).
    #[serde(default)]
    pub velocity: VelocityParams,
}

impl ApproachBound {
    fn speed() -> Self {
        Self::Speed
    }
}

impl Default for EngineParams {
    fn default() -> Self {
        Self {
            gravity: Vec3::new(0.0, 0.0, -STANDARD_GRAVITY),
            eps_p: 5e-3,
            proximity_factor: 0.1,
            contact_distance_factor: 1e-3,
            slop_factor: 2.5e-4,
            max_penetration_factor: 1e-2,
            max_rotation_per_substep: 0.01,
            max_rewinds: 8,
            stepper: Stepper::Velocity,
            acceleration: AccelerationParams::default(),
            velocity: VelocityParams::default(),
        }
    }
}

impl EngineParams {
    /// The paper's formulation: the force-level stepper with the paper's contact model
    /// ([`AccelerationParams::paper`]). The physics tests check it.
    pub fn paper() -> Self {
        Self { stepper: Stepper::Acceleration, acceleration: AccelerationParams::paper(), ..Self::default() }
    }

    /// These parameters with the resting band εp = `eps`, and εf = εp (below it the sliding
    /// direction is noise); the substep cap is lowered to εp/(2g) where that is below it (with
    /// g·δt_cap > εp/2 a body whose contact has just formed re-collides every substep). At the
    /// default εp it changes nothing.
    pub fn with_resting_band(self, eps: Real) -> Self {
        let g = self.gravity.norm();
        let acceleration =
            AccelerationParams { eps_f: eps, dt_cap: self.acceleration.dt_cap.min(0.5 * eps / g), ..self.acceleration };
        Self { eps_p: eps, acceleration, ..self }
    }

    /// Solver residual tolerance in m/s².
    pub fn solver_tolerance(&self) -> Real {
        let g = self.gravity.norm();
        let g = if g > 0.0 { g } else { STANDARD_GRAVITY };
        self.acceleration.solver_tolerance_factor * g
    }

    /// Rejects non-finite or non-positive values.
    pub fn validate(&self) -> Result<(), SimError> {
        if self.gravity.iter().any(|g| !g.is_finite()) {
            return Err(SimError::InvalidParameter {
                name: "gravity",
                value: self.gravity.norm(),
                reason: "must be finite",
            });
        }
        positive("eps_p", self.eps_p)?;
        positive("proximity_factor", self.proximity_factor)?;
        positive("contact_distance_factor", self.contact_distance_factor)?;
        positive("slop_factor", self.slop_factor)?;
        positive("max_penetration_factor", self.max_penetration_factor)?;
        positive("max_rotation_per_substep", self.max_rotation_per_substep)?;
        self.acceleration.validate()?;
        self.velocity.validate()
    }
}

/// Pellet–pellet material (each pair uses these values; no combining rule).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Material {
    /// Density, kg/m³.
    pub density: Real,
    /// Coefficient of restitution, 0..=1.
    pub cor: Real,
    /// Coulomb friction coefficient, ≥ 0.
    pub friction: Real,
}

/// Pellet–wall and pellet–floor material.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct WallMaterial {
    /// Coefficient of restitution, 0..=1.
    pub cor: Real,
    /// Coulomb friction coefficient, ≥ 0.
    pub friction: Real,
}

pub(crate) fn check_cor_mu(cor: Real, mu: Real) -> Result<(), SimError> {
    if !(cor.is_finite() && (0.0..=1.0).contains(&cor)) {
        return Err(SimError::InvalidParameter { name: "cor", value: cor, reason: "must lie in [0, 1]" });
    }
    if !(mu.is_finite() && mu >= 0.0) {
        return Err(SimError::InvalidParameter { name: "friction", value: mu, reason: "must be finite and >= 0" });
    }
    Ok(())
}

impl Material {
    /// Validates density, restitution and friction.
    pub fn validate(&self) -> Result<(), SimError> {
        positive("density", self.density)?;
        check_cor_mu(self.cor, self.friction)
    }
}

impl WallMaterial {
    /// Validates restitution and friction.
    pub fn validate(&self) -> Result<(), SimError> {
        check_cor_mu(self.cor, self.friction)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_keeps_its_own_resting_band_rule() {
        let d = EngineParams::default();
        assert_eq!(d.clone().with_resting_band(d.eps_p), d);
        assert_eq!(d.acceleration.dt_cap, 2.5e-4);
    }

    #[test]
    fn paper_is_the_force_level_stepper_with_the_paper_contact_model() {
        let p = EngineParams::paper();
        assert_eq!(p.stepper, Stepper::Acceleration);
        let a = p.acceleration;
        assert!(!a.static_friction && !a.velocity_bias);
        assert_eq!(a.friction_clamp, FrictionClamp::Zero);
        assert_eq!((a.exact_solver_max_rows, a.exact_fallback_max_rows), (64, 0));
        assert_eq!(
            EngineParams { stepper: Stepper::Velocity, acceleration: AccelerationParams::default(), ..p },
            EngineParams::default()
        );
    }
}
