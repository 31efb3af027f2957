//! Project tasks for palc, run as `cargo xtask <task>` from anywhere in the
//! workspace (the alias lives in `.cargo/config.toml`).
//!
//! xtask only orchestrates: `reproduce-paper` runs the product's own command,
//! `palc eval`, in a release build, so the evaluation lives in one place
//! (`crates/palc-eval`) and the task and the command give the same outputs.
//! Repository hygiene lives in `tidy.rs` as ordinary tests, run by
//! `cargo test --workspace`.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::Context;

#[cfg(test)]
mod tidy;

fn main() -> anyhow::Result<()> {
    let root = project_root();
    std::env::set_current_dir(&root)
        .with_context(|| format!("cannot enter the workspace root {}", root.display()))?;
    let mut args = std::env::args().skip(1);
    let task = args.next();
    match task.as_deref() {
        None | Some("help" | "--help" | "-h") => {
            print_help();
            Ok(())
        }
        Some("reproduce-paper") => reproduce_paper(args),
        Some(other) => {
            print_help();
            anyhow::bail!("unknown task `{other}`")
        }
    }
}

fn print_help() {
    println!(
        "cargo xtask <task>\n\ntasks:\n  \
         reproduce-paper  regenerate the paper's evaluation (--quick, --jobs N, --out DIR, --config FILE);\n                   \
         the same as `palc eval` in a release build\n  \
         help             this text"
    );
}

/// `cargo xtask reproduce-paper [flags]`: `palc eval [flags]`, built in release mode.
fn reproduce_paper(args: impl Iterator<Item = String>) -> anyhow::Result<()> {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let status = Command::new(cargo)
        .args([
            "run",
            "--release",
            "--package",
            "palc-cli",
            "--bin",
            "palc",
            "--",
        ])
        .arg("eval")
        .args(args)
        .status()
        .context("cannot run cargo")?;
    anyhow::ensure!(status.success(), "`palc eval` failed ({status})");
    Ok(())
}

/// The workspace root: the parent of this crate's manifest directory.
fn project_root() -> PathBuf {
    let manifest_dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    manifest_dir.parent().unwrap_or(manifest_dir).to_path_buf()
}
