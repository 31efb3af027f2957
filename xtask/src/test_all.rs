//! `cargo xtask test`: every test of the project, Rust and Python.
//!
//! First Chromium and its WebDriver for the real-browser test (installed as
//! root when missing), then `cargo test --workspace`; then the Python checks of the CommonRoad
//! export: a virtual environment in `target/venv` (created once, its packages
//! installed again only when `python/requirements-test.txt` changes), a release
//! build of `palc`, `palc export commonroad` for the default scene and the grid
//! into `target/commonroad-export`, and `pytest python/commonroad`, which writes
//! `target/commonroad-check/SUMMARY.md`. Last, the Python package: `maturin
//! develop --release` into the same venv and `pytest python/tests`, which compares
//! it with the `palc` binary just built and runs `mypy.stubtest`, which fails when
//! the hand-written stubs no longer match the native module.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::Context;

/// The pinned Python packages of the checks.
const REQUIREMENTS: &str = "python/requirements-test.txt";
/// Where the exports go, under the target directory.
const EXPORT_DIR: &str = "commonroad-export";

/// Runs every test; fails on the first step that fails. With `--python`, only
/// the Python checks (and what they need).
pub fn run(args: impl Iterator<Item = String>) -> anyhow::Result<()> {
    let mut python_only = false;
    for arg in args {
        match arg.as_str() {
            "--python" => python_only = true,
            other => {
                anyhow::bail!("unknown argument `{other}` of `cargo xtask test` (only `--python`)")
            }
        }
    }
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let target =
        std::env::var_os("CARGO_TARGET_DIR").map_or_else(|| PathBuf::from("target"), PathBuf::from);

    if !python_only {
        browser()?;
        heading("cargo test --workspace (the Rust tests)");
        status(
            Command::new(&cargo).args(["test", "--workspace"]),
            "cargo test --workspace",
        )?;
    }

    heading("Python environment for the CommonRoad checks and the package (target/venv)");
    let venv_dir = target.join("venv");
    let python = venv(&venv_dir)?;

    heading("palc export commonroad (release build; the default scene and the grid)");
    status(
        Command::new(&cargo).args([
            "build",
            "--release",
            "--package",
            "palc-cli",
            "--bin",
            "palc",
        ]),
        "cargo build --release -p palc-cli",
    )?;
    let palc = target
        .join("release")
        .join(format!("palc{}", std::env::consts::EXE_SUFFIX));
    let export = target.join(EXPORT_DIR);
    if export.exists() {
        std::fs::remove_dir_all(&export)
            .with_context(|| format!("cannot remove the old exports in {}", export.display()))?;
    }
    for (dir, grid) in [("default", false), ("grid", true)] {
        let out = export.join(dir);
        let mut command = Command::new(&palc);
        command.args([
            "export",
            "commonroad",
            "--config",
            "configs/learn.toml",
            "--out",
        ]);
        command.arg(&out);
        if grid {
            command.arg("--grid");
        }
        status(&mut command, "palc export commonroad")?;
    }

    heading("pytest python/commonroad (commonroad-io and the drivability checker)");
    status(
        Command::new(&python)
            .args([
                "-m",
                "pytest",
                "python/commonroad",
                "-q",
                "-p",
                "no:cacheprovider",
            ])
            .env("PALC_COMMONROAD_EXPORT", &export)
            .env(
                "PALC_COMMONROAD_SUMMARY",
                target.join("commonroad-check").join("SUMMARY.md"),
            ),
        "pytest python/commonroad",
    )?;

    python_package(&python, &venv_dir, &target, &palc)?;
    println!(
        "\nall tests passed; the KS feasibility of the grid is in target/commonroad-check/SUMMARY.md"
    );
    Ok(())
}

/// The Python package: built into `venv` by maturin (release), then its tests, which
/// compare it with the `palc` binary and check its stubs with `mypy.stubtest`.
fn python_package(python: &Path, venv: &Path, target: &Path, palc: &Path) -> anyhow::Result<()> {
    let absolute = |p: &Path| {
        std::path::absolute(p).with_context(|| format!("cannot resolve {}", p.display()))
    };
    heading("the Python package (maturin develop --release into target/venv)");
    let maturin = ["-m", "maturin", "develop", "--release", "--quiet"];
    let mut command = Command::new(python);
    command.args(maturin).env("VIRTUAL_ENV", absolute(venv)?);
    status(
        command.env("CARGO_TARGET_DIR", target),
        "maturin develop --release",
    )?;

    heading("pytest python/tests (the palc package against the palc binary, its stubs)");
    let pytest = [
        "-m",
        "pytest",
        "python/tests",
        "-q",
        "-p",
        "no:cacheprovider",
    ];
    let mut command = Command::new(python);
    status(
        command.args(pytest).env("PALC_BIN", absolute(palc)?),
        "pytest python/tests",
    )
}

