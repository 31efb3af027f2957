//! `palc export`: not yet built.

use clap::Args;

/// Arguments of `palc export`.
#[derive(Debug, Args)]
pub struct ExportArgs {}

/// Runs `palc export`.
pub fn run(_args: ExportArgs) -> anyhow::Result<()> {
    anyhow::bail!("palc export is not built yet")
}
