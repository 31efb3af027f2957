//! `palc drive`: a browser driving study in which palc learns from a person's
//! takeovers.
//!
//! A local web server ([`serve`]) shows the scene from above in a page embedded
//! in the binary (no build step, no CDN, works offline). The person takes over
//! with a key or a gamepad and then steers (a lateral-speed command within
//! physical limits) and sets the speed; what they drove is the lesson, exactly as
//! a simulated user's (`palc_harness::live`). A study [`Protocol`] (TOML) lists
//! the scenes and their stopping rules. Nothing is lost: the [`record`] is an
//! append-only JSONL file synced at the end of every lane change, the experience
//! is written atomically after every lesson, every scene's run is written in
//! `palc learn --record`'s format, and a killed session resumes at its last
//! completed lane change ([`Session::open`] with `resume`).
//!
//! ```no_run
//! use std::path::Path;
//! use palc_drive::{Protocol, Session};
//!
//! let (protocol, config) = Protocol::load(Path::new("study.toml"))?;
//! let session = Session::open(protocol, config, Path::new("target/study"), false)?;
//! palc_drive::run_blocking("127.0.0.1:8080".parse()?, session, |url| println!("{url}"))?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![deny(missing_docs)]
#![warn(clippy::print_stdout, clippy::print_stderr)]
#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]

pub mod control;
mod error;
pub mod protocol;
pub mod record;
mod server;
mod session;

use std::net::SocketAddr;

pub use error::DriveError;
pub use protocol::Protocol;
pub use server::serve;
pub use session::{EXPERIENCE_FILE, Frame, Phase, RECORD_FILE, Session};

/// Binds `bind`, tells `ready` the page's URL, and serves `session` until the
/// process ends, on a runtime of its own.
///
/// # Errors
/// [`DriveError::Io`] when the address cannot be bound or the server fails.
pub fn run_blocking(
    bind: SocketAddr,
    session: Session,
    ready: impl FnOnce(String),
) -> Result<(), DriveError> {
    let io = |source| DriveError::Io {
        path: bind.to_string().into(),
        source,
    };
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .map_err(io)?;
    runtime.block_on(async {
        let listener = tokio::net::TcpListener::bind(bind).await.map_err(io)?;
        let address = listener.local_addr().map_err(io)?;
        ready(format!("http://{address}/"));
        serve(listener, session).await
    })
}
