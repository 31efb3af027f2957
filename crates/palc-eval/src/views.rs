//! The experiments of Section III as views of the runs: which rows each table
//! and figure uses. [`Indexed`] sorts the rows once by experiment, method and
//! user kind; the report's sections look their rows up in it.

use std::collections::HashMap;

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

/// The rows of an evaluation indexed once by experiment, method and user kind,
/// each list in plan order.
#[derive(Debug, Clone)]
pub struct Indexed<'a> {
    rows: &'a [RunRow],
    cells: HashMap<(Experiment, &'static str), HashMap<&'a str, Vec<&'a RunRow>>>,
    experiments: HashMap<(Experiment, &'static str), Vec<&'a RunRow>>,
    methods: HashMap<&'static str, Vec<&'a RunRow>>,
}

impl<'a> Indexed<'a> {
    /// Indexes `rows` (in plan order: a run's `experience_from` is its index).
    pub fn new(rows: &'a [RunRow]) -> Indexed<'a> {
        let mut index = Indexed {
            rows,
            cells: HashMap::new(),
            experiments: HashMap::new(),
            methods: HashMap::new(),
        };
        for row in rows {
            let (experiment, method) = (row.spec.experiment, row.spec.method.name());
            let user = row.spec.user.name.as_str();
            (index.cells.entry((experiment, method)).or_default())
                .entry(user)
                .or_default()
                .push(row);
            (index.experiments.entry((experiment, method)).or_default()).push(row);
            index.methods.entry(method).or_default().push(row);
        }
        index
    }

    /// Every row, in plan order.
    pub fn rows(&self) -> &'a [RunRow] {
        self.rows
    }

    /// The rows of one experiment, method and user kind.
    pub fn runs(&self, experiment: Experiment, method: Method, user: &str) -> &[&'a RunRow] {
        (self.cells.get(&(experiment, method.name())))
            .and_then(|users| users.get(user))
            .map_or(&[], Vec::as_slice)
    }

    /// The grid rows (no experience) of one method and user kind.
    pub fn grid(&self, method: Method, user: &str) -> &[&'a RunRow] {
        self.runs(Experiment::Grid, method, user)
    }

    /// The grid rows, then the transfer rows, of one method and user kind.
    pub fn with_transfer(&self, method: Method, user: &str) -> Vec<&'a RunRow> {
        let transfer = self.runs(Experiment::Transfer, method, user);
        let mut rows = self.grid(method, user).to_vec();
        rows.extend_from_slice(transfer);
        rows
    }

    /// The rows of one experiment and method, every user kind.
    pub fn of_experiment(&self, experiment: Experiment, method: Method) -> &[&'a RunRow] {
        (self.experiments.get(&(experiment, method.name()))).map_or(&[], Vec::as_slice)
    }

    /// The rows of one method, every experiment and user kind.
    pub fn of_method(&self, method: Method) -> &[&'a RunRow] {
        self.methods.get(method.name()).map_or(&[], Vec::as_slice)
    }

    /// The experiments with runs, in the order of [`Experiment`]'s variants.
    pub fn experiments(&self) -> Vec<Experiment> {
        let mut experiments: Vec<Experiment> = self.experiments.keys().map(|(e, _)| *e).collect();
        experiments.sort();
        experiments.dedup();
        experiments
    }

    /// Whether any run belongs to `experiment`.
    pub fn has(&self, experiment: Experiment) -> bool {
        self.experiments.keys().any(|(e, _)| *e == experiment)
    }

    /// Pairs of the grid row and the closed-loop row of the same cell, for one
    /// method and user kind, in plan order.
    pub fn closed_loop_pairs(&self, method: Method, user: &str) -> Vec<(&'a RunRow, &'a RunRow)> {
        let open: HashMap<_, &RunRow> = (self.grid(method, user).iter())
            .map(|r| (r.spec.experiment_cell(), *r))
            .collect();
        (self.runs(Experiment::ClosedLoop, method, user).iter())
            .filter_map(|closed| {
                let cell = closed.spec.experiment_cell();
                open.get(&cell).map(|&o| (o, *closed))
            })
            .collect()
    }
}
