//! The run manifest: what was run, from which code and config, on what machine.

use std::process::Command;

use serde::Serialize;
use sha2::{Digest, Sha256};

/// Everything needed to tell whether two reports are comparable.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Manifest {
    /// palc's version (the workspace version).
    pub palc_version: String,
    /// `git rev-parse HEAD`, if git and a repository are there.
    pub git_commit: Option<String>,
    /// Whether the work tree had changes to tracked files.
    pub git_dirty: Option<bool>,
    /// SHA-256 of the reproduction config followed by the base learning config.
    pub config_sha256: String,
    /// Path of the reproduction config.
    pub config_path: String,
    /// Path of the base learning config.
    pub base_path: String,
    /// Whether this was the `--quick` subset.
    pub quick: bool,
    /// Scene seeds of the grid.
    pub seeds: Vec<u64>,
    /// Worker threads.
    pub threads: usize,
    /// Logical cores of the machine.
    pub cores: usize,
    /// Operating system and architecture.
    pub machine: String,
    /// Runs made.
    pub runs: usize,
    /// Wall time of all runs (s).
    pub wall_s: f64,
}

/// Hex SHA-256 of the texts, in order, each followed by a NUL byte so that
/// moving text from one file to the next changes the hash.
pub fn config_hash(texts: &[&str]) -> String {
    let mut hasher = Sha256::new();
    for text in texts {
        hasher.update(text.as_bytes());
        hasher.update([0u8]);
    }
    hasher
        .finalize()
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// The current commit and whether tracked files changed; `None` without git.
pub fn git_state() -> (Option<String>, Option<bool>) {
    let commit = Command::new("git")
        .args(["rev-parse", "HEAD"])
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_owned());
    let dirty = Command::new("git")
        .args(["status", "--porcelain", "--untracked-files=no"])
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| !o.stdout.is_empty());
    (commit, dirty)
}

/// palc's version: the workspace version every palc crate carries.
pub fn palc_version() -> String {
    env!("CARGO_PKG_VERSION").to_owned()
}

/// Logical cores, or 1 when unknown.
pub fn cores() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// Operating system and architecture.
pub fn machine() -> String {
    format!("{} {}", std::env::consts::OS, std::env::consts::ARCH)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_config_hash_is_stable_and_sensitive() {
        let a = config_hash(&["grid", "base"]);
        assert_eq!(a, config_hash(&["grid", "base"]));
        assert_eq!(a.len(), 64);
        assert_ne!(a, config_hash(&["grid", "base "]));
        assert_ne!(a, config_hash(&["gridb", "ase"]));
        // SHA-256 of the empty string, as a known answer.
        assert_eq!(
            config_hash(&[]),
            "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855"
        );
    }
}
