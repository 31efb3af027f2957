//! The lesson-learning loop of paper Fig. 2 as an executor (in the shape of
//! argmin's `Executor`): [`LearningLoop::new`] prepares the scenario and the first
//! plan, [`LearningLoop::step`] drives one lane change and, on a takeover, learns
//! from it, [`LearningLoop::termination`] says whether the run is over, and
//! [`LearningLoop::run`] repeats the step until it is.

use std::time::Instant;

use palc_aggregator::{
    AggregatorError, AggregatorOptions, Experience, Representation, StepOutcome, Timings,
    learn_from_lesson, plan_problem,
};
use palc_planner::{LateralBoundsMode, Plan, Planner, PlannerConfig, Problem};

use crate::HarnessError;
use crate::carry::{Names, rehearse, starting_experience};
use crate::closed_loop::ClosedLoop;
use crate::config::{LearnConfig, StoppingConfig};
use crate::drive::{
    Drive, execute, judge, own_lane_change_enters_beside, plan_safety, problem, states_safety,
};
use crate::lesson::{lesson, scenes, zone_feature_set};
use crate::method::Method;
use crate::observer::{LessonEvent, Observer};
use crate::onset::{UserLaneChange, onset_at};
use crate::record::{FrozenEvaluation, LaneChangeRecord, Outcome, RunResult, RunSummary};
use crate::refusal::Refusal;
use crate::safety::{SafetyMetrics, Violation};
use crate::scenario::{aggregator_options, prepare_for};
use crate::scene_lessons::SceneLessons;
use crate::setup::Setup;
use palc_user::{Expectation, User};

/// One run of the lesson-learning loop (paper Fig. 2): plan with the experience,
/// let the simulated user judge the lane change, and on a takeover label the lesson,
/// update the zone and correct the weights (Eqs. 24-36), until the user stops
/// taking over or a cap is reached.
///
/// ```no_run
/// use palc_harness::{LearnConfig, LearningLoop, NoObserver};
///
/// let config = LearnConfig::from_toml_str(&std::fs::read_to_string("configs/learn.toml")?)?;
/// let mut run = LearningLoop::new(&config, None)?;
/// while run.termination().is_none() {
///     let record = run.step(&mut NoObserver)?;
///     println!("lane change {}: takeover {:?}", record.index, record.takeover);
/// }
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug)]
pub struct LearningLoop {
    label: String,
    method: Method,
    stopping: StoppingConfig,
    options: AggregatorOptions,
    setup: Setup,
    planner: Planner,
    user: Box<dyn User>,
    /// The user's nominal expected lane change: the ceiling of a user with spread.
    nominal: Expectation,
    /// The scenario without weights or zone: the aggregator fills both in.
    template: Problem,
    experience: Experience,
    next_plan: Plan,
    /// With the safety layer on, the standard ALC's plan and its predicted safety
    /// (checked safe): what the layer drives when it refuses `next_plan`.
    fallback: Option<(Plan, SafetyMetrics)>,
    /// With `[planning.closed_loop]` on, the closed-loop driver.
    closed_loop: Option<ClosedLoop>,
    /// The lessons of this run's scene, averaged with `average_lessons`.
    scene_lessons: SceneLessons,
    /// Compute time of the step that produced `next_plan`.
    pending_times: Timings,
    records: Vec<LaneChangeRecord>,
    takeovers: usize,
    /// Takeover-free lane changes since the last takeover.
    streak: usize,
    learning_failures: usize,
    /// Whether the last lane change's lesson failed.
    last_lesson_failed: bool,
}

impl LearningLoop {
    /// Prepares the run of `config`: builds and checks the scenario
    /// ([`crate::prepare`]), the planner, the simulated user and the first plan, starting
    /// from `experience` if given (its weights resampled to this scenario's horizon
    /// and step), else from the standard ALC's weights.
    ///
    /// # Errors
    /// Invalid config or options, a scenario the paper's premise does not hold in
    /// ([`HarnessError::Refused`]), a user without a sane lane change in it, or a
    /// first plan that cannot be solved.
    pub fn new(
        config: &LearnConfig,
        experience: Option<&Experience>,
    ) -> Result<Self, HarnessError> {
        let user = config
            .user
            .simulated(config.planning.takeover_threshold_m)?;
        Self::with_user(config, experience, Box::new(user))
    }

