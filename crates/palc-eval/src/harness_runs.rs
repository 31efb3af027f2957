//! The one place that calls the harness: a [`RunSpec`] becomes a
//! [`LearnConfig`] (the base config with the run's cell, user and method, set
//! through its builders), and the run is watched by observers: [`RowRecorder`]
//! keeps what every lane change and lesson produced for the run's [`RunRow`]
//! (outcome, perceived safety, compute time by part, learning failures), and
//! [`TraceRecorder`] keeps the trajectories of the qualitative example (Fig. 6).

use std::time::Instant;

use palc_aggregator::Experience;
use palc_harness::advanced::aggregator_options;
use palc_harness::user::{Spread, TakeoverCause};
use palc_harness::{
    CellChoice, HarnessError, LaneChangeRecord, LearnConfig, LearningLoop, LessonEvent, Observer,
    Outcome, RunResult, UserConfig,
};
use palc_traffic::TestbedConfig;
use serde::Serialize;

use crate::EvalError;
use crate::ablation::Rung;
use crate::plan::{Experiment, RunSpec};
use crate::recorded_drivers::RecordedDrivers;
use crate::results::{Iteration, RunRow, Status};
use crate::runner::Executor;

/// Runs specs through `palc_harness::run`.
#[derive(Debug)]
pub struct HarnessRuns {
    base: LearnConfig,
    testbed: TestbedConfig,
    rungs: Vec<Rung>,
    recorded: Vec<RecordedDrivers>,
}

impl HarnessRuns {
    /// Runs made from `base`, which must have a `[traffic.testbed]`.
    pub fn new(base: LearnConfig) -> Result<HarnessRuns, EvalError> {
        let testbed = base.traffic.testbed.clone().ok_or_else(|| {
            EvalError::invalid(
                "traffic.testbed",
                "missing",
                "the test bed whose cells the evaluation runs",
            )
        })?;
        Ok(HarnessRuns {
            base,
            testbed,
            rungs: Vec::new(),
            recorded: Vec::new(),
        })
    }

    /// These runs with the ablation ladder's rungs, which runs with a `rung`
    /// take their label rule and aggregator options from.
    pub fn with_rungs(mut self, rungs: Vec<Rung>) -> HarnessRuns {
        self.rungs = rungs;
        self
    }

    /// The ablation ladder's rungs.
    pub fn rungs(&self) -> &[Rung] {
        &self.rungs
    }

    /// These runs with the recorded user kinds' drivers, which runs with a
    /// `driver` take their user from.
    pub fn with_recorded(mut self, recorded: Vec<RecordedDrivers>) -> HarnessRuns {
        self.recorded = recorded;
        self
    }

    /// The recorded user kinds' drivers.
    pub fn recorded(&self) -> &[RecordedDrivers] {
        &self.recorded
    }

    /// The test bed of the base config: speed cases, headways and seeds.
    pub fn testbed(&self) -> &TestbedConfig {
        &self.testbed
    }

    /// The learning config of one run: the base with the run's method, cell,
    /// user, (timing experiment) step and horizon margin and (ablation) the
    /// rung's label rule and aggregator options.
    pub fn config(&self, spec: &RunSpec) -> Result<LearnConfig, EvalError> {
        let user = match &spec.user.driver {
            Some(driver) => self.driver_config(spec, driver)?,
            None => self.kind_config(spec),
        };
        self.config_with_user(spec, user)
    }

    /// The user of a recorded driver's run.
    fn driver_config(&self, spec: &RunSpec, driver: &str) -> Result<UserConfig, EvalError> {
        let drivers = self.recorded.iter().find(|r| r.kind == spec.user.name);
        let found = drivers.and_then(|r| r.driver(driver));
        found
            .map(|d| d.user.clone())
            .ok_or_else(|| EvalError::Unknown {
                kind: "recorded driver",
                name: driver.to_owned(),
                field: format!("run {}", spec.label()),
                known: (drivers.into_iter())
                    .flat_map(|r| r.accepted.iter().map(|d| d.id.clone()))
                    .collect(),
            })
    }

