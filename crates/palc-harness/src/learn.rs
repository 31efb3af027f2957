//! The lesson-learning loop (paper Fig. 2): plan, execute in the scene, let the
//! user judge each step; on a takeover, label the lesson, update the zone, run the
//! aggregator; repeat until the user stops taking over or the cap is reached.
//!
//! Observers (progress bars, logs, recorders) watch each lane change through
//! [`Observer`]; the loop does not know them.

use std::time::Instant;

use palc_aggregator::{AggregatorOptions, Experience, Lesson, learn_from_lesson, plan_problem};
use palc_planner::{LateralBoundsMode, Plan, Planner, PlannerConfig, State};
use palc_traffic::Scene;
use palc_zone_filter::{FeatureInput, Label, Sample, StepScene, features};
use serde::{Deserialize, Serialize};

use crate::HarnessError;
use crate::config::LearnConfig;
use crate::drive::{Drive, execute, problem};
use crate::method::{Driver, Method, label};
use crate::record::{LaneChangeRecord, Outcome, PartTimes, RunSummary};
use crate::setup::Setup;
use crate::user::{Style, User, first_takeover};

/// Watches the loop; every method has a default that does nothing.
pub trait Observer {
    /// Called after each lane change.
    fn lane_change(&mut self, _record: &LaneChangeRecord) {}
    /// Called once when the run ends.
    fn finished(&mut self, _summary: &RunSummary) {}
}

/// An observer that watches nothing.
#[derive(Debug, Default, Clone, Copy)]
pub struct NoObserver;

impl Observer for NoObserver {}

/// Everything a run produced.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct RunResult {
    /// The scenario, e.g. `collector-high / 40 m / seed 1 / neutral`.
    pub label: String,
    /// The method.
    pub method: Method,
    /// Planning horizon K of this scenario.
    pub horizon: usize,
    /// Step (s).
    pub dt: f64,
    /// How the run ended.
    pub summary: RunSummary,
    /// One record per lane change.
    pub records: Vec<LaneChangeRecord>,
    /// What was learned, to be saved or carried into another scenario.
    pub experience: Experience,
}

/// The paper's three styles, by name.
pub const PRESET_STYLES: [(&str, Style); 3] = [
    ("aggressive", Style::AGGRESSIVE),
    ("neutral", Style::NEUTRAL),
    ("cautious", Style::CAUTIOUS),
];

/// The aggregator options of a config: its own table if given, else the method's.
pub fn aggregator_options(config: &LearnConfig) -> AggregatorOptions {
    config
        .aggregator
        .clone()
        .unwrap_or_else(|| match config.method {
            Method::Paper => AggregatorOptions::paper(),
            Method::Palc => AggregatorOptions::default(),
        })
}

/// Builds the scenario of a config and checks the paper's premise in it: the
/// standard ALC is later and slower than each of the paper's styles. The error
/// names the scenario and what does not hold.
pub fn prepare(config: &LearnConfig) -> Result<Setup, HarnessError> {
    config.validate()?;
    let label = config.label();
    let scene = Scene::for_cell(&config.traffic, &config.cell()?)?;
    let setup = Setup::new(&scene, &config.planning, &label)?;
    setup
        .check_conservative(&config.planning.standard_alc, &PRESET_STYLES)
        .map_err(|reason| HarnessError::Scenario {
            scenario: label,
            reason,
        })?;
    Ok(setup)
}