    /// As [`LearningLoop::new`], with a user of the caller's own instead of the
    /// config's `[user]`: a recorded driver, a person at a simulator, another
    /// model. The horizon is extended to cover the user's nominal lane change when
    /// it ends after the standard ALC's.
    ///
    /// # Errors
    /// As [`LearningLoop::new`].
    pub fn with_user(
        config: &LearnConfig,
        experience: Option<&Experience>,
        user: Box<dyn User>,
    ) -> Result<Self, HarnessError> {
        let (setup, nominal) = prepare_for(config, user.as_ref())?;
        // The user's own lane change, driven, must not make it take over (its
        // perceived-safety bound against its own gap acceptance).
        if let Some((step, cause)) = judge(
            &setup,
            user.as_ref(),
            &nominal,
            &nominal.states[..=setup.horizon],
        )? {
            return Err(HarnessError::Refused {
                scenario: config.label(),
                refusal: Box::new(Refusal::OwnLaneChangeTakenOver {
                    user: user.name().to_owned(),
                    step,
                    cause,
                }),
            });
        }
        // Under the longitudinal guard, the user's own lane change driven in the
        // scene must not collide: a scene in which it does has no sane lane change
        // for this user (without the guard, the paper's constant speeds run most of
        // them into the slower target-lane vehicle, and the scene is driven as is).
        if setup.acc.guard {
            let own = states_safety(&setup, &nominal.states[..=setup.horizon])?;
            if own.collision {
                return Err(HarnessError::Refused {
                    scenario: config.label(),
                    refusal: Box::new(Refusal::OwnLaneChangeCollides {
                        user: user.name().to_owned(),
                        vehicles: collided_with(&own),
                    }),
                });
            }
        }
        // The user's own lane change, driven by the user, must not enter the
        // target lane beside a vehicle of it: the user would hold there, so it
        // would take over any other plan and then teach a hold it does not expect.
        if let Some(step) = own_lane_change_enters_beside(&setup, user.as_ref(), &nominal)? {
            return Err(HarnessError::Refused {
                scenario: config.label(),
                refusal: Box::new(Refusal::OwnLaneChangeEntersBeside {
                    user: user.name().to_owned(),
                    step,
                }),
            });
        }
        let options = aggregator_options(config);
        options.validate()?;
        // The standard ALC's weights at this scenario's horizon: a fresh
        // experience's, and the safety layer's fallback.
        let standard_lane_change = setup.standard_lane_change(&config.planning.standard_alc);
        let standard_weights =
            (config.standard_weights).weights(&standard_lane_change, setup.horizon, setup.dt);
        let label = config.label();
        let names = Names {
            user: config.user.style.name(),
            scenario: &label,
            method: config.method.name(),
        };
        let (experience, rehearsal) =
            starting_experience(names, &standard_weights, &setup, experience, &options)?;
        let mut planner = Planner::new(PlannerConfig {
            horizon: setup.horizon,
            dt: setup.dt,
            lateral_bounds_mode: match config.method {
                Method::Paper => LateralBoundsMode::Hard,
                Method::Palc => config.planner.lateral_bounds_mode,
            },
            ..config.planner.clone()
        })?;
        let enforce = config.planning.safety.enforce;
        let fallback = if enforce {
            let plan = planner.plan(&problem(&setup, standard_weights.clone(), Vec::new()))?;
            let safety = plan_safety(&setup, &plan)?;
            if let Some(violation) = safety.first_violation {
                return Err(HarnessError::Refused {
                    scenario: config.label(),
                    refusal: Box::new(Refusal::StandardPlanUnsafe { violation }),
                });
            }
            Some((plan, safety))
        } else {
            None
        };
        let template = problem(&setup, experience.weights.clone(), Vec::new());
        let experience = match rehearsal {
            Some(path) => rehearse(&mut planner, &setup, &template, experience, &path, &options),
            None => experience,
        };
        let (first_problem, _) = plan_problem(
            &planner,
            &experience,
            &template,
            &scenes(&setup, None),
            &options,
        )?;
        let closed_loop = ClosedLoop::for_config(
            config.planning.closed_loop,
            enforce.then_some(&standard_weights),
            &setup,
            planner.config(),
        )?;
        let started = Instant::now();
        let next_plan = planner.plan(&first_problem)?;
        let pending_times = Timings {
            plan_s: started.elapsed().as_secs_f64(),
            ..Timings::default()
        };
        Ok(LearningLoop {
            label: config.label(),
            method: config.method,
            stopping: config.stopping,
            options,
            setup,
            planner,
            user,
            nominal,
            template,
            experience,
            next_plan,
            fallback,
            closed_loop,
            scene_lessons: SceneLessons::default(),
            pending_times,
            records: Vec::new(),
            takeovers: 0,
            streak: 0,
            learning_failures: 0,
            last_lesson_failed: false,
        })
    }

