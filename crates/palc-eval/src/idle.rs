//! Experiments that measured nothing: none of their runs ran (every one was
//! refused or failed). An evaluation with such an experiment still writes its
//! results, but its [`crate::Outcome`] names the experiment and the most common
//! reason, and `palc eval` exits non-zero, so that a config that cannot run
//! (a step of `1e-300 s`, a speed case the standard ALC never leaves) is not taken
//! for a result.
//!
//! A scene built to have no safe lane change (the dense stress scene) refuses
//! every run on purpose; its config lists the refusal kinds that may account for
//! a whole experiment (`expected_refusals`), and an experiment all of whose runs
//! were refused with those kinds is not idle. A failed run is never expected.

use std::collections::BTreeMap;

use crate::results::{RunRow, Status};

/// An experiment none of whose runs ran.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct IdleExperiment {
    /// The experiment's name (`grid`, `transfer`, ...).
    pub experiment: String,
    /// Its runs.
    pub runs: usize,
    /// The most common reason: a refusal kind (`Refusal::kind`) or `failed`.
    pub reason: String,
    /// How many runs ended for that reason.
    pub count: usize,
}

impl std::fmt::Display for IdleExperiment {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "experiment `{}`: none of its {} runs ran (most common reason: {}, {} runs)",
            self.experiment, self.runs, self.reason, self.count
        )
    }
}

/// The experiments of `rows` none of whose runs ran, in the order they first
/// appear, except those whose runs were all refused with a kind in `expected`.
pub fn idle_experiments(rows: &[RunRow], expected: &[String]) -> Vec<IdleExperiment> {
    let mut order: Vec<&'static str> = Vec::new();
    let mut by_experiment: BTreeMap<&'static str, Vec<&RunRow>> = BTreeMap::new();
    for row in rows {
        let name = row.spec.experiment.name();
        if !by_experiment.contains_key(name) {
            order.push(name);
        }
        by_experiment.entry(name).or_default().push(row);
    }
    order
        .into_iter()
        .filter_map(|name| idle(name, &by_experiment[name], expected))
        .collect()
}

/// The experiment `name` as idle, or `None` when one of its runs ran or every
/// run was refused as expected.
fn idle(name: &str, rows: &[&RunRow], expected: &[String]) -> Option<IdleExperiment> {
    let reasons: Vec<String> = rows
        .iter()
        .map(|row| match &row.status {
            Status::Personalized | Status::CapReached => None,
            Status::Refused { .. } => row.status.refusal_kind(),
            Status::Failed { .. } => Some("failed".to_owned()),
        })
        .collect::<Option<_>>()?;
    if reasons.iter().all(|reason| expected.contains(reason)) {
        return None;
    }
    let mut counts: BTreeMap<&str, usize> = BTreeMap::new();
    for reason in &reasons {
        *counts.entry(reason.as_str()).or_default() += 1;
    }
    // The most common reason; ties go to the first in name order.
    let (reason, count) = counts.into_iter().fold(
        None,
        |best: Option<(&str, usize)>, (reason, count)| match best {
            Some((_, most)) if most >= count => best,
            _ => Some((reason, count)),
        },
    )?;
    Some(IdleExperiment {
        experiment: name.to_owned(),
        runs: rows.len(),
        reason: reason.to_owned(),
        count,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::UserKind;
    use crate::plan::{Experiment, RunSpec};
    use crate::results::NO_EXPERIENCE_SOURCE;
    use palc_harness::{Method, StylePreset};
    use palc_traffic::SpeedCaseConfig;

    fn row(experiment: Experiment, status: Status) -> RunRow {
        let spec = RunSpec {
            id: 0,
            experiment,
            method: Method::Palc,
            user: UserKind::deterministic(),
            style: StylePreset::Neutral,
            speed_case: SpeedCaseConfig {
                name: "high".to_owned(),
                ego_mph: 45.0,
                others_mph: 40.0,
            },
            headway_m: 30.0,
            seed: 1,
            dt: None,
            horizon_margin_s: None,
            experience_from: None,
            rung: None,
        };
        RunRow::without_result(spec, status, 30, 0.0)
    }

    fn refused(kind: &str) -> Status {
        // The evaluation's own refusal carries its kind without a harness refusal.
        assert_eq!(kind, NO_EXPERIENCE_SOURCE);
        Status::Refused {
            reason: "source refused".to_owned(),
            refusal: None,
        }
    }

    #[test]
    fn an_experiment_with_one_run_that_ran_is_not_idle() {
        let rows = [
            row(Experiment::Grid, Status::Personalized),
            row(Experiment::Grid, refused(NO_EXPERIENCE_SOURCE)),
            row(Experiment::Timing, Status::CapReached),
        ];
        assert!(idle_experiments(&rows, &[]).is_empty());
    }

    #[test]
    fn an_experiment_with_no_run_that_ran_is_named_with_its_most_common_reason() {
        let failed = || Status::Failed {
            error: "singular".to_owned(),
        };
        let rows = [
            row(Experiment::Grid, Status::Personalized),
            row(Experiment::Transfer, refused(NO_EXPERIENCE_SOURCE)),
            row(Experiment::Transfer, failed()),
            row(Experiment::Transfer, failed()),
        ];
        let idle = idle_experiments(&rows, &[]);
        assert_eq!(
            idle,
            [IdleExperiment {
                experiment: "transfer".to_owned(),
                runs: 3,
                reason: "failed".to_owned(),
                count: 2,
            }]
        );
        let message = idle[0].to_string();
        assert!(message.contains("`transfer`") && message.contains("failed, 2 runs"));
    }

    #[test]
    fn refusals_of_expected_kinds_do_not_make_an_experiment_idle_but_failures_do() {
        let expected = [NO_EXPERIENCE_SOURCE.to_owned()];
        let all_refused = [row(Experiment::Transfer, refused(NO_EXPERIENCE_SOURCE))];
        assert!(idle_experiments(&all_refused, &expected).is_empty());
        let with_failure = [
            row(Experiment::Transfer, refused(NO_EXPERIENCE_SOURCE)),
            row(
                Experiment::Transfer,
                Status::Failed {
                    error: "io".to_owned(),
                },
            ),
        ];
        assert_eq!(idle_experiments(&with_failure, &expected).len(), 1);
    }
}
