//! The world state, the stepping pipeline and the energy ledger.

mod acceleration_step;
pub mod ledger;
mod projection;
mod proximity;
pub mod step;
pub mod velocity_step;
pub mod world;
