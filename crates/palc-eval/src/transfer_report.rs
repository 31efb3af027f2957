//! REPORT.md's transfer-matrix and accumulation section
//! (docs/experiments/0017-how-the-reproduction-counts.md; measured in
//! docs/experiments/0047-relative-onset-measured.md): what experience from every
//! other speed case (and headway) does to each cell, and what a user who drives the
//! scenes in sequence lives through.

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

/// palc's targets for experience across scenes
/// (docs/experiments/0017-how-the-reproduction-counts.md): the reduction of the
/// mean takeovers with experience from another speed case (twice the paper's 24 %)
/// and from another headway, with no pair more than one takeover worse than from
/// scratch and none at the cap.
const TARGET_REDUCTION_SPEED_CASE: f64 = 0.5;
/// See [`TARGET_REDUCTION_SPEED_CASE`].
const TARGET_REDUCTION_HEADWAY: f64 = 0.8;
/// The target mean of the takeovers after the first scene of an accumulation chain.
const TARGET_AFTER_FIRST_SCENE: f64 = 0.5;

/// Which axis a transfer run crosses: the speed case or the headway.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Axis {
    SpeedCase,
    Headway,
}

impl Axis {
    /// Both axes, speed case first.
    pub(crate) const BOTH: [Axis; 2] = [Axis::SpeedCase, Axis::Headway];

    pub(crate) fn name(self) -> &'static str {
        match self {
            Axis::SpeedCase => "speed case",
            Axis::Headway => "headway",
        }
    }

    /// The target reduction of the mean takeovers with experience along this axis.
    fn target_reduction(self) -> f64 {
        match self {
            Axis::SpeedCase => TARGET_REDUCTION_SPEED_CASE,
            Axis::Headway => TARGET_REDUCTION_HEADWAY,
        }
    }

    pub(crate) fn label(self, row: &RunRow) -> String {
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
    let _ = writeln!(out, "## Experience across scenes\n");
    let _ = writeln!(
        out,
        "Each cell learned again from the experience of the same user, method, style and seed in \
         another scene. The matrices give the mean counted takeovers with experience from the row's \
         scene in the column's; the diagonal is from scratch (the grid). Pairs count where both runs \
         were counted. A cell is *worse* when it needs more than one takeover more than from scratch.\n"
    );
    for &method in methods {
        for axis in Axis::BOTH {
            matrix(out, rows, method, axis);
        }
    }
    for &method in methods {
        accumulation(out, rows, method);
    }
}

/// One pair of the transfer matrix: a cell run from scratch and with the
/// experience of another scene, both counted.
pub(crate) struct MatrixPair {
    /// The scene the experience came from.
    pub from: String,
    /// The cell's scene.
    pub to: String,
    /// Counted takeovers from scratch (the grid run).
    pub without: f64,
    /// Counted takeovers with the experience.
    pub with: f64,
    /// Whether the run with experience personalized.
    pub personalized: bool,
}

/// The pairs of `method`'s transfer matrix along `axis`, in run order.
pub(crate) fn matrix_pairs(rows: &[RunRow], method: Method, axis: Axis) -> Vec<MatrixPair> {
    let grid: HashMap<CellKey, &RunRow> = rows
        .iter()
        .filter(|r| r.spec.experiment == Experiment::Grid)
        .map(|r| (r.spec.experiment_cell(), r))
        .collect();
    let mut pairs = Vec::new();
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
        pairs.push(MatrixPair {
            from: axis.label(source),
            to: axis.label(row),
            without: base.counted_takeovers() as f64,
            with: row.counted_takeovers() as f64,
            personalized: row.personalized(),
        });
    }
    pairs
}

