//! The world and its stepping: the world state, one step of either stepper, position projection
//! as both call it, the narrow phase on several threads, and the energy ledger.

mod acceleration_step;
mod ledger;
mod projection;
mod proximity;
mod speculative;
mod step;
mod threads;
mod velocity_step;
mod world;

pub use ledger::EnergyLedger;
pub use step::{ContactRecord, Pipeline, StepReport, WarmForce, WarmImpulse};
pub use world::{World, WorldState};
