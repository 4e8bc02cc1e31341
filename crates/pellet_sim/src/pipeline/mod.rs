//! The world state, the stepping pipeline and the energy ledger.

pub mod ledger;
pub mod step;
pub mod world;
