//! `palc import`: not yet built.

use clap::Args;

/// Arguments of `palc import`.
#[derive(Debug, Args)]
pub struct ImportArgs {}

/// Runs `palc import`.
pub fn run(_args: ImportArgs) -> anyhow::Result<()> {
    anyhow::bail!("palc import is not built yet")
}
