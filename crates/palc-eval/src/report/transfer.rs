//! REPORT.md's transfer-matrix and accumulation section
//! (docs/experiments/0017-how-the-reproduction-counts.md; measured in
//! docs/experiments/0047-relative-onset-measured.md): what experience from every
//! other speed case (and headway) does to each cell, and what a user who drives the
//! scenes in sequence lives through. The text states palc's targets; the
//! matrices and the sequences go to [`MATRIX_FILE`] and [`ACCUMULATION_FILE`].

use std::collections::HashMap;
use std::fmt::{self, Write as _};

use palc_harness::Method;

use crate::claims::num;
use crate::plan::Experiment;
use crate::scenes::{self, Axis, MatrixPair, mean};
use crate::targets::{self, Case, TargetId, Verdict, target};

use super::section::{Out, Results, Section, fill};

/// The CSV file of the transfer matrices.
pub const MATRIX_FILE: &str = "transfer-matrix.csv";
/// The CSV file of the accumulation tables.
pub const ACCUMULATION_FILE: &str = "accumulation.csv";
const MATRIX_COLUMNS: &[&str] = &["method", "axis", "from", "to", "mean_takeovers", "runs"];
const ACCUMULATION_COLUMNS: &[&str] = &[
    "method",
    "axis",
    "user_kind",
    "scene",
    "mean_takeovers",
    "runs",
];

/// The experience-across-scenes section.
pub struct Transfer;

impl Section for Transfer {
    fn title(&self) -> &'static str {
        "Experience across scenes"
    }

    fn applies(&self, results: &Results) -> bool {
        results.index.has(Experiment::Matrix) || results.index.has(Experiment::Accumulation)
    }

    fn render(&self, results: &Results, out: &mut Out) -> fmt::Result {
        let text = fill(
            include_str!("templates/transfer.md"),
            &[
                ("matrix", MATRIX_FILE.to_owned()),
                ("accumulation", ACCUMULATION_FILE.to_owned()),
            ],
        );
        writeln!(out, "{text}\n")?;
        for &method in results.methods() {
            for (axis, id) in [
                (Axis::SpeedCase, TargetId::TransferSpeedCase),
                (Axis::Headway, TargetId::TransferHeadway),
            ] {
                let Some(measured) = targets::transfer(&results.index, method, axis) else {
                    continue;
                };
                let case = Case {
                    who: format!("`{}`", method.name()),
                    measured,
                };
                writeln!(out, "- {}", target(id).state(&case))?;
                matrix(results, method, axis, out);
            }
        }
        let accumulation = target(TargetId::Accumulation);
        for &method in results.methods() {
            let cases = accumulation.cases(&results.index, method, results.input.user_kinds);
            if accumulation.judge(&cases) == Verdict::NotMeasured {
                continue;
            }
            let who = format!("`{}`, each user kind and axis", method.name());
            writeln!(out, "- {}", accumulation.state_cases(&who, &cases))?;
            sequences(results, method, out);
        }
        writeln!(out)
    }
}

/// The transfer matrix of `method` along `axis`, into [`MATRIX_FILE`]: the
/// diagonal holds each target's grid runs once per pair (the same runs,
/// repeated; their mean is the grid's over the paired cells).
fn matrix(results: &Results, method: Method, axis: Axis, out: &mut Out) {
    let mut labels: Vec<String> = Vec::new();
    let mut cells: HashMap<(String, String), Vec<f64>> = HashMap::new();
    for pair in scenes::matrix_pairs(results.input.rows, method, axis) {
        let MatrixPair {
            from,
            to,
            without,
            with,
            ..
        } = pair;
        for label in [&from, &to] {
            if !labels.contains(label) {
                labels.push(label.clone());
            }
        }
        cells.entry((from, to.clone())).or_default().push(with);
        cells.entry((to.clone(), to)).or_default().push(without);
    }
    let table = out.table(MATRIX_FILE, MATRIX_COLUMNS);
    for from in &labels {
        for to in &labels {
            if let Some(values) = cells.get(&(from.clone(), to.clone())) {
                table.rows.push(vec![
                    method.name().to_owned(),
                    axis.name().to_owned(),
                    from.clone(),
                    to.clone(),
                    num(mean(values), 2),
                    values.len().to_string(),
                ]);
            }
        }
    }
}

/// The accumulation tables of `method`, one per axis, into [`ACCUMULATION_FILE`].
fn sequences(results: &Results, method: Method, out: &mut Out) {
    let table = out.table(ACCUMULATION_FILE, ACCUMULATION_COLUMNS);
    for axis in Axis::BOTH {
        let kinds = scenes::accumulation_places(results.input.rows, method, axis);
        if kinds.iter().map(|(_, p)| p.len()).max().unwrap_or(0) < 2 {
            continue;
        }
        for (name, places) in &kinds {
            for (place, values) in places.iter().enumerate() {
                table.rows.push(vec![
                    method.name().to_owned(),
                    axis.name().to_owned(),
                    name.clone(),
                    (place + 1).to_string(),
                    num(mean(values), 2),
                    values.len().to_string(),
                ]);
            }
        }
    }
}