/// Runs the lesson-learning loop of `config`, starting from `experience` if given.
pub fn run(
    config: &LearnConfig,
    experience: Option<&Experience>,
    observer: &mut dyn Observer,
) -> Result<RunResult, HarnessError> {
    let setup = prepare(config)?;
    let options = aggregator_options(config);
    options.validate()?;
    let k = setup.horizon;
    let dt = setup.dt;
    let standard = setup.standard_lane_change(&config.planning.standard_alc);
    let standard_weights = config.standard_weights.weights(&standard, k, dt);

    let mut experience = match experience {
        Some(previous) => {
            let mut carried = previous.clone();
            carried.weights = previous.weights_for(k, dt)?;
            carried.metadata.dt = dt;
            carried.metadata.scenario = config.label();
            carried
        }
        None => Experience::new(
            config.user.style.clone(),
            config.label(),
            config.method.name(),
            standard_weights,
            dt,
        )?,
    };
    let mut planner = Planner::new(PlannerConfig {
        horizon: k,
        dt,
        lateral_bounds_mode: match config.method {
            Method::Paper => LateralBoundsMode::Hard,
            Method::Palc => config.planner.lateral_bounds_mode,
        },
        ..config.planner.clone()
    })?;

    let nominal = config.user.style()?;
    let mut user = match config.user.spread {
        Some(spread) => User::with_spread(nominal, spread)?,
        None => User::deterministic(nominal)?,
    };
    let nominal_expected = setup
        .expected(&nominal)
        .ok_or_else(|| HarnessError::Scenario {
            scenario: config.label(),
            reason: "the user does not change lanes within the horizon".to_owned(),
        })?;
    let nominal_l = nominal_expected.sample(k, dt);

    let stopping = config.stopping;
    let threshold = config.planning.takeover_threshold_m;
    let mut records: Vec<LaneChangeRecord> = Vec::new();
    let mut takeovers = 0;
    let mut streak = 0;
    // The scenario without weights or zone: the aggregator fills both in.
    let template = problem(&setup, experience.weights.clone(), Vec::new());
    let (first_problem, _) = plan_problem(
        &planner,
        &experience,
        &template,
        &scenes(&setup, None),
        &options,
    )?;
    let started = Instant::now();
    let mut next_plan: Plan = planner.plan(&first_problem)?;
    let mut pending_times = PartTimes {
        plan_s: started.elapsed().as_secs_f64(),
        ..PartTimes::default()
    };
    let outcome = loop {
        let style = user.next_style();
        let expected = setup.expected(&style).ok_or_else(|| HarnessError::Scenario {
            scenario: config.label(),
            reason: format!(
                "a drawn user (headway {:.3} s, duration {:.3} s) does not change lanes within the horizon",
                style.time_headway_s, style.lane_change_duration_s
            ),
        })?;
        let drive = execute(&setup, next_plan.clone(), expected, threshold)?;
        let expected_l = &drive.expected_l;
        let record = LaneChangeRecord {
            index: records.len(),
            takeovers_before: takeovers,
            takeover: drive.takeover,
            max_deviation_m: drive.max_deviation_m,
            perceived_safety_ratio: drive.perceived_safety_ratio,
            times: pending_times,
            dt,
            planned_l: drive.plan.states.iter().map(|x| x.l).collect(),
            expected_l: expected_l.clone(),
            driven_l: drive.driven.iter().map(|x| x.l).collect(),
            with_spread: user.has_spread(),
            nominal_plan_taken_over: first_takeover(&nominal_l, expected_l, threshold).is_some(),
            learning_error: None,
        };
        observer.lane_change(&record);
        records.push(record);
        pending_times = PartTimes::default();

        if let Some(takeover) = drive.takeover {
            takeovers += 1;
            streak = 0;
            if takeovers >= stopping.max_takeovers {
                break Outcome::CapReached;
            }
            let lesson = lesson(config.method, &setup, &drive, takeover.step)?;
            let outcome =
                match learn_from_lesson(&mut planner, &experience, &lesson, &template, &options) {
                    Ok(outcome) => outcome,
                    // A lesson the method cannot learn from (e.g. the paper's expert
                    // infeasible in a hard zone) leaves the experience as it was: the
                    // next lane change repeats the plan, and the cap counts it.
                    Err(error) => {
                        if let Some(last) = records.last_mut() {
                            last.learning_error = Some(error.to_string());
                        }
                        continue;
                    }
                };
            let t = outcome.timings;
            pending_times = PartTimes {
                zone_fit_s: t.zone_fit_seconds,
                bounds_s: t.bounds_seconds,
                expert_s: t.expert_seconds,
                correction_s: t.correction_seconds,
                plan_s: t.plan_seconds,
            };
            experience = outcome.experience;
            next_plan = outcome.plan;
        } else {
            streak += 1;
        }
        if success(&records, streak, &stopping) {
            break Outcome::Personalized;
        }
        if records.len()
            >= stopping
                .max_lane_changes
                .max(stopping.max_takeovers + stopping.success_streak)
        {
            break Outcome::CapReached;
        }
    };

    let window = &records[records.len().saturating_sub(stopping.spread_window)..];
    let rate = |f: fn(&LaneChangeRecord) -> bool| {
        window.iter().filter(|r| f(r)).count() as f64 / window.len().max(1) as f64
    };
    let summary = RunSummary {
        outcome,
        takeovers: match outcome {
            Outcome::Personalized => takeovers,
            Outcome::CapReached => stopping.max_takeovers.max(takeovers),
        },
        lane_changes: records.len(),
        final_max_deviation_m: records.last().map_or(0.0, |r| r.max_deviation_m),
        final_takeover_rate: rate(|r| r.takeover.is_some()),
        ceiling_takeover_rate: rate(|r| r.nominal_plan_taken_over),
    };
    observer.finished(&summary);
    Ok(RunResult {
        label: config.label(),
        method: config.method,
        horizon: k,
        dt,
        summary,
        records,
        experience,
    })
}

