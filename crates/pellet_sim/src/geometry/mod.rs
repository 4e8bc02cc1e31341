//! Collision geometry: the broad phase (candidate pairs) and the narrow phase (contact points).

pub mod broad_phase;
pub mod contact;
pub(crate) mod contact_lateral;
pub mod contact_sampled;
pub mod contact_shape_wall;
pub mod contact_sphere_sphere;
pub mod contact_sphere_wall;
pub mod narrow_phase;
pub mod pair_cache;
pub mod patch;
pub mod sample_cache;
pub mod samples;
pub mod sdf;
