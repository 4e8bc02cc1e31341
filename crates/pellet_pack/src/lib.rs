//! How pellets enter the tube: the paper's loading schemes and a pack
//! run's configuration.
//!
//! - [`loading`]: the schemes (1, 2 or 4 columns, sock, dense), with seeded
//!   random disturbances of position and orientation;
//! - [`driver`]: the run itself — feeding, stepping the engine, streaming
//!   frames and energy records to a sink, stopping when settled;
//! - [`checkpoint`]: the state that continues a run bit for bit (`pack --resume`);
//! - [`config`]: every parameter of a `pack` run, with the paper's
//!   validation values as defaults, loadable from a TOML or JSON case file.
#![deny(missing_docs)]

mod case_file;
pub mod checkpoint;
pub mod config;
pub mod driver;
mod keys;
pub mod loading;
mod setup;

pub use checkpoint::{resume_conflicts, Checkpoint, RunState, CHECKPOINT_VERSION};
pub use config::{Amount, ClampRule, ContactModel, PackConfig, PackOptions, Stepper};
pub use driver::{
    check_setup, engine_params, resume_pack, run_pack, Ending, PackError, Progress, RunSink, RunSummary, SolverStats,
    SOLVER_WINDOW_S,
};
pub use loading::{batch_height_per_pellet, entry_height, Feeder, FeederState, LoadingScheme, Spawn};

/// A configuration value out of range; the message names the flag and the range.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct ConfigError(pub String);