/// Whether the run has succeeded: `success_streak` takeover-free lane changes in a
/// row for a deterministic user; for a user with spread, the takeover rate over the
/// last window within the margin of the nominal plan's rate on the same draws.
fn success(
    records: &[LaneChangeRecord],
    streak: usize,
    stopping: &crate::config::StoppingConfig,
) -> bool {
    let with_spread = records.last().is_some_and(|r| r.with_spread);
    if !with_spread {
        return streak >= stopping.success_streak;
    }
    if records.len() < stopping.spread_window {
        return false;
    }
    let window = &records[records.len() - stopping.spread_window..];
    let n = window.len() as f64;
    let taken = window.iter().filter(|r| r.takeover.is_some()).count() as f64 / n;
    let ceiling = window.iter().filter(|r| r.nominal_plan_taken_over).count() as f64 / n;
    taken <= ceiling + stopping.spread_margin
}

/// The zone filter's view of each planning step: the previous plan's position
/// (or lane keeping before any plan) and the predicted vehicles.
fn scenes(setup: &Setup, previous: Option<&[State]>) -> Vec<StepScene> {
    (0..=setup.horizon)
        .map(|i| {
            let (ego_s, reference_l) = previous
                .map_or((setup.ego_speed * i as f64 * setup.dt, 0.0), |states| {
                    (states[i].s, states[i].l)
                });
            StepScene {
                ego_s,
                reference_l,
                ego_speed: setup.ego_speed,
                preceding: setup.preceding[i],
                adjacent: setup.adjacent[i],
            }
        })
        .collect()
}

/// Turns a taken-over lane change into a lesson, labelled by the method's rule.
fn lesson(
    method: Method,
    setup: &Setup,
    drive: &Drive,
    takeover_step: usize,
) -> Result<Lesson, HarnessError> {
    let mut samples = Vec::new();
    let mut push = |state: &State, i: usize, driver: Driver| -> Result<(), HarnessError> {
        let Some(safe) = label(method, driver) else {
            return Ok(());
        };
        let x = features(
            Default::default(),
            &FeatureInput {
                ego_s: state.s,
                ego_l: state.l,
                ego_speed: setup.ego_speed,
                preceding: drive.preceding[i],
                adjacent: drive.adjacent[i],
            },
        )?;
        samples.push(Sample::new(
            x,
            if safe { Label::Safe } else { Label::Unsafe },
        ));
        Ok(())
    };
    for (i, state) in drive.driven.iter().enumerate() {
        let driver = if i < takeover_step {
            Driver::System
        } else {
            Driver::User
        };
        push(state, i, driver)?;
    }
    for (i, state) in drive.plan.states.iter().enumerate().skip(takeover_step) {
        push(state, i, Driver::Rejected)?;
    }
    Ok(Lesson {
        planned: drive.plan.clone(),
        executed: drive.driven.clone(),
        takeover_step,
        samples,
        step_scenes: scenes(setup, Some(&drive.plan.states)),
    })
}
