//! Project tasks for palc, run as `cargo xtask <task>` from anywhere in the
//! workspace (the alias lives in `.cargo/config.toml`).
//!
//! xtask only orchestrates: `reproduce-paper` runs the product's own command,
//! `palc eval`, in a release build, so the evaluation lives in one place
//! (`crates/palc-eval`) and the task and the command give the same outputs: the
//! paper's set-up (`configs/reproduce.toml`), then the same with the ACC and the
//! safety layer (`configs/reproduce-safe.toml`, into `safe/`), the stress scenes
//! (`configs/stress/`, into `stress/<scene>/`) and `palc` on held-out seeds
//! (`configs/reproduce-held-out.toml`, into `held-out/`).
//! `test` runs every test: `cargo test --workspace`, then the Python checks of
//! the CommonRoad export (`test_all.rs`).
//! Repository hygiene lives in `tidy.rs` as ordinary tests, run by
//! `cargo test --workspace`.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::Context;

mod test_all;
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
        Some("test") => test_all::run(args),
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
         the same as `palc eval` in a release build, then (without --config)\n                   \
         configs/reproduce-safe.toml into DIR/safe, configs/stress/* into DIR/stress\n                   \
         and configs/reproduce-held-out.toml into DIR/held-out\n  \
         test             every test: cargo test --workspace, then the Python checks of the\n                   \
         CommonRoad export (a venv in target/venv, palc export commonroad, pytest python);\n                   \
         --python runs only the Python checks\n  \
         help             this text"
    );
}

/// `cargo xtask reproduce-paper [flags]`: `palc eval [flags]`, built in release mode;
/// without `--config`, then the same evaluation with the ego's ACC, the safety layer
/// and users who wait for safe gaps, the stress scenes under the same set-up, and
/// `palc` on held-out seeds ([`COMPANIONS`]), each written to its directory under
/// the output directory.
fn reproduce_paper(args: impl Iterator<Item = String>) -> anyhow::Result<()> {
    let args: Vec<String> = args.collect();
    palc_eval(&args)?;
    if args
        .iter()
        .any(|a| a == "--config" || a.starts_with("--config="))
    {
        return Ok(());
    }
    let mut out = PathBuf::from(DEFAULT_OUT);
    let mut rest_args = Vec::new();
    let mut rest = args.iter();
    while let Some(arg) = rest.next() {
        if arg == "--out" {
            out = rest.next().map_or(out, PathBuf::from);
        } else if let Some(dir) = arg.strip_prefix("--out=") {
            out = PathBuf::from(dir);
        } else {
            rest_args.push(arg.clone());
        }
    }
    for (config, dir) in COMPANIONS {
        let mut companion = rest_args.clone();
        companion.extend([
            "--config".to_owned(),
            config.to_owned(),
            "--out".to_owned(),
            out.join(dir).display().to_string(),
        ]);
        palc_eval(&companion)?;
    }
    Ok(())
}

/// `palc eval`'s default output directory.
const DEFAULT_OUT: &str = "target/reproduce-paper";

/// The evaluations run after the paper's set-up, and their directories under the
/// output directory: the ego's ACC, the safety layer and users who wait for safe
/// gaps, then the stress scenes under the same set-up, then `palc` on seeds no
/// figure uses.
const COMPANIONS: [(&str, &str); 5] = [
    ("configs/reproduce-safe.toml", "safe"),
    (
        "configs/stress/braking-leader-eval.toml",
        "stress/braking-leader",
    ),
    (
        "configs/stress/accelerating-lag-eval.toml",
        "stress/accelerating-lag",
    ),
    ("configs/stress/dense-eval.toml", "stress/dense"),
    ("configs/reproduce-held-out.toml", "held-out"),
];

/// `palc eval ARGS` in a release build.
fn palc_eval(args: &[String]) -> anyhow::Result<()> {
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
