//! Experience across scenes as data (docs/experiments/0017-how-the-reproduction-counts.md):
//! the pairs of the transfer matrix (a cell from scratch and with the experience of
//! another scene) and the accumulation chains (one user through the scenes in
//! sequence), which the report's tables, palc's targets and the figures read.

use std::collections::HashMap;

use palc_harness::Method;

use crate::plan::{CellKey, Experiment};
use crate::results::RunRow;

/// Mean of a list, `None` when empty.
pub fn mean(values: &[f64]) -> Option<f64> {
    (!values.is_empty()).then(|| values.iter().sum::<f64>() / values.len() as f64)
}

/// Which axis a transfer run crosses: the speed case or the headway.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Axis {
    /// Experience from another speed case at the same headway.
    SpeedCase,
    /// Experience from another headway in the same speed case.
    Headway,
}

impl Axis {
    /// Both axes, speed case first.
    pub const BOTH: [Axis; 2] = [Axis::SpeedCase, Axis::Headway];

    /// The axis in words.
    pub fn name(self) -> &'static str {
        match self {
            Axis::SpeedCase => "speed case",
            Axis::Headway => "headway",
        }
    }

    /// The scene of `row` along this axis: its speed case or its headway.
    pub fn label(self, row: &RunRow) -> String {
        match self {
            Axis::SpeedCase => row.spec.speed_case.name.clone(),
            Axis::Headway => format!("{} m", row.spec.headway_m),
        }
    }

    /// The axis `row` (started from `source`) crosses.
    pub fn of(row: &RunRow, source: &RunRow) -> Axis {
        if row.spec.speed_case.name != source.spec.speed_case.name {
            Axis::SpeedCase
        } else {
            Axis::Headway
        }
    }
}

/// One pair of the transfer matrix: a cell run from scratch and with the
/// experience of another scene, both counted.
pub struct MatrixPair {
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
pub fn matrix_pairs(rows: &[RunRow], method: Method, axis: Axis) -> Vec<MatrixPair> {
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

/// The accumulation chains of `method` along `axis`, per user kind in order of
/// appearance: the counted takeovers at each place of the chain (place 0 is the
/// grid run the chain starts from). A run counts when it and every run before it
/// in its chain were counted.
pub fn accumulation_places(
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
