//! Regression test on a small fixed subset of the reproduction, run through the
//! real harness: the results are deterministic for a seed, do not depend on the
//! number of threads, and their key statistics match `tests/golden/quick.json`.
//!
//! When the model changes on purpose, rewrite the golden file with
//! `PALC_UPDATE_GOLDEN=1 cargo test -p palc-eval --test golden` and give the
//! reason in the commit message.

use std::path::{Path, PathBuf};

use palc_eval::config::{Selection, TimingConfig, TransferConfig, TransferSource};
use palc_eval::stats::Summary;
use palc_eval::{Evaluation, Experiment, NoProgress, RunRow, plan, runner};
use palc_harness::{Method, StylePreset};
use serde::{Deserialize, Serialize};

/// The key numbers of one run, rounded so that the file is readable.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct GoldenRun {
    run: String,
    outcome: String,
    takeovers: usize,
    lane_changes: usize,
    horizon: usize,
    final_max_deviation_mm: Option<i64>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct Golden {
    runs: Vec<GoldenRun>,
    mean_takeovers_by_method: Vec<(String, Option<f64>)>,
}

fn project_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn golden_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden/quick.json")
}

/// Two speed cases, one headway, two styles, one seed, deterministic users,
/// both methods, with the transfer experiment.
fn subset(evaluation: &Evaluation) -> Selection {
    let mut selection = evaluation.selection().clone();
    let testbed = evaluation.harness().testbed();
    selection.grid.speed_cases = (testbed.speed_cases.iter())
        .filter(|c| c.name == "collector-high" || c.name == "collector-slow")
        .cloned()
        .collect();
    selection.grid.headways_m = vec![40.0];
    selection.grid.styles = vec![StylePreset::Aggressive, StylePreset::Cautious];
    selection.grid.seeds = vec![1];
    selection.drive = Default::default();
    selection
        .users
        .retain(|u| !u.has_spread() && !u.is_family());
    selection.transfer = TransferConfig {
        source: TransferSource::NextSpeedCase,
        users: selection.users.iter().map(|u| u.name.clone()).collect(),
        matrix_users: Vec::new(),
        accumulation_users: Vec::new(),
    };
    selection.closed_loop = Default::default();
    selection.ablation = Default::default();
    selection.timing = TimingConfig {
        dts: Vec::new(),
        ..selection.timing
    };
    selection
}

fn golden(rows: &[RunRow], methods: &[Method]) -> Golden {
    Golden {
        runs: rows
            .iter()
            .map(|r| GoldenRun {
                run: r.spec.label(),
                outcome: r.status.name().to_owned(),
                takeovers: r.counted_takeovers(),
                lane_changes: r.lane_changes,
                horizon: r.horizon,
                // Only a personalized plan's deviation is a key number; that of a
                // run stopped at the cap depends on where the failing learner stopped.
                final_max_deviation_mm: (r.final_max_deviation_m)
                    .filter(|_| r.personalized())
                    .map(|d| (d * 1e3).round() as i64),
            })
            .collect(),
        mean_takeovers_by_method: methods
            .iter()
            .map(|&m| {
                let rows = rows
                    .iter()
                    .filter(|r| r.spec.method == m && r.spec.experiment == Experiment::Grid);
                (m.name().to_owned(), Summary::of(rows).mean)
            })
            .collect(),
    }
}

#[test]
fn the_quick_subset_is_deterministic_and_matches_the_golden_file() {
    let config_path = project_root().join("configs/reproduce.toml");
    let evaluation = Evaluation::load(&config_path, true).unwrap();
    let harness = evaluation.harness();
    let selection = subset(&evaluation);
    let plan = plan::expand(&selection, harness.testbed()).unwrap();
    assert!(!plan.transfer.is_empty());

    let one = runner::execute(&plan, harness, 1, &NoProgress).unwrap();
    let two = runner::execute(&plan, harness, 2, &NoProgress).unwrap();
    let strip = |rows: &[RunRow]| rows.iter().map(RunRow::without_timing).collect::<Vec<_>>();
    assert_eq!(
        strip(&one),
        strip(&two),
        "results depend on the number of threads"
    );

    let measured = golden(&one, &selection.grid.methods);
    let path = golden_path();
    if std::env::var_os("PALC_UPDATE_GOLDEN").is_some() {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        let text = serde_json::to_string_pretty(&measured).unwrap() + "\n";
        std::fs::write(&path, text).unwrap();
        return;
    }
    let stored: Golden = serde_json::from_str(&std::fs::read_to_string(&path).unwrap_or_else(|e| {
        panic!(
            "cannot read {}: {e}; create it with `PALC_UPDATE_GOLDEN=1 cargo test -p palc-eval --test golden`",
            path.display()
        )
    }))
    .unwrap();
    assert_eq!(
        measured,
        stored,
        "the quick subset's results changed; if the model changed on purpose, rewrite {} with \
         `PALC_UPDATE_GOLDEN=1 cargo test -p palc-eval --test golden` and say why in the commit message",
        path.display()
    );
}
