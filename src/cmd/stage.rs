//! `frf stage`: the virtual light stage.

use clap::Args;

use crate::CliResult;

/// Arguments of `frf stage`.
#[derive(Args)]
pub struct StageArgs {}

/// Runs `frf stage`.
pub fn run(_args: StageArgs) -> CliResult {
    Err("frf stage: not built yet".into())
}
