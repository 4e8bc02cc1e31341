//! Dynamics: integration, contact rows, the LCP solvers, the collision and resting phases and
//! position projection.

mod by_body;
pub mod collide;
pub mod coupled_pgs;
pub mod friction_guard;
mod friction_scatter;
pub mod friction_update;
pub mod impulse_solve;
pub mod integrator;
pub mod island_solve;
pub mod islands;
pub mod lcp;
mod linear_product;
pub mod polish_momentum;
pub mod resting;
pub mod rows;
pub mod stabilize;
