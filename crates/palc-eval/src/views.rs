//! The experiments of Section III as views of the runs: which rows each table
//! and figure uses.

use palc_harness::Method;

use crate::plan::Experiment;
use crate::results::RunRow;

/// A figure written to the output directory.
#[derive(Debug, Clone, PartialEq)]
pub struct FigureFile {
    /// File stem; `stem.svg` and `stem.png` exist.
    pub stem: String,
    /// What it shows.
    pub caption: String,
}

/// The grid rows (no experience) of one method and user kind, in plan order.
pub fn grid<'a>(rows: &'a [RunRow], method: Method, user: &str) -> Vec<&'a RunRow> {
    rows.iter()
        .filter(|r| {
            r.spec.experiment == Experiment::Grid
                && r.spec.method == method
                && r.spec.user.name == user
        })
        .collect()
}

/// Grid and transfer rows of one method and user kind.
pub fn with_transfer<'a>(rows: &'a [RunRow], method: Method, user: &str) -> Vec<&'a RunRow> {
    rows.iter()
        .filter(|r| {
            matches!(r.spec.experiment, Experiment::Grid | Experiment::Transfer)
                && r.spec.method == method
                && r.spec.user.name == user
        })
        .collect()
}

/// The timing rows of one method.
pub fn timing(rows: &[RunRow], method: Method) -> Vec<&RunRow> {
    rows.iter()
        .filter(|r| r.spec.experiment == Experiment::Timing && r.spec.method == method)
        .collect()
}

/// A name usable in a file name.
pub fn slug(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '-'
            }
        })
        .collect::<String>()
        .trim_matches('-')
        .to_owned()
}

/// Speed-case label with its speeds.
pub fn speed_label(row: &RunRow) -> String {
    let case = &row.spec.speed_case;
    format!(
        "{} ({:.0}/{:.0} mph)",
        case.name, case.ego_mph, case.others_mph
    )
}

/// Pairs of the grid row and the closed-loop row of the same cell, for one
/// method and user kind, in plan order.
pub fn closed_loop_pairs<'a>(
    rows: &'a [RunRow],
    method: Method,
    user: &str,
) -> Vec<(&'a RunRow, &'a RunRow)> {
    let open = grid(rows, method, user);
    rows.iter()
        .filter(|r| {
            r.spec.experiment == Experiment::ClosedLoop
                && r.spec.method == method
                && r.spec.user.name == user
        })
        .filter_map(|closed| {
            let cell = closed.spec.experiment_cell();
            (open.iter())
                .find(|o| o.spec.experiment_cell() == cell)
                .map(|&o| (o, closed))
        })
        .collect()
}