    /// Drives one lane change with the current plan and, when the user takes over
    /// and the takeover cap is not reached, learns from the lesson (Fig. 2's
    /// learning branch). Observers see the lane change, then the lesson's
    /// [`LessonEvent`]. Returns the lane change's record.
    ///
    /// A lesson the method cannot learn from is not an error of the run: the
    /// experience and the plan stay as they were, observers see
    /// [`LessonEvent::Failed`], and the record keeps the message.
    ///
    /// # Errors
    /// A drawn user who does not change lanes within the horizon, or a plan, drive
    /// or feature error.
    pub fn step(&mut self, observer: &mut dyn Observer) -> Result<&LaneChangeRecord, HarnessError> {
        let index = self.records.len();
        let (drive, record) = self.drive_next_plan(index, observer)?;
        observer.lane_change(&record);
        self.records.push(record);
        self.pending_times = Timings::default();
        self.last_lesson_failed = false;
        match drive.takeover {
            Some(takeover) => {
                self.takeovers += 1;
                self.streak = 0;
                if self.takeovers < self.stopping.max_takeovers {
                    self.learn(index, &drive, takeover.step, observer)?;
                }
            }
            None => {
                self.streak += 1;
                self.count_accepted(&drive);
            }
        }
        Ok(&self.records[index])
    }

    /// How the run ends, once it has: [`Outcome::CapReached`] when the takeovers
    /// reach `loop.max_takeovers`; [`Outcome::Personalized`] on the success rule
    /// (`success_streak` takeover-free lane changes in a row, the paper's three; for
    /// a user with spread, the window's takeover rate within the margin of the
    /// nominal plan's); [`Outcome::CapReached`] at the lane-change cap
    /// (`max(max_lane_changes, max_takeovers + success_streak)`). `None` while the
    /// run goes on.
    ///
    /// After a failed lesson only the takeover cap ends the run: the next lane
    /// change repeats the plan and is judged instead.
    pub fn termination(&self) -> Option<Outcome> {
        termination(
            &self.stopping,
            &self.records,
            Progress {
                takeovers: self.takeovers,
                streak: self.streak,
                last_lesson_failed: self.last_lesson_failed,
            },
        )
    }

    /// Runs [`LearningLoop::step`] until [`LearningLoop::termination`] says the run
    /// is over, then tells the observer the summary.
    ///
    /// # Errors
    /// Those of [`LearningLoop::step`].
    pub fn run(mut self, observer: &mut dyn Observer) -> Result<RunResult, HarnessError> {
        let outcome = loop {
            self.step(observer)?;
            if let Some(outcome) = self.termination() {
                break outcome;
            }
        };
        let mut summary = self.summary(outcome);
        summary.frozen = self.frozen_evaluation(observer)?;
        observer.finished(&summary);
        Ok(RunResult {
            label: self.label,
            method: self.method,
            horizon: self.setup.horizon,
            dt: self.setup.dt,
            summary,
            records: self.records,
            experience: self.experience,
        })
    }

