//! Collision geometry: the broad phase (candidate pairs) and the narrow phase (contact points).
//!
//! Public: the narrow phase's interface and the per-type geometry and cache it reads, which the
//! contact tests drive directly.

mod broad_phase;
pub(crate) mod carried;
pub(crate) mod contact;
mod contact_lateral;
pub(crate) mod contact_sampled;
mod contact_shape_wall;
pub(crate) mod contact_sphere_sphere;
mod contact_sphere_wall;
pub(crate) mod manifold;
pub mod narrow_phase;
pub(crate) mod pair_cache;
mod patch;
mod rim_refine;
pub mod sample_cache;
pub mod samples;
pub(crate) mod sdf;
