//! REPORT.md's run manifest: version, commit, config hash, subset, seeds, runs,
//! threads, machine and wall time (`manifest.json` holds the same).

use std::fmt::{self, Write as _};

use super::section::{Out, Results, Section};

/// The run-manifest section.
pub struct RunManifest;

impl Section for RunManifest {
    fn title(&self) -> &'static str {
        "Run manifest"
    }

    fn render(&self, results: &Results, out: &mut Out) -> fmt::Result {
        let m = results.input.manifest;
        writeln!(out, "| | |\n| --- | --- |")?;
        let rows = [
            ("palc version", m.palc_version.clone()),
            (
                "git commit",
                match (&m.git_commit, m.git_dirty) {
                    (Some(c), Some(true)) => format!("{c} (with local changes)"),
                    (Some(c), _) => c.clone(),
                    (None, _) => "unknown (no git)".to_owned(),
                },
            ),
            ("config SHA-256", format!("`{}`", m.config_sha256)),
            ("config", format!("`{}` + `{}`", m.config_path, m.base_path)),
            ("subset", if m.quick { "quick" } else { "full" }.to_owned()),
            ("seeds", format!("{:?}", m.seeds)),
            ("runs", m.runs.to_string()),
            ("threads", m.threads.to_string()),
            (
                "machine",
                format!("{}, {} logical cores", m.machine, m.cores),
            ),
            ("wall time", format!("{:.1} s", m.wall_s)),
        ];
        for (k, v) in rows {
            writeln!(out, "| {k} | {v} |")?;
        }
        writeln!(out)
    }
}