    /// The lane changes driven so far.
    pub fn records(&self) -> &[LaneChangeRecord] {
        &self.records
    }

    /// What has been learned so far.
    pub fn experience(&self) -> &Experience {
        &self.experience
    }

    /// The plan the next lane change will drive.
    pub fn next_plan(&self) -> &Plan {
        &self.next_plan
    }

    /// Drives the next plan once (through the safety layer and, when configured,
    /// in closed loop) against the user's next lane change, and records it as lane
    /// change `index`; refusals go to `observer`.
    fn drive_next_plan(
        &mut self,
        index: usize,
        observer: &mut dyn Observer,
    ) -> Result<(Drive, LaneChangeRecord), HarnessError> {
        let (plan, planned_safety, refusal) = self.checked_plan()?;
        let (plan, closed_loop) = match &self.closed_loop {
            Some(driver) => {
                let (plan, stats) = driver.drive(
                    &self.setup,
                    &self.experience,
                    &self.options,
                    &plan,
                    refusal.is_some(),
                )?;
                (plan, Some(stats))
            }
            None => (plan, None),
        };
        let refusal = refusal.or(closed_loop.and_then(|c| c.first_refusal));
        if let Some(violation) = &refusal {
            observer.safety_refusal(index, violation);
        }
        let (drive, nominal_plan_taken_over) = self.drive(plan)?;
        let mut record = self.record(&drive, nominal_plan_taken_over);
        record.index = index;
        record.planned_safety = planned_safety;
        record.safety_refusal = refusal;
        record.closed_loop = closed_loop;
        Ok((drive, record))
    }

    /// The evaluation phase of a user with spread (`loop.frozen_lane_changes`):
    /// the plan the run ended with, driven again against new draws of the user
    /// without learning, and the nominal plan judged on the same draws. These lane
    /// changes are not records of the run and observers see only their refusals.
    fn frozen_evaluation(
        &mut self,
        observer: &mut dyn Observer,
    ) -> Result<Option<FrozenEvaluation>, HarnessError> {
        let lane_changes = self.stopping.frozen_lane_changes;
        if !self.user.has_spread() || lane_changes == 0 {
            return Ok(None);
        }
        let mut frozen = FrozenEvaluation {
            lane_changes,
            ..FrozenEvaluation::default()
        };
        for i in 0..lane_changes {
            let (drive, record) = self.drive_next_plan(self.records.len() + i, observer)?;
            frozen.takeovers += usize::from(drive.takeover.is_some());
            frozen.ceiling_takeovers += usize::from(record.nominal_plan_taken_over);
        }
        Ok(Some(frozen))
    }

    /// The safety layer (with `safety.enforce`): the learned plan if it is safe, else the standard ALC's
    /// (checked safe when the loop was prepared), with the predicted safety of the
    /// plan returned and the reason for a refusal.
    fn checked_plan(&self) -> Result<(Plan, SafetyMetrics, Option<Violation>), HarnessError> {
        let predicted = plan_safety(&self.setup, &self.next_plan)?;
        match (predicted.first_violation, &self.fallback) {
            (Some(violation), Some((plan, safety))) => Ok((plan.clone(), *safety, Some(violation))),
            _ => Ok((self.next_plan.clone(), predicted, None)),
        }
    }

    /// Asks the user for the next lane change (a user with spread draws anew),
    /// drives `plan` in the scene, and judges the nominal lane change against the
    /// same draw (the ceiling).
    fn drive(&mut self, plan: Plan) -> Result<(Drive, bool), HarnessError> {
        let expectation = (self.user.next(&self.setup.user_scene()))
            .map_err(|error| HarnessError::from_user(&self.label, error))?;
        let horizon_s = self.setup.horizon as f64 * self.setup.dt;
        if expectation.lane_change.end_s() > horizon_s + 1e-9 {
            return Err(HarnessError::Refused {
                scenario: self.label.clone(),
                refusal: Box::new(Refusal::DrawBeyondHorizon {
                    user: self.user.name().to_owned(),
                    start_s: expectation.lane_change.start_s,
                    duration_s: expectation.lane_change.duration_s,
                    horizon_s,
                }),
            });
        }
        let ceiling = if self.user.has_spread() {
            let nominal = &self.nominal.states[..=self.setup.horizon];
            judge(&self.setup, self.user.as_ref(), &expectation, nominal)?.is_some()
        } else {
            false
        };
        let drive = execute(&self.setup, plan, self.user.as_ref(), &expectation)?;
        Ok((drive, ceiling))
    }