/// One transfer matrix of `method` along `axis`, with its summary line.
fn matrix(out: &mut String, rows: &[RunRow], method: Method, axis: Axis) {
    let mut labels: Vec<String> = Vec::new();
    let mut cells: HashMap<(String, String), Vec<f64>> = HashMap::new();
    let (mut with, mut without, mut worse, mut capped) = (Vec::new(), Vec::new(), 0, 0);
    for pair in matrix_pairs(rows, method, axis) {
        let MatrixPair {
            from,
            to,
            without: a,
            with: b,
            personalized,
        } = pair;
        for label in [&from, &to] {
            if !labels.contains(label) {
                labels.push(label.clone());
            }
        }
        cells.entry((from, to.clone())).or_default().push(b);
        cells.entry((to.clone(), to)).or_default().push(a);
        with.push(b);
        without.push(a);
        worse += usize::from(b > a + 1.0);
        capped += usize::from(!personalized);
    }
    if with.is_empty() {
        return;
    }
    // The diagonal holds each target's grid runs once per pair: the same runs,
    // repeated; their mean is the grid's mean over the paired cells.
    let reduction = match (mean(&without), mean(&with)) {
        (Some(a), Some(b)) if a > 0.0 => Some(1.0 - b / a),
        _ => None,
    };
    let _ = writeln!(
        out,
        "**`{}`, experience from another {}** ({} pairs): from scratch {} -> with experience {} \
         takeovers ({}); {} pairs worse, {} not personalized. {}\n",
        method.name(),
        axis.name(),
        with.len(),
        num(mean(&without), 2),
        num(mean(&with), 2),
        reduction.map_or_else(|| "n/a".to_owned(), |r| format!("{:+.0} %", -100.0 * r)),
        worse,
        capped,
        transfer_verdict(axis, reduction, worse, capped)
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

/// The sentence that sets a transfer matrix's summary against palc's target.
fn transfer_verdict(axis: Axis, reduction: Option<f64>, worse: usize, capped: usize) -> String {
    let target = axis.target_reduction();
    let met = reduction.is_some_and(|r| r >= target) && worse == 0 && capped == 0;
    format!(
        "Target: at least {:.0} % fewer, no pair worse, none not personalized: {}.",
        100.0 * target,
        if met { "met" } else { "**not met**" }
    )
}

/// The sentence that sets the accumulation tables' means after the first scene
/// against palc's target: the user kinds that meet it and those that do not.
fn accumulation_verdict(after_first: &[(&str, Option<f64>)]) -> String {
    let (met, missed): (Vec<_>, Vec<_>) = after_first
        .iter()
        .filter_map(|&(name, value)| value.map(|v| (name, v)))
        .partition(|&(_, v)| v <= TARGET_AFTER_FIRST_SCENE);
    let names = |kinds: &[(&str, f64)]| {
        if kinds.is_empty() {
            "none".to_owned()
        } else {
            kinds.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", ")
        }
    };
    format!(
        "Target: at most {} takeovers after the first scene. Met by {}; **not met** by {}.",
        TARGET_AFTER_FIRST_SCENE,
        names(&met),
        names(&missed)
    )
}

/// The accumulation table of `method`, one per axis: mean takeovers of each user
/// kind by the scene's place in the sequence. A chain starts at a grid run (scene
/// 1, from scratch); each later scene starts from the experience of the one
/// before. A run counts when it and every run before it in its chain were counted.
fn accumulation(out: &mut String, rows: &[RunRow], method: Method) {
    for axis in Axis::BOTH {
        let kinds = accumulation_places(rows, method, axis);
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
        let mut after_first = Vec::new();
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
            after_first.push((name.as_str(), mean(&following)));
        }
        let _ = writeln!(out, "\n{}\n", accumulation_verdict(&after_first));
    }
}

/// The accumulation chains of `method` along `axis`, per user kind in order of
/// appearance: the counted takeovers at each place of the chain (place 0 is the
/// grid run the chain starts from). A run counts when it and every run before it
/// in its chain were counted.
pub(crate) fn accumulation_places(
    rows: &[RunRow],
    method: Method,
    axis: Axis,
) -> Vec<(String, Vec<Vec<f64>>)> {
    let source = |r: &RunRow| r.spec.experience_from.and_then(|id| rows.get(id));
    let chained = rows
        .iter()
        .filter(|r| r.spec.experiment == Experiment::Accumulation && r.spec.method == method)
        .filter(|r| source(r).is_some_and(|s| Axis::of(r, s) == axis));
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
    kinds
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_transfer_meets_its_target_only_with_no_pair_worse_and_none_capped() {
        let verdict = |axis, r, worse, capped| transfer_verdict(axis, Some(r), worse, capped);
        assert!(verdict(Axis::SpeedCase, 0.5, 0, 0).ends_with(": met."));
        assert!(verdict(Axis::SpeedCase, 0.49, 0, 0).contains("not met"));
        assert!(verdict(Axis::SpeedCase, 0.9, 1, 0).contains("not met"));
        assert!(verdict(Axis::SpeedCase, 0.9, 0, 1).contains("not met"));
        assert!(verdict(Axis::Headway, 0.67, 0, 0).contains("at least 80 % fewer"));
        assert!(verdict(Axis::Headway, 0.67, 0, 0).contains("not met"));
        assert!(transfer_verdict(Axis::Headway, None, 0, 0).contains("not met"));
    }

    #[test]
    fn the_accumulation_verdict_names_the_kinds_on_each_side() {
        let line = accumulation_verdict(&[
            ("deterministic", Some(0.27)),
            ("ttc-start", Some(0.5)),
            ("spread-2%", Some(5.47)),
            ("empty", None),
        ]);
        assert!(
            line.ends_with("Met by deterministic, ttc-start; **not met** by spread-2%."),
            "{line}"
        );
        let all = accumulation_verdict(&[("deterministic", Some(0.1))]);
        assert!(all.ends_with("**not met** by none."), "{all}");
    }
}
