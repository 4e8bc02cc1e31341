//! Dynamics: integration, contact rows, the LCP solvers, the collision and resting phases and
//! position projection.
//!
//! Public: the integrator, the contact rows and the LCP solvers, which the solver tests drive
//! directly, and the projection's gap bounds that `World::gap_bounds` returns.

mod by_body;
pub(crate) mod collide;
mod coupled_pgs;
mod friction_guard;
mod friction_scatter;
mod friction_update;
pub(crate) mod impulse_solve;
pub mod integrator;
mod island_solve;
mod islands;
pub mod lcp;
mod linear_product;
mod polish_momentum;
pub(crate) mod resting;
pub mod rows;
pub(crate) mod stabilize;

pub use stabilize::GapBounds;
