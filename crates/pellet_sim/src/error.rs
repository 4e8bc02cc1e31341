//! The engine's error type. Bad input is reported, never panicked on.

use thiserror::Error;

/// Everything that can go wrong when building or stepping a [`crate::World`].
#[derive(Debug, Error, Clone, PartialEq)]
pub enum SimError {
    /// A shape kind the narrow phase cannot handle yet.
    #[error("unsupported shape: {0}")]
    UnsupportedShape(String),
    /// A length, mass property or parameter that must be positive and finite is not.
    #[error("invalid parameter `{name}` = {value}: {reason}")]
    InvalidParameter {
        /// Parameter name.
        name: &'static str,
        /// The offending value.
        value: f64,
        /// Why it is rejected.
        reason: &'static str,
    },
    /// A body-type id that was never registered.
    #[error("unknown body type id {0}")]
    UnknownBodyType(u32),
    /// The container cannot hold a pellet of this size.
    #[error("container too small: tube radius {tube_radius} m, pellet bounding radius {pellet_radius} m")]
    ContainerTooSmall {
        /// Inner tube radius, m.
        tube_radius: f64,
        /// Pellet bounding radius, m.
        pellet_radius: f64,
    },
    /// A body was placed outside the container or overlapping a wall.
    #[error("body placed outside the container at ({x}, {y}, {z})")]
    OutsideContainer {
        /// x, m.
        x: f64,
        /// y, m.
        y: f64,
        /// z, m.
        z: f64,
    },
    /// A non-finite value appeared in the state (should not happen; reported instead of spreading NaN).
    #[error("non-finite state in body {0}")]
    NonFiniteState(u32),
}
