//! The one place that calls the harness: a [`RunSpec`] becomes a
//! [`LearnConfig`] (the base config with the run's cell, user and method), and
//! the harness's [`RunResult`] becomes a [`RunRow`].

use std::time::Instant;

use anyhow::Context;
use palc_aggregator::Experience;
use palc_harness::user::Spread;
use palc_harness::{
    CellChoice, HarnessError, LaneChangeRecord, LearnConfig, Method, NoObserver, Outcome,
    RunResult, UserConfig,
};
use serde::Serialize;

use super::plan::{RunSpec, SpeedCase};
use super::results::{Iteration, RunRow, Status};
use super::runner::Executor;

/// Runs specs through `palc_harness::run`.
pub struct HarnessRuns {
    base: LearnConfig,
}

impl HarnessRuns {
    /// Parses the base learning config.
    pub fn from_toml_str(text: &str) -> anyhow::Result<HarnessRuns> {
        let base = LearnConfig::from_toml_str(text).context("the base learning config")?;
        Ok(HarnessRuns { base })
    }

    /// The speed cases of the base config's test bed.
    pub fn speed_cases(&self) -> anyhow::Result<Vec<SpeedCase>> {
        let testbed = (self.base.traffic.testbed.as_ref())
            .context("the base learning config has no `[traffic.testbed]`")?;
        Ok(testbed
            .speed_cases
            .iter()
            .map(|case| SpeedCase {
                name: case.name.clone(),
                ego_mph: case.ego_mph,
                others_mph: case.others_mph,
            })
            .collect())
    }

    /// The learning config of one run.
    pub fn config(&self, spec: &RunSpec) -> anyhow::Result<LearnConfig> {
        let mut config = self.base.clone();
        config.method = Method::named(&spec.method)
            .with_context(|| format!("unknown method `{}`", spec.method))?;
        config.cell = CellChoice {
            speed_case: spec.speed_case.name.clone(),
            headway_m: spec.headway_m,
            seed: spec.seed,
        };
        config.user = UserConfig {
            style: spec.style.parse()?,
            custom: None,
            spread: spec.user.spread_relative.map(|relative| Spread {
                relative,
                seed: spec.seed,
            }),
        };
        if let Some(dt) = spec.dt {
            config.planning.dt = dt;
        }
        if let Some(margin) = spec.horizon_margin_s {
            config.planning.horizon_margin_s = margin;
        }
        config
            .validate()
            .with_context(|| format!("run `{}`", spec.label()))?;
        Ok(config)
    }

    /// Runs the qualitative example and keeps every lane change.
    pub fn example(&self, spec: &RunSpec) -> anyhow::Result<ExampleTrace> {
        let config = self.config(spec)?;
        let result = palc_harness::run(&config, None, &mut NoObserver)
            .with_context(|| format!("the example run `{}`", spec.label()))?;
        Ok(ExampleTrace::from_result(&result))
    }
}

impl Executor for HarnessRuns {
    type Experience = Experience;

    fn run(&self, spec: &RunSpec, experience: Option<&Experience>) -> (RunRow, Option<Experience>) {
        let start = Instant::now();
        let cap = self.cap();
        let config = match self.config(spec) {
            Ok(config) => config,
            Err(error) => {
                let status = Status::Failed {
                    error: format!("{error:#}"),
                };
                return (RunRow::without_result(spec.clone(), status, cap, 0.0), None);
            }
        };
        let result = palc_harness::run(&config, experience, &mut NoObserver);
        let wall_s = start.elapsed().as_secs_f64();
        match result {
            Ok(result) => {
                let row = row(spec, &result, cap, wall_s);
                (row, Some(result.experience))
            }
            Err(HarnessError::Scenario { scenario, reason }) => {
                let status = Status::Refused {
                    reason: format!("{scenario}: {reason}"),
                };
                (
                    RunRow::without_result(spec.clone(), status, cap, wall_s),
                    None,
                )
            }
            Err(error) => {
                let status = Status::Failed {
                    error: error.to_string(),
                };
                (
                    RunRow::without_result(spec.clone(), status, cap, wall_s),
                    None,
                )
            }
        }
    }

    fn cap(&self) -> usize {
        self.base.stopping.max_takeovers
    }
}

fn row(spec: &RunSpec, result: &RunResult, cap: usize, wall_s: f64) -> RunRow {
    let summary = &result.summary;
    RunRow {
        spec: spec.clone(),
        status: match summary.outcome {
            Outcome::Personalized => Status::Personalized,
            Outcome::CapReached => Status::CapReached,
        },
        takeovers: summary.counted_takeovers(),
        cap,
        lane_changes: summary.lane_changes,
        final_max_deviation_m: Some(summary.final_max_deviation_m),
        final_takeover_rate: Some(summary.final_takeover_rate),
        ceiling_takeover_rate: Some(summary.ceiling_takeover_rate),
        horizon: result.horizon,
        dt: Some(result.dt),
        wall_s,
        iterations: result.records.iter().map(iteration).collect(),
    }
}

fn iteration(record: &LaneChangeRecord) -> Iteration {
    Iteration {
        takeover: record.takeover.is_some(),
        perceived_safety_ratio: record.perceived_safety_ratio,
        max_deviation_m: record.max_deviation_m,
        times_s: record.times.parts(),
    }
}

/// Every lane change of the example run, for Fig. 6.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ExampleTrace {
    /// The scenario.
    pub label: String,
    /// Step (s).
    pub dt: f64,
    /// Per lane change: planned, expected and driven lateral positions, and
    /// whether the user took over.
    pub lane_changes: Vec<ExampleLaneChange>,
    /// The learned weight matrix, one column of ten rows per stage.
    pub weights: Vec<[f64; 10]>,
    /// Names of the ten rows.
    pub weight_names: Vec<String>,
    /// Takeovers to success and whether the run personalized.
    pub takeovers: usize,
    /// Whether the run personalized.
    pub personalized: bool,
}

/// One lane change of the example.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ExampleLaneChange {
    /// Planned lateral positions (m).
    pub planned_l: Vec<f64>,
    /// Expected lateral positions (m).
    pub expected_l: Vec<f64>,
    /// Driven lateral positions (m).
    pub driven_l: Vec<f64>,
    /// Step of the takeover, if any.
    pub takeover_step: Option<usize>,
}

impl ExampleTrace {
    fn from_result(result: &RunResult) -> ExampleTrace {
        ExampleTrace {
            label: format!("{} ({})", result.label, result.method.name()),
            dt: result.dt,
            lane_changes: (result.records.iter())
                .map(|r| ExampleLaneChange {
                    planned_l: r.planned_l.clone(),
                    expected_l: r.expected_l.clone(),
                    driven_l: r.driven_l.clone(),
                    takeover_step: r.takeover.map(|t| t.step),
                })
                .collect(),
            weights: result.experience.weights.columns().to_vec(),
            weight_names: palc_planner::feature::NAMES
                .iter()
                .map(|s| s.to_string())
                .collect(),
            takeovers: result.summary.counted_takeovers(),
            personalized: result.summary.outcome == Outcome::Personalized,
        }
    }
}
