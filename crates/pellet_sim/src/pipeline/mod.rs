//! The world state, the stepping pipeline and the energy ledger.

pub mod ledger;
mod proximity;
pub mod step;
pub mod velocity_step;
pub mod world;