fn heading(text: &str) {
    println!("\n== {text}");
}

/// Runs `command` and fails, naming `what`, unless it succeeds.
fn status(command: &mut Command, what: &str) -> anyhow::Result<()> {
    let status = command
        .status()
        .with_context(|| format!("cannot run `{what}`"))?;
    anyhow::ensure!(status.success(), "`{what}` failed ({status})");
    Ok(())
}

/// The venv's Python, the venv created (or reused) and its packages installed
/// when the requirements changed since the last install.
fn venv(dir: &Path) -> anyhow::Result<PathBuf> {
    let python = dir.join("bin").join("python");
    if !python.is_file() {
        create_venv(dir)?;
    }
    let requirements = std::fs::read_to_string(REQUIREMENTS)
        .with_context(|| format!("cannot read {REQUIREMENTS}"))?;
    let stamp = dir.join("requirements-test.installed");
    if std::fs::read_to_string(&stamp).ok().as_deref() == Some(requirements.as_str()) {
        println!(
            "reusing {} (its packages match {REQUIREMENTS})",
            dir.display()
        );
        return Ok(python);
    }
    status(
        Command::new(&python).args([
            "-m",
            "pip",
            "install",
            "--quiet",
            "--disable-pip-version-check",
            "-r",
            REQUIREMENTS,
        ]),
        "pip install -r python/requirements-test.txt",
    )?;
    std::fs::write(&stamp, requirements)
        .with_context(|| format!("cannot write {}", stamp.display()))?;
    Ok(python)
}

/// `python3 -m venv DIR`; on a CI machine as root, Debian's `python3-venv` is
/// installed first when it is missing, elsewhere the error says what to install.
fn create_venv(dir: &Path) -> anyhow::Result<()> {
    let found = Command::new("python3").arg("--version").output();
    if !found.is_ok_and(|o| o.status.success()) {
        anyhow::bail!(
            "python3 is missing: the CommonRoad checks need Python 3.11 or later with venv \
             (e.g. `apt-get install python3 python3-venv`)"
        );
    }
    if make_venv(dir)? {
        return Ok(());
    }
    if std::env::var_os("CI").is_some() && is_root() {
        println!("python3 cannot create a venv: installing python3-venv with apt-get (CI, root)");
        status(Command::new("apt-get").arg("update"), "apt-get update")?;
        status(
            Command::new("apt-get").args(["install", "-y", "python3-venv"]),
            "apt-get install -y python3-venv",
        )?;
        if make_venv(dir)? {
            return Ok(());
        }
    }
    anyhow::bail!(
        "`python3 -m venv {}` failed: install Python's venv module (e.g. `apt-get install python3-venv`)",
        dir.display()
    )
}

/// The real-browser test's Chromium and WebDriver (Debian's `chromium`, `chromium-driver`):
/// installed with apt-get as root when missing, else a notice that the test will skip.
fn browser() -> anyhow::Result<()> {
    let found = |bin: &str| {
        Command::new(bin)
            .arg("--version")
            .output()
            .is_ok_and(|o| o.status.success())
    };
    if found("chromium") && found("chromedriver") {
        return Ok(());
    }
    if !is_root() {
        println!(
            "NOTICE: chromium or chromedriver is missing and this is not root: the real-browser test \
                  (crates/palc-drive/tests/browser.rs) will be SKIPPED; install `chromium chromium-driver`"
        );
        return Ok(());
    }
    heading("apt-get install chromium chromium-driver (the real-browser test)");
    status(Command::new("apt-get").arg("update"), "apt-get update")?;
    let install = ["install", "-y", "chromium", "chromium-driver"];
    status(
        Command::new("apt-get").args(install),
        "apt-get install -y chromium chromium-driver",
    )
}

/// Whether `python3 -m venv DIR` made a venv; a half-made one is removed.
fn make_venv(dir: &Path) -> anyhow::Result<bool> {
    let made = Command::new("python3")
        .args(["-m", "venv"])
        .arg(dir)
        .status()
        .context("cannot run python3")?
        .success()
        && dir.join("bin").join("python").is_file();
    if !made && dir.exists() {
        std::fs::remove_dir_all(dir).with_context(|| format!("cannot remove {}", dir.display()))?;
    }
    Ok(made)
}

/// Whether the process runs as root (Linux: the real UID in /proc/self/status).
fn is_root() -> bool {
    std::fs::read_to_string("/proc/self/status").is_ok_and(|status| {
        status
            .lines()
            .find_map(|line| line.strip_prefix("Uid:"))
            .and_then(|uids| uids.split_whitespace().next())
            == Some("0")
    })
}
