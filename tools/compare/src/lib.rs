//! `compare`: scores packed beds against the literature's correlations.

use clap::Parser;
use pellet_cli::Outcome;

/// Score packed beds against literature correlations.
#[derive(Debug, Parser)]
#[command(name = "compare", version)]
pub struct Args {}

/// Runs the tool.
pub fn run(_args: Args) -> anyhow::Result<Outcome> {
    Ok(Outcome::Success)
}