    /// The user of a run of a simulated user kind: the run's style refined by
    /// the kind's family and spread.
    fn kind_config(&self, spec: &RunSpec) -> UserConfig {
        UserConfig {
            spread: spec.user.has_spread().then(|| Spread {
                relative: spec.user.spread_relative.unwrap_or(0.0),
                seed: spec.seed,
                parameters: spec.user.spread_parameters.unwrap_or_default(),
            }),
            family: spec.user.family.clone(),
            ..UserConfig::preset(spec.style)
        }
    }

    fn config_with_user(&self, spec: &RunSpec, user: UserConfig) -> Result<LearnConfig, EvalError> {
        let mut config = (self.base.clone())
            .with_method(spec.method)
            .with_cell(CellChoice {
                speed_case: spec.speed_case.name.clone(),
                headway_m: spec.headway_m,
                seed: spec.seed,
            })
            .with_user(user);
        if let Some(dt) = spec.dt {
            config.planning.dt = dt;
        }
        if let Some(margin) = spec.horizon_margin_s {
            config.planning.horizon_margin_s = margin;
        }
        if spec.experiment == Experiment::ClosedLoop {
            config.planning.closed_loop.enabled = true;
        }
        if spec.experiment.is_drive() {
            // A drive's scene is driven once: no evaluation phase after it, and
            // a drawn speed case joins the test bed's.
            config.stopping.frozen_lane_changes = 0;
            if let Some(testbed) = config.traffic.testbed.as_mut() {
                let case = &spec.speed_case;
                if !testbed.speed_cases.iter().any(|c| c.name == case.name) {
                    testbed.speed_cases.push(case.clone());
                }
            }
        }
        if let Some(name) = &spec.rung {
            let rung = (self.rungs.iter().find(|r| &r.name == name)).ok_or_else(|| {
                EvalError::Unknown {
                    kind: "ablation rung",
                    name: name.clone(),
                    field: format!("run {}", spec.label()),
                    known: self.rungs.iter().map(|r| r.name.clone()).collect(),
                }
            })?;
            config.method = rung.labels;
            config.aggregator = Some(rung.options.clone());
        }
        config.validate().map_err(|source| EvalError::Run {
            run: spec.label(),
            source,
        })?;
        Ok(config)
    }

    /// Runs the qualitative example and keeps every lane change.
    pub fn example(&self, spec: &RunSpec) -> Result<ExampleTrace, EvalError> {
        let config = self.config(spec)?;
        let mut trace = TraceRecorder::default();
        let result =
            palc_harness::run(&config, None, &mut trace).map_err(|source| EvalError::Run {
                run: format!("the example {}", spec.label()),
                source,
            })?;
        Ok(ExampleTrace::new(&result, trace.lane_changes))
    }
}

impl Executor for HarnessRuns {
    type Experience = Experience;

