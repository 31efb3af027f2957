//! Project tasks for palc, run as `cargo xtask <task>` from anywhere in the
//! workspace (the alias lives in `.cargo/config.toml`).
//!
//! `reproduce-paper` regenerates the paper's evaluation (`reproduce/`).
//! Repository hygiene lives in `tidy.rs` as ordinary tests, run by
//! `cargo test --workspace`.

use std::path::{Path, PathBuf};

mod reproduce;
#[cfg(test)]
mod tidy;

fn main() -> anyhow::Result<()> {
    std::env::set_current_dir(project_root())?;
    let task = std::env::args().nth(1);
    match task.as_deref() {
        None | Some("help" | "--help" | "-h") => {
            print_help();
            Ok(())
        }
        Some("reproduce-paper") => reproduce::main(std::env::args().skip(2)),
        Some(other) => {
            print_help();
            anyhow::bail!("unknown task `{other}`")
        }
    }
}

fn print_help() {
    println!(
        "cargo xtask <task>\n\ntasks:\n  \
         reproduce-paper  regenerate the paper's evaluation (--quick, --jobs N, --out DIR)\n  \
         help             this text"
    );
}

/// The workspace root: the parent of this crate's manifest directory.
fn project_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("xtask lives one level below the workspace root")
        .to_path_buf()
}