    /// `follow_user_speed`, for a user who drove at a speed of its own after taking
    /// over at `takeover_step` in `drive` (another acceleration than the ego's ACC
    /// would have commanded): the plans from now on move along the road as the
    /// user did. Their reference speed from that step on, and their terminal speed
    /// (and, under the ACC, terminal station) are the user's; before it, the
    /// scenario's.
    fn follow_user_speed(
        &mut self,
        drive: &Drive,
        takeover_step: usize,
    ) -> Result<(), HarnessError> {
        let template = &mut self.template;
        let from = takeover_step.min(template.reference_speed.len());
        for (reference, state) in template.reference_speed[from..]
            .iter_mut()
            .zip(&drive.driven[from..])
        {
            *reference = state.v;
        }
        if let Some(end) = drive.driven.get(template.reference_speed.len()) {
            template.terminal.v = end.v;
            if template.terminal.s.is_some() {
                template.terminal.s = Some(end.s);
            }
        }
        if let Some(driver) = &mut self.closed_loop {
            driver.plan_at_speeds(&template.reference_speed, template.terminal)?;
        }
        Ok(())
    }

    /// The record of a driven lane change.
    fn record(&self, drive: &Drive, nominal_plan_taken_over: bool) -> LaneChangeRecord {
        LaneChangeRecord {
            index: self.records.len(),
            takeovers_before: self.takeovers,
            takeover: drive.takeover,
            max_deviation_m: drive.max_deviation_m,
            perceived_safety_ratio: drive.perceived_safety_ratio,
            times: self.pending_times,
            dt: self.setup.dt,
            planned_l: drive.plan.states.iter().map(|x| x.l).collect(),
            expected_l: drive.expected_l.clone(),
            driven_l: drive.driven.iter().map(|x| x.l).collect(),
            with_spread: self.user.has_spread(),
            nominal_plan_taken_over,
            safety: drive.safety,
            user_safety: drive.user_safety,
            planned_safety: SafetyMetrics::default(),
            safety_refusal: None,
            closed_loop: None,
            learning_error: None,
        }
    }