    fn run(&self, spec: &RunSpec, experience: Option<&Experience>) -> (RunRow, Option<Experience>) {
        let start = Instant::now();
        let cap = cap_of(spec, self.cap());
        let config = match self.config(spec) {
            Ok(config) => config,
            Err(error) => {
                let status = Status::Failed {
                    error: error.to_string(),
                };
                return (RunRow::without_result(spec.clone(), status, cap, 0.0), None);
            }
        };
        let mut recorder = RowRecorder::default();
        let result = match spec.experiment {
            Experiment::Drive | Experiment::DriveFromScratch => {
                one_lane_change(&config, experience, &mut recorder)
            }
            _ => palc_harness::run(&config, experience, &mut recorder),
        };
        let wall_s = start.elapsed().as_secs_f64();
        match result {
            Ok(result) => {
                let row = row(spec, &result, recorder.iterations, wall_s);
                (row, Some(result.experience))
            }
            Err(HarnessError::Refused { scenario, refusal }) => {
                let status = Status::refused(&scenario, *refusal);
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

    /// The run's learning config, with the aggregator options it resolves to
    /// written out (a rung that names the method's own options runs the method),
    /// and what the run does with it: one lane change (a drive) or the loop.
    fn identity(&self, spec: &RunSpec) -> Option<String> {
        let mut config = self.config(spec).ok()?;
        config.aggregator = Some(aggregator_options(&config));
        let driven = (spec.experiment.is_drive(), cap_of(spec, self.cap()));
        serde_json::to_string(&(config, driven)).ok()
    }
}

/// The takeovers a run counts at most: a drive's lane change is one lane change,
/// which counts one takeover when taken over or when it failed; other runs count
/// the loop's cap.
fn cap_of(spec: &RunSpec, cap: usize) -> usize {
    match spec.experiment {
        Experiment::Drive | Experiment::DriveFromScratch => 1,
        _ => cap,
    }
}

/// One lane change of a drive ([`crate::drive`]): the scene's plan is driven
/// once and its takeover, if any, learned; the run then ends, `personalized` when
/// the lane change was not taken over and `cap-reached` when it was.
fn one_lane_change(
    config: &LearnConfig,
    experience: Option<&Experience>,
    observer: &mut dyn Observer,
) -> Result<RunResult, HarnessError> {
    let mut run = LearningLoop::new(config, experience)?;
    let taken_over = run.step(observer)?.takeover.is_some();
    let outcome = match taken_over {
        true => Outcome::CapReached,
        false => Outcome::Personalized,
    };
    run.finish(outcome, observer)
}

fn row(spec: &RunSpec, result: &RunResult, iterations: Vec<Iteration>, wall_s: f64) -> RunRow {
    let summary = &result.summary;
    RunRow {
        spec: spec.clone(),
        status: match summary.outcome {
            Outcome::Personalized => Status::Personalized,
            Outcome::CapReached => Status::CapReached,
        },
        takeovers: (summary.outcome)
            .counted_takeovers(summary.takeovers, cap_of(spec, summary.cap)),
        cap: cap_of(spec, summary.cap),
        lane_changes: summary.lane_changes,
        final_max_deviation_m: Some(summary.final_max_deviation_m),
        final_takeover_rate: Some(summary.final_takeover_rate),
        ceiling_takeover_rate: Some(summary.ceiling_takeover_rate),
        frozen: summary.frozen,
        horizon: result.horizon,
        dt: Some(result.dt),
        wall_s,
        iterations,
        driver_belief: result.carried_belief,
    }
}

/// Keeps, per lane change, what a [`RunRow`] reports: takeover, perceived
/// safety, deviation, compute time by part and, from the lesson events, why a
/// lesson could not be learned.
#[derive(Debug, Default)]
pub struct RowRecorder {
    /// One entry per lane change, in order.
    pub iterations: Vec<Iteration>,
}

impl Observer for RowRecorder {
    fn lane_change(&mut self, record: &LaneChangeRecord) {
        self.iterations.push(Iteration {
            takeover: record.takeover.is_some(),
            perceived_safety_takeover: record
                .takeover
                .is_some_and(|t| matches!(t.cause, TakeoverCause::PerceivedSafety { .. })),
            perceived_safety_ratio: record.perceived_safety_ratio,
            max_deviation_m: record.max_deviation_m,
            times_s: record.times,
            learning_error: None,
            safety: record.safety,
            user_safety: record.user_safety,
            safety_refusal: record.safety_refusal,
            closed_loop: record.closed_loop,
        });
    }

    fn lesson(&mut self, event: &LessonEvent<'_>) {
        if let LessonEvent::Failed {
            lane_change, error, ..
        } = event
        {
            if let Some(iteration) = self.iterations.get_mut(*lane_change) {
                iteration.learning_error = Some(error.to_string());
            }
        }
    }
}

/// Keeps the trajectories of every lane change (Fig. 6).
#[derive(Debug, Default)]
pub struct TraceRecorder {
    /// One entry per lane change, in order.
    pub lane_changes: Vec<ExampleLaneChange>,
}

impl Observer for TraceRecorder {
    fn lane_change(&mut self, record: &LaneChangeRecord) {
        self.lane_changes.push(ExampleLaneChange {
            planned_l: record.planned_l.clone(),
            expected_l: record.expected_l.clone(),
            driven_l: record.driven_l.clone(),
            takeover_step: record.takeover.map(|t| t.step),
        });
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
    fn new(result: &RunResult, lane_changes: Vec<ExampleLaneChange>) -> ExampleTrace {
        ExampleTrace {
            label: format!("{} ({})", result.label, result.method.name()),
            dt: result.dt,
            lane_changes,
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
