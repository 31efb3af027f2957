//! `palc drive`: a browser driving study (the `palc-drive` crate). Parses the
//! arguments, opens the session and prints the page's URL.

use std::net::SocketAddr;
use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use palc_drive::{Protocol, Session};

use crate::console::say;

/// Arguments of `palc drive`.
#[derive(Debug, Args)]
pub struct DriveArgs {
    /// The study protocol (TOML): participant, scenes, stopping rules.
    #[arg(long)]
    protocol: PathBuf,
    /// The directory of the session's record, experience and scene runs.
    #[arg(long, default_value = "target/drive")]
    out: PathBuf,
    /// The address to serve the page on; local only by default.
    #[arg(long, default_value = "127.0.0.1:8080")]
    bind: SocketAddr,
    /// Go on with the session recorded in `--out` from its last completed lane change.
    #[arg(long)]
    resume: bool,
}

/// Runs `palc drive` until it is stopped.
pub fn run(args: DriveArgs) -> anyhow::Result<()> {
    let (protocol, config) = Protocol::load(&args.protocol)?;
    let session = Session::open(protocol, config, &args.out, args.resume)
        .with_context(|| format!("cannot open the session in {}", args.out.display()))?;
    palc_drive::run_blocking(args.bind, session, |url| {
        say!(
            "palc drive: open {url} in a browser (the record goes to {})",
            args.out.display()
        );
    })?;
    Ok(())
}