    /// Learns from the lesson of lane change `lane_change` (taken over at
    /// `takeover_step`) and tells the observer what it produced.
    fn learn(
        &mut self,
        lane_change: usize,
        drive: &Drive,
        takeover_step: usize,
        observer: &mut dyn Observer,
    ) -> Result<(), HarnessError> {
        // The samples update the zone, so they take its features (Eq. 1 or a variant).
        let feature_set = zone_feature_set(&self.experience, &self.options);
        let mut lesson = lesson(self.method, &self.setup, drive, takeover_step, feature_set)?;
        let driven_l: Vec<f64> = drive.driven.iter().map(|x| x.l).collect();
        let (dt, target_l) = (self.setup.dt, self.setup.target_l);
        let user = UserLaneChange::fit(&driven_l, takeover_step, dt, target_l);
        if let (Some(user), Representation::RelativeOnset) = (user, self.options.representation) {
            // The expert follows the user's whole path: before the takeover, the
            // quintic fitted to what the user drove after it, not the old plan.
            let path = user.path(&driven_l, takeover_step, dt);
            for (state, l) in lesson.executed.iter_mut().zip(path) {
                state.l = l;
            }
        }
        // Whether the lesson shows where the user starts in this scene's gap.
        let mut onset_seen = true;
        if let (Some(user), true) = (user, self.options.average_lessons) {
            // The expert follows the mean of this scene's lessons (scene_lessons.rs).
            // A lesson in a gap the scene's lane changes do not point to leaves the
            // plan as it is: its expert is the plan driven.
            let path: Vec<f64> = lesson.executed.iter().map(|x| x.l).collect();
            let mean = self.scene_lessons.add(user, path, dt);
            onset_seen = mean.includes_lesson;
            let path =
                (mean.path).unwrap_or_else(|| drive.plan.states.iter().map(|x| x.l).collect());
            for (state, l) in lesson.executed.iter_mut().zip(path) {
                state.l = l;
            }
        }
        // Under the safety layer the ego's speed is the ACC's that keeps the safe
        // distance, which a learned speed must not override.
        if self.options.follow_user_speed && drive.user_speed_differs && !self.setup.safety.enforce
        {
            self.follow_user_speed(drive, takeover_step)?;
        }
        let result: Result<StepOutcome, AggregatorError> = learn_from_lesson(
            &mut self.planner,
            &self.experience,
            &lesson,
            &self.template,
            &self.options,
        );
        match result {
            Ok(outcome) => {
                observer.lesson(&LessonEvent::Learned {
                    lane_change,
                    lesson: &lesson,
                    outcome: &outcome,
                });
                self.pending_times = outcome.timings;
                self.experience = outcome.experience;
                self.next_plan = outcome.plan;
                if let (Some(user), true) = (user, onset_seen) {
                    self.observe_onset(user.start_s);
                }
            }
            Err(error) => {
                observer.lesson(&LessonEvent::Failed {
                    lane_change,
                    lesson: &lesson,
                    error: &error,
                });
                self.learning_failures += 1;
                self.last_lesson_failed = true;
                if let Some(record) = self.records.get_mut(lane_change) {
                    record.learning_error = Some(error.to_string());
                }
            }
        }
        Ok(())
    }

    /// Counts a lane change the user accepted in this scene's lessons (with
    /// `average_lessons`): it tells which gap of the target lane the user takes.
    fn count_accepted(&mut self, drive: &Drive) {
        if !self.options.average_lessons {
            return;
        }
        let driven_l: Vec<f64> = drive.driven.iter().map(|x| x.l).collect();
        let (dt, target_l) = (self.setup.dt, self.setup.target_l);
        if let Some(driven) = UserLaneChange::fit(&driven_l, 0, dt, target_l) {
            self.scene_lessons.accept(driven.start_s);
        }
    }

    /// Records the user's start `start_s` seen in a lesson in the experience:
    /// merged into this scene's onset, which becomes the anchor of the weights.
    fn observe_onset(&mut self, start_s: f64) {
        let onsets = &mut self.experience.onsets;
        // This scene's onset so far, taken out to be merged with the new one; the
        // onsets of earlier scenes tell which waits were for the leader's gap.
        let this_scene = if onsets
            .last()
            .is_some_and(|o| o.scenario == self.setup.label)
        {
            onsets.pop()
        } else {
            None
        };
        let Some(observed) = onset_at(&self.setup, start_s, onsets) else {
            onsets.extend(this_scene);
            return;
        };
        let merged = match this_scene {
            Some(last) => last.merged(&observed),
            None => observed,
        };
        self.experience.anchor_s = Some(merged.time_s);
        onsets.push(merged);
    }

    /// The summary of a run that ended with `outcome`.
    fn summary(&self, outcome: Outcome) -> RunSummary {
        let records = &self.records;
        let window = &records[records.len().saturating_sub(self.stopping.spread_window)..];
        let rate = |f: fn(&LaneChangeRecord) -> bool| {
            window.iter().filter(|r| f(r)).count() as f64 / window.len().max(1) as f64
        };
        RunSummary {
            outcome,
            takeovers: self.takeovers,
            cap: self.stopping.max_takeovers,
            lane_changes: records.len(),
            learning_failures: self.learning_failures,
            final_max_deviation_m: records.last().map_or(0.0, |r| r.max_deviation_m),
            final_takeover_rate: rate(|r| r.takeover.is_some()),
            ceiling_takeover_rate: rate(|r| r.nominal_plan_taken_over),
            frozen: None,
        }
    }
}

