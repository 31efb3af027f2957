//! REPORT.md's refusals: refused runs counted by kind and experiment (every
//! refused run is in `refusals.csv`), the experiments that measured nothing,
//! then the runs that stopped on an error, counted by the error's kind (its
//! first clause, e.g. `problem is infeasible`; every one is in `runs.csv` with
//! its message).

use std::fmt::{self, Write as _};

use crate::results::Status;

use super::section::{Out, Results, Section};

/// The refusals section.
pub struct Refusals;

impl Section for Refusals {
    fn title(&self) -> &'static str {
        "Refused scenarios and failed runs"
    }

    fn render(&self, results: &Results, out: &mut Out) -> fmt::Result {
        let rows = results.input.rows;
        let refused: Vec<Counted> = (rows.iter())
            .filter_map(|row| match &row.status {
                Status::Refused { reason, .. } => Some(Counted {
                    kind: format!("`{}`", row.status.refusal_kind()?),
                    experiment: row.spec.experiment.name(),
                    example: reason.clone(),
                }),
                _ => None,
            })
            .collect();
        let failed: Vec<Counted> = (rows.iter())
            .filter_map(|row| match &row.status {
                Status::Failed { error } => Some(Counted {
                    kind: failure_kind(error).to_owned(),
                    experiment: row.spec.experiment.name(),
                    example: format!("`{}`: {error}", row.spec.label()),
                }),
                _ => None,
            })
            .collect();
        writeln!(
            out,
            "{} of {} runs were refused before running (not counted in the statistics above), \
             {} stopped on an error (counted as failures at the cap). Every refused run, with its \
             message, is in `refusals.csv`.\n",
            refused.len(),
            rows.len(),
            failed.len()
        )?;
        let idle = results.input.idle;
        if !idle.is_empty() {
            writeln!(
                out,
                "**Experiments that measured nothing** (`palc eval` exits non-zero; a scene built to \
                 refuse lists its refusal kinds in the config's `expected_refusals`):\n"
            )?;
            for experiment in idle {
                writeln!(out, "- {experiment}")?;
            }
            writeln!(out)?;
        }
        kind_table(out, "kind", &refused)?;
        if !failed.is_empty() {
            writeln!(
                out,
                "Runs that stopped on an error, by the error's kind (the full messages are in `runs.csv`):\n"
            )?;
            kind_table(out, "error", &failed)?;
        }
        Ok(())
    }
}

/// A run counted in a table by kind and experiment.
struct Counted {
    kind: String,
    experiment: &'static str,
    /// The message of the first run of its kind.
    example: String,
}

/// Longest example message in a table cell (characters); the full one is in the
/// CSV files.
const EXAMPLE_CHARS: usize = 240;

/// One line per kind (in order of first appearance): its count in each
/// experiment, the total and the first run's message; nothing without runs.
fn kind_table(out: &mut Out, header: &str, runs: &[Counted]) -> fmt::Result {
    let mut experiments: Vec<&str> = Vec::new();
    let mut kinds: Vec<&Counted> = Vec::new();
    for run in runs {
        if !experiments.contains(&run.experiment) {
            experiments.push(run.experiment);
        }
        if !kinds.iter().any(|k| k.kind == run.kind) {
            kinds.push(run);
        }
    }
    if kinds.is_empty() {
        return Ok(());
    }
    writeln!(
        out,
        "| {header} | {} | total | example |",
        experiments.join(" | ")
    )?;
    writeln!(out, "|{}", " --- |".repeat(experiments.len() + 3))?;
    for first in kinds {
        let of_kind: Vec<&Counted> = runs.iter().filter(|r| r.kind == first.kind).collect();
        let cells: Vec<String> = (experiments.iter())
            .map(|&e| {
                of_kind
                    .iter()
                    .filter(|r| r.experiment == e)
                    .count()
                    .to_string()
            })
            .collect();
        writeln!(
            out,
            "| {} | {} | {} | {} |",
            first.kind.replace('|', "\\|"),
            cells.join(" | "),
            of_kind.len(),
            shorten(&first.example).replace('|', "\\|")
        )?;
    }
    writeln!(out)
}

/// `text` up to [`EXAMPLE_CHARS`] characters, with `…` when cut.
fn shorten(text: &str) -> String {
    match text.char_indices().nth(EXAMPLE_CHARS) {
        Some((end, _)) => format!("{}…", &text[..end]),
        None => text.to_owned(),
    }
}

/// The kind of a run's error: its first clause (`what failed`), without the
/// scenario it names first (`scenario <label>: `), the details after the next
/// colon and the numbers in brackets, so that one cause is one line whatever
/// scene it happened in.
fn failure_kind(error: &str) -> &str {
    let what = match error.strip_prefix("scenario ") {
        Some(rest) => rest.split_once(": ").map_or(error, |(_, what)| what),
        None => error,
    };
    let clause = what.split_once(": ").map_or(what, |(kind, _)| kind);
    clause
        .split_once(" (")
        .map_or(clause, |(kind, _)| kind)
        .trim_end()
}

#[cfg(test)]
mod tests {
    use super::failure_kind;

    #[test]
    fn an_errors_kind_leaves_out_its_scenario_details_and_numbers() {
        let off_road = "scenario collector-high / 50 m / seed 2 / aggressive: the experience's weights plan \
                        the first lane change off the road (l = -4.11 m at step 12)";
        assert_eq!(
            failure_kind(off_road),
            "the experience's weights plan the first lane change off the road"
        );
        let solver = "problem is infeasible: lateral bounds at steps 170 cannot hold";
        assert_eq!(failure_kind(solver), "problem is infeasible");
        assert_eq!(
            failure_kind("scenario without a colon"),
            "scenario without a colon"
        );
    }

    #[test]
    fn a_long_example_is_cut_on_a_character() {
        let long = "é".repeat(300);
        let short = super::shorten(&long);
        assert_eq!(short.chars().count(), super::EXAMPLE_CHARS + 1);
        assert!(short.ends_with('…'));
        assert_eq!(super::shorten("short"), "short");
    }
}
