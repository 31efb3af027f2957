//! REPORT.md's "A drive of varied scenes" ([`crate::drive`]): per method and
//! user kind, the takeover rate over the drive's lane changes in bands, beside
//! the same lane changes from scratch ([`crate::drive_report`]).

use std::fmt::{self, Write as _};

use super::section::{Out, Results, Section, fill, header, state_targets};
use crate::drive_report::{BANDS, WINDOW, table_lines};
use crate::plan::Experiment;
use crate::targets::TargetId;

/// The drive section.
pub struct Drive;

impl Section for Drive {
    fn title(&self) -> &'static str {
        "A drive of varied scenes"
    }

    fn applies(&self, results: &Results) -> bool {
        (results.input.rows.iter()).any(|r| r.spec.experiment == Experiment::Drive)
    }

    fn render(&self, results: &Results, out: &mut Out) -> fmt::Result {
        let text = fill(
            include_str!("templates/drive.md"),
            &[("window", WINDOW.to_string())],
        );
        writeln!(out, "{text}\n")?;
        let bands: Vec<String> = (BANDS.iter())
            .map(|(first, last)| format!("lane changes {first}-{last}"))
            .collect();
        let mut columns = vec![
            "method", "user", "drives", "scenes", "driven", "refused", "failed",
        ];
        columns.extend(bands.iter().map(String::as_str));
        header(out, &columns)?;
        for line in table_lines(results.input.rows, results.methods()) {
            writeln!(out, "{line}")?;
        }
        writeln!(out)?;
        let ids = [TargetId::DriveOwnFamilies, TargetId::DriveOutOfClass];
        state_targets(out, results, &ids)?;
        writeln!(out)
    }
}