/// Runs the lesson-learning loop of `config`, starting from `experience` if given:
/// [`LearningLoop::new`] then [`LearningLoop::run`].
pub fn run(
    config: &LearnConfig,
    experience: Option<&Experience>,
    observer: &mut dyn Observer,
) -> Result<RunResult, HarnessError> {
    LearningLoop::new(config, experience)?.run(observer)
}

/// The counters [`termination`] reads besides the records.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
struct Progress {
    /// Takeovers so far.
    takeovers: usize,
    /// Takeover-free lane changes since the last takeover.
    streak: usize,
    /// Whether the last lane change's lesson failed.
    last_lesson_failed: bool,
}

/// The rule of [`LearningLoop::termination`].
fn termination(
    stopping: &StoppingConfig,
    records: &[LaneChangeRecord],
    progress: Progress,
) -> Option<Outcome> {
    if progress.takeovers >= stopping.max_takeovers {
        return Some(Outcome::CapReached);
    }
    if progress.last_lesson_failed {
        return None;
    }
    if success(records, progress.streak, stopping) {
        return Some(Outcome::Personalized);
    }
    let lane_change_cap = stopping
        .max_lane_changes
        .max(stopping.max_takeovers + stopping.success_streak);
    (records.len() >= lane_change_cap).then_some(Outcome::CapReached)
}

