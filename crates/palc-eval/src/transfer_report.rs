//! REPORT.md's transfer-matrix and accumulation section (docs/paper-mapping.md,
//! "Experience in relative space"): what experience from every other speed case
//! (and headway) does to each cell, and what a user who drives the scenes in
//! sequence lives through.

use std::collections::HashMap;
use std::fmt::Write as _;

use palc_harness::Method;

use crate::claims::num;
use crate::plan::{CellKey, Experiment};
use crate::results::RunRow;

/// Mean of a list, `None` when empty.
fn mean(values: &[f64]) -> Option<f64> {
    (!values.is_empty()).then(|| values.iter().sum::<f64>() / values.len() as f64)
}

/// Which axis a transfer run crosses: the speed case or the headway.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Axis {
    SpeedCase,
    Headway,
}

impl Axis {
    fn name(self) -> &'static str {
        match self {
            Axis::SpeedCase => "speed case",
            Axis::Headway => "headway",
        }
    }

    fn label(self, row: &RunRow) -> String {
        match self {
            Axis::SpeedCase => row.spec.speed_case.name.clone(),
            Axis::Headway => format!("{} m", row.spec.headway_m),
        }
    }

    /// The axis `row` (started from `source`) crosses.
    fn of(row: &RunRow, source: &RunRow) -> Axis {
        if row.spec.speed_case.name != source.spec.speed_case.name {
            Axis::SpeedCase
        } else {
            Axis::Headway
        }
    }
}

/// Writes the section; nothing without matrix or accumulation runs.
pub fn section(out: &mut String, rows: &[RunRow], methods: &[Method]) {
    let has = |e: Experiment| rows.iter().any(|r| r.spec.experiment == e);
    if !has(Experiment::Matrix) && !has(Experiment::Accumulation) {
        return;
    }
    let grid: HashMap<CellKey, &RunRow> = rows
        .iter()
        .filter(|r| r.spec.experiment == Experiment::Grid)
        .map(|r| (r.spec.experiment_cell(), r))
        .collect();
    let _ = writeln!(out, "## Experience across scenes\n");
    let _ = writeln!(
        out,
        "Each cell learned again from the experience of the same user, method, style and seed in \
         another scene. The matrices give the mean counted takeovers with experience from the row's \
         scene in the column's; the diagonal is from scratch (the grid). Pairs count where both runs \
         were counted. A cell is *worse* when it needs more than one takeover more than from scratch.\n"
    );
    for &method in methods {
        for axis in [Axis::SpeedCase, Axis::Headway] {
            matrix(out, rows, &grid, method, axis);
        }
    }
    for &method in methods {
        accumulation(out, rows, method);
    }
}

/// One transfer matrix of `method` along `axis`, with its summary line.
fn matrix(
    out: &mut String,
    rows: &[RunRow],
    grid: &HashMap<CellKey, &RunRow>,
    method: Method,
    axis: Axis,
) {
    let mut labels: Vec<String> = Vec::new();
    let mut cells: HashMap<(String, String), Vec<f64>> = HashMap::new();
    let (mut with, mut without, mut worse, mut capped) = (Vec::new(), Vec::new(), 0, 0);
    for row in rows.iter().filter(|r| {
        r.spec.experiment == Experiment::Matrix && r.spec.method == method && r.status.counted()
    }) {
        let Some(source) = row.spec.experience_from.and_then(|id| rows.get(id)) else {
            continue;
        };
        if Axis::of(row, source) != axis {
            continue;
        }
        let Some(base) = grid.get(&row.spec.experiment_cell()) else {
            continue;
        };
        if !base.status.counted() {
            continue;
        }
        let (from, to) = (axis.label(source), axis.label(row));
        for label in [&from, &to] {
            if !labels.contains(label) {
                labels.push(label.clone());
            }
        }
        let (a, b) = (base.counted_takeovers(), row.counted_takeovers());
        cells.entry((from, to.clone())).or_default().push(b as f64);
        cells.entry((to.clone(), to)).or_default().push(a as f64);
        with.push(b as f64);
        without.push(a as f64);
        worse += usize::from(b > a + 1);
        capped += usize::from(!row.personalized());
    }
    if with.is_empty() {
        return;
    }
    // The diagonal holds each target's grid runs once per pair: the same runs,
    // repeated; their mean is the grid's mean over the paired cells.
    let _ = writeln!(
        out,
        "**`{}`, experience from another {}** ({} pairs): from scratch {} -> with experience {} \
         takeovers ({}); {} pairs worse, {} not personalized.\n",
        method.name(),
        axis.name(),
        with.len(),
        num(mean(&without), 2),
        num(mean(&with), 2),
        match (mean(&without), mean(&with)) {
            (Some(a), Some(b)) if a > 0.0 => format!("{:+.0} %", 100.0 * (b / a - 1.0)),
            _ => "n/a".to_owned(),
        },
        worse,
        capped
    );
    let _ = writeln!(out, "| from \\ to | {} |", labels.join(" | "));
    let _ = writeln!(out, "| --- |{}", " --- |".repeat(labels.len()));
    for from in &labels {
        let line: Vec<String> = labels
            .iter()
            .map(|to| {
                let value = cells.get(&(from.clone(), to.clone())).and_then(|v| mean(v));
                if from == to {
                    format!("*{}*", num(value, 2))
                } else {
                    num(value, 2)
                }
            })
            .collect();
        let _ = writeln!(out, "| {from} | {} |", line.join(" | "));
    }
    let _ = writeln!(out);
}

