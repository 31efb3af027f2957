//! Runs shared between experiments, through the real harness: the quick plan's
//! repeats (a transfer run that is also a pair of the transfer matrix, an
//! ablation `paper` rung run that is a grid run) give, computed a second time on
//! their own, the row of the run they repeat (timing and spec aside), so the
//! runner may compute them once.

use std::path::Path;

use palc_eval::runner::Executor;
use palc_eval::shared_runs::originals;
use palc_eval::{Evaluation, Experiment, RunRow, RunSpec};

/// A row without its spec and timing fields.
fn result_of(row: &RunRow) -> RunRow {
    let mut row = row.without_timing();
    row.spec = RunSpec {
        id: 0,
        experiment: Experiment::Grid,
        experience_from: None,
        rung: None,
        ..row.spec
    };
    row
}

#[test]
fn a_repeated_run_computed_again_gives_the_row_of_its_original() {
    let config = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../configs/reproduce.toml");
    let evaluation = Evaluation::load(&config, true).unwrap();
    let harness = evaluation.harness();
    let plan = evaluation.plan().unwrap();
    let runs: Vec<&RunSpec> = plan.all().collect();
    let original = originals(&plan, |spec| harness.identity(spec));
    let repeat_of = |experiment: Experiment, of: Experiment| {
        (runs.iter())
            .find(|s| {
                s.experiment == experiment
                    && original[s.id] != s.id
                    && runs[original[s.id]].experiment == of
            })
            .unwrap_or_else(|| panic!("a {experiment:?} run repeats a {of:?} run"))
    };
    let pairs = [
        repeat_of(Experiment::Matrix, Experiment::Transfer),
        repeat_of(Experiment::Ablation, Experiment::Grid),
    ];
    for repeat in pairs {
        let first = runs[original[repeat.id]];
        let source = (repeat.experience_from).map(|s| harness.run(runs[s], None).1.unwrap());
        let (computed, _) = harness.run(first, source.as_ref());
        let (again, _) = harness.run(repeat, source.as_ref());
        assert_eq!(
            result_of(&computed),
            result_of(&again),
            "{} repeats {}",
            repeat.label(),
            first.label()
        );
    }
}