/// Whether the run has succeeded: `success_streak` takeover-free lane changes in a
/// row for a deterministic user; for a user with spread, the takeover rate over the
/// last window within the margin of the nominal plan's rate on the same draws.
fn success(records: &[LaneChangeRecord], streak: usize, stopping: &StoppingConfig) -> bool {
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

/// The vehicles a collision of `metrics` overlapped, with their smallest net gap.
fn collided_with(metrics: &SafetyMetrics) -> String {
    let roles = [
        ("the preceding vehicle", metrics.min_gap_preceding_m),
        ("the target lane's lead", metrics.min_gap_target_lead_m),
        ("the target lane's lag", metrics.min_gap_target_lag_m),
    ];
    let overlapped: Vec<String> = (roles.iter())
        .filter_map(|(role, gap)| {
            gap.filter(|g| *g <= 0.0)
                .map(|g| format!("{role} at {g:.1} m"))
        })
        .collect();
    if overlapped.is_empty() {
        "another vehicle".to_owned()
    } else {
        overlapped.join(", ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::record::Takeover;

    fn stopping() -> StoppingConfig {
        StoppingConfig {
            max_takeovers: 4,
            success_streak: 3,
            spread_window: 5,
            spread_margin: 0.1,
            max_lane_changes: 12,
            frozen_lane_changes: 0,
        }
    }

    /// A lane change, taken over or not, of a user with or without spread whose
    /// nominal plan would (not) have been taken over.
    fn record(
        index: usize,
        taken: bool,
        with_spread: bool,
        nominal_taken: bool,
    ) -> LaneChangeRecord {
        LaneChangeRecord {
            index,
            takeovers_before: 0,
            takeover: taken.then_some(Takeover {
                step: 10,
                time_s: 1.0,
                distance_m: 20.0,
                deviation_m: 0.4,
                cause: Default::default(),
            }),
            max_deviation_m: if taken { 0.4 } else { 0.1 },
            perceived_safety_ratio: if taken { 0.5 } else { 1.0 },
            times: Timings::default(),
            dt: 0.1,
            planned_l: Vec::new(),
            expected_l: Vec::new(),
            driven_l: Vec::new(),
            with_spread,
            nominal_plan_taken_over: nominal_taken,
            safety: SafetyMetrics::default(),
            user_safety: SafetyMetrics::default(),
            planned_safety: SafetyMetrics::default(),
            safety_refusal: None,
            closed_loop: None,
            learning_error: None,
        }
    }

    /// Records of a deterministic user from a pattern: `T` a takeover, `-` none.
    fn deterministic(pattern: &str) -> Vec<LaneChangeRecord> {
        pattern
            .chars()
            .enumerate()
            .map(|(i, c)| record(i, c == 'T', false, false))
            .collect()
    }

    /// Replays `pattern` through the counters the loop keeps.
    fn progress(pattern: &str) -> Progress {
        pattern.chars().fold(Progress::default(), |p, c| match c {
            'T' => Progress {
                takeovers: p.takeovers + 1,
                streak: 0,
                ..p
            },
            _ => Progress {
                streak: p.streak + 1,
                ..p
            },
        })
    }

    fn judge(pattern: &str) -> Option<Outcome> {
        termination(&stopping(), &deterministic(pattern), progress(pattern))
    }

    #[test]
    fn a_deterministic_user_personalizes_after_the_success_streak() {
        assert_eq!(judge(""), None);
        assert_eq!(judge("T-"), None);
        assert_eq!(judge("T--"), None);
        assert_eq!(judge("T---"), Some(Outcome::Personalized));
        assert_eq!(judge("---"), Some(Outcome::Personalized));
    }

    #[test]
    fn the_takeover_cap_ends_the_run_before_anything_else() {
        assert_eq!(judge("TTT"), None);
        assert_eq!(judge("TTTT"), Some(Outcome::CapReached));
        assert_eq!(judge("T-T-T--T"), Some(Outcome::CapReached));
        let failed = Progress {
            last_lesson_failed: true,
            ..progress("TTTT")
        };
        let records = deterministic("TTTT");
        assert_eq!(
            termination(&stopping(), &records, failed),
            Some(Outcome::CapReached)
        );
    }

    #[test]
    fn after_a_failed_lesson_only_the_takeover_cap_is_checked() {
        // With spread, a window within the margin would be success, and 12 lane
        // changes reach the lane-change cap; a failed lesson defers both.
        let records: Vec<_> = (0..12).map(|i| record(i, i == 11, true, i == 11)).collect();
        let p = Progress {
            takeovers: 1,
            streak: 0,
            last_lesson_failed: true,
        };
        assert_eq!(termination(&stopping(), &records, p), None);
        let p = Progress {
            last_lesson_failed: false,
            ..p
        };
        assert_eq!(
            termination(&stopping(), &records, p),
            Some(Outcome::Personalized)
        );
    }

    #[test]
    fn a_user_with_spread_is_judged_on_the_window_against_the_ceiling() {
        let s = stopping();
        // Five lane changes, two taken over, the nominal plan would have had one:
        // 0.4 > 0.2 + 0.1, not yet personalized.
        let pattern = [true, false, true, false, false];
        let records: Vec<_> = (pattern.iter().enumerate())
            .map(|(i, &t)| record(i, t, true, i == 0))
            .collect();
        let p = Progress {
            takeovers: 2,
            streak: 2,
            last_lesson_failed: false,
        };
        assert_eq!(termination(&s, &records, p), None);
        // Too short a window is never success, whatever the streak.
        assert_eq!(
            termination(&s, &records[..4], Progress { streak: 9, ..p }),
            None
        );
        // The ceiling at two of five: 0.4 <= 0.4 + 0.1.
        let records: Vec<_> = (pattern.iter().enumerate())
            .map(|(i, &t)| record(i, t, true, i < 2))
            .collect();
        assert_eq!(termination(&s, &records, p), Some(Outcome::Personalized));
    }

    #[test]
    fn a_user_with_spread_stops_at_the_lane_change_cap() {
        let s = stopping();
        let records: Vec<_> = (0..12)
            .map(|i| record(i, i % 2 == 0, true, false))
            .collect();
        let p = Progress {
            takeovers: 3,
            streak: 1,
            last_lesson_failed: false,
        };
        assert_eq!(termination(&s, &records[..11], p), None);
        assert_eq!(termination(&s, &records, p), Some(Outcome::CapReached));
        // The cap is at least max_takeovers + success_streak lane changes.
        let s = StoppingConfig {
            max_lane_changes: 1,
            ..s
        };
        assert_eq!(termination(&s, &records[..6], p), None);
        assert_eq!(termination(&s, &records[..7], p), Some(Outcome::CapReached));
    }
}