/// The accumulation table of `method`, one per axis: mean takeovers of each user
/// kind by the scene's place in the sequence. A chain starts at a grid run (scene
/// 1, from scratch); each later scene starts from the experience of the one
/// before. A run counts when it and every run before it in its chain were counted.
fn accumulation(out: &mut String, rows: &[RunRow], method: Method) {
    let source = |r: &RunRow| r.spec.experience_from.and_then(|id| rows.get(id));
    for axis in [Axis::SpeedCase, Axis::Headway] {
        let chained: Vec<&RunRow> = rows
            .iter()
            .filter(|r| r.spec.experiment == Experiment::Accumulation && r.spec.method == method)
            .filter(|r| source(r).is_some_and(|s| Axis::of(r, s) == axis))
            .collect();
        if chained.is_empty() {
            continue;
        }
        // Per user kind, in order of appearance: takeovers by place.
        let mut kinds: Vec<(String, Vec<Vec<f64>>)> = Vec::new();
        let mut starts: Vec<usize> = Vec::new();
        for row in chained {
            let (mut place, mut counted, mut at) = (1, true, Some(row));
            while let Some(run) = at.filter(|r| r.spec.experiment != Experiment::Grid) {
                counted &= run.status.counted();
                place += 1;
                at = source(run);
            }
            let Some(start) = at.filter(|grid| grid.status.counted()) else {
                continue;
            };
            if !counted {
                continue;
            }
            let name = &row.spec.user.name;
            let index = match kinds.iter().position(|(n, _)| n == name) {
                Some(i) => i,
                None => {
                    kinds.push((name.clone(), vec![Vec::new()]));
                    kinds.len() - 1
                }
            };
            let places = &mut kinds[index].1;
            if !starts.contains(&start.spec.id) {
                starts.push(start.spec.id);
                places[0].push(start.counted_takeovers() as f64);
            }
            if places.len() < place {
                places.resize(place, Vec::new());
            }
            places[place - 1].push(row.counted_takeovers() as f64);
        }
        let scenes = kinds.iter().map(|(_, p)| p.len()).max().unwrap_or(0);
        if scenes < 2 {
            continue;
        }
        let _ = writeln!(
            out,
            "**`{}`, one user through the {}s in sequence**: mean takeovers in each scene \
             (scene 1 from scratch; the number of counted runs in brackets).\n",
            method.name(),
            axis.name(),
        );
        let places: Vec<String> = (1..=scenes).map(|p| format!("scene {p}")).collect();
        let _ = writeln!(
            out,
            "| user kind | {} | after the first scene |",
            places.join(" | ")
        );
        let _ = writeln!(out, "| --- |{} --- |", " --- |".repeat(scenes));
        for (name, by_place) in &kinds {
            let values: Vec<String> = (0..scenes)
                .map(|p| {
                    by_place.get(p).map_or_else(
                        || "-".to_owned(),
                        |v| format!("{} ({})", num(mean(v), 2), v.len()),
                    )
                })
                .collect();
            let following: Vec<f64> = by_place.iter().skip(1).flatten().copied().collect();
            let _ = writeln!(
                out,
                "| {name} | {} | {} |",
                values.join(" | "),
                num(mean(&following), 2)
            );
        }
        let _ = writeln!(out);
    }
}
