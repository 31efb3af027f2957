//! The lesson-learning loop of paper Fig. 2 as an executor (in the shape of
//! argmin's `Executor`): [`LearningLoop::new`] prepares the scenario and the first
//! plan, [`LearningLoop::step`] drives one lane change and, on a takeover, learns
//! from it, [`LearningLoop::termination`] says whether the run is over, and
//! [`LearningLoop::run`] repeats the step until it is.
//!
//! The loop's state is split as argmin splits solver and state: the scenario
//! ([`Scenario`]: the set-up, the user, the problem template, the safety layer's
//! fallback, the closed-loop driver), the learner ([`Learner`]: the planner, the
//! method's [`Personalization`], the experience and the next plan) and the run
//! ([`run_state::RunState`]: records and counters, all that the stopping rules
//! read). The config is resolved once, at the top, into the scenario and a
//! [`Policy`].

mod checks;
mod live;
mod repeat;
mod run_state;

use std::time::Instant;

use palc_aggregator::{
    AggregatorError, AggregatorOptions, Experience, StepOutcome, Timings, learn_from_lesson,
    plan_problem,
};
use palc_planner::{LateralBoundsMode, Plan, Planner, PlannerConfig, Problem};
use palc_user::{Expectation, User};

use crate::HarnessError;
use crate::carry::{Names, rehearse};
use crate::closed_loop::ClosedLoop;
use crate::config::{LearnConfig, StoppingConfig};
use crate::drive::{Drive, execute_in, judge, plan_safety, problem};
use crate::driver::CarriedBelief;
use crate::lesson::{lesson, scenes, zone_feature_set};
use crate::method::Method;
use crate::observer::{DriverEvidence, LessonEvent, Observer};
use crate::onset::start_clear_of_vehicles_beside;
use crate::personalization::{self, LessonPaths, Personalization};
use crate::record::{ClosedLoopStats, FrozenEvaluation, LaneChangeRecord, Outcome, RunResult};
use crate::refusal::Refusal;
use crate::safety::{SafetyMetrics, Violation};
use crate::scenario::{aggregator_options, prepare_for};
use crate::setup::Setup;
use crate::world::World;

use repeat::{LastDrive, LastFailure};
use run_state::{RunState, termination};

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
    policy: Policy,
    scenario: Scenario,
    learner: Learner,
    run: RunState,
}

/// How the method learns and when the run stops: the config's method, options
/// and stopping rules, resolved once.
#[derive(Debug, Clone)]
struct Policy {
    method: Method,
    options: AggregatorOptions,
    stopping: StoppingConfig,
    /// Whether plans follow a user who drove at a speed of its own after a
    /// takeover (`follow_user_speed`, off under the safety layer, where the ego's
    /// speed is the ACC's that keeps the safe distance).
    follow_user_speed: bool,
}

/// The scenario of a run: the set-up, the user, the problem template and what
/// drives a plan besides the planner (the safety layer's fallback, closed loop).
#[derive(Debug)]
struct Scenario {
    label: String,
    setup: Setup,
    user: Box<dyn User>,
    /// The user's nominal expected lane change: the ceiling of a user with spread.
    nominal: Expectation,
    /// The scenario without weights or zone: the aggregator fills both in.
    template: Problem,
    /// With the safety layer on, the standard ALC's plan and its predicted safety
    /// (checked safe): what the layer drives when it refuses the learned plan.
    fallback: Option<(Plan, SafetyMetrics)>,
    /// With `[planning.closed_loop]` on, the closed-loop driver.
    closed_loop: Option<ClosedLoop>,
    /// The last closed-loop drive in palc's own traffic, repeated from equal inputs.
    last_closed_loop: LastDrive,
    /// The simulator the lane changes are driven in, when not palc's own traffic.
    world: Option<Box<dyn World>>,
}

/// What the method has learned and will drive next.
#[derive(Debug)]
struct Learner {
    planner: Planner,
    personalization: Box<dyn Personalization>,
    experience: Experience,
    next_plan: Plan,
    /// Compute time of the step that produced `next_plan`.
    pending_times: Timings,
    /// What the driver estimate believed when the experience was carried in.
    carried_belief: Option<CarriedBelief>,
    /// The last lesson that could not be learned, repeated from equal inputs.
    last_failure: LastFailure,
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
        checks::check_own_lane_change(&setup, user.as_ref(), &nominal)?;
        let options = aggregator_options(config);
        options.validate()?;
        let policy = Policy {
            method: config.method,
            stopping: config.stopping,
            follow_user_speed: options.follow_user_speed && !setup.safety.enforce,
            options,
        };
        let personalization = personalization::for_options(&policy.options);
        let given_experience = experience.is_some();
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
        let carried = personalization.carry(names, &standard_weights, &setup, experience)?;
        let (experience, rehearsal) = (carried.experience, carried.rehearsal);
        let carried_belief = carried.belief;
        let mut planner = Planner::new(PlannerConfig {
            horizon: setup.horizon,
            dt: setup.dt,
            lateral_bounds_mode: match config.method {
                Method::Paper => LateralBoundsMode::Hard,
                Method::Palc => config.planner.lateral_bounds_mode,
            },
            ..config.planner.clone()
        })?;
        let enforce = setup.safety.enforce;
        let fallback = if enforce {
            let plan = planner.plan(&problem(&setup, standard_weights.clone(), Vec::new()))?;
            let safety = plan_safety(&setup, &plan)?;
            if let Some(violation) = safety.first_violation {
                return Err(HarnessError::Refused {
                    scenario: label,
                    refusal: Box::new(Refusal::StandardPlanUnsafe { violation }),
                });
            }
            Some((plan, safety))
        } else {
            None
        };
        let template = problem(&setup, experience.weights.clone(), Vec::new());
        let options = &policy.options;
        let experience = match rehearsal {
            Some(path) => rehearse(&mut planner, &setup, &template, experience, &path, options),
            None => experience,
        };
        let (first_problem, _) = plan_problem(
            &planner,
            &experience,
            &template,
            &scenes(&setup, None),
            options,
        )?;
        let closed_loop = ClosedLoop::for_config(
            config.planning.closed_loop,
            enforce.then_some(&standard_weights),
            &setup,
            planner.config(),
        )?;
        let started = Instant::now();
        let next_plan = planner.plan(&first_problem)?;
        if given_experience {
            check_on_road(&setup, &label, &next_plan)?;
        }
        let pending_times = Timings {
            plan_s: started.elapsed().as_secs_f64(),
            ..Timings::default()
        };
        Ok(LearningLoop {
            policy,
            scenario: Scenario {
                label,
                setup,
                user,
                nominal,
                template,
                fallback,
                closed_loop,
                last_closed_loop: LastDrive::default(),
                world: None,
            },
            learner: Learner {
                planner,
                personalization,
                experience,
                next_plan,
                pending_times,
                carried_belief,
                last_failure: LastFailure::default(),
            },
            run: RunState::default(),
        })
    }

    /// This run with every lane change driven in `world`'s traffic instead of
    /// palc's own: the world places the scenario's scene at the trigger, moves the
    /// other vehicles, and the loop (plans, the user, lessons, safety) reads them
    /// as it reads its own ([`World`]).
    #[must_use]
    pub fn in_world(mut self, world: Box<dyn World>) -> Self {
        self.scenario.world = Some(world);
        self
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
        let index = self.run.records.len();
        let (drive, record) = self.drive_next_plan(index, observer)?;
        self.conclude(index, &drive, record, observer)
    }

    /// Records lane change `index` (driven as `drive`) and, on a takeover within
    /// the cap, learns from it: the second half of [`LearningLoop::step`].
    fn conclude(
        &mut self,
        index: usize,
        drive: &Drive,
        record: LaneChangeRecord,
        observer: &mut dyn Observer,
    ) -> Result<&LaneChangeRecord, HarnessError> {
        observer.lane_change(&record);
        self.run.count(record);
        self.learner.pending_times = Timings::default();
        match drive.takeover {
            Some(takeover) if self.run.takeovers < self.policy.stopping.max_takeovers => {
                self.learn(index, drive, takeover.step, observer)?;
            }
            Some(_) => {}
            None => {
                let driven_l: Vec<f64> = drive.driven.iter().map(|x| x.l).collect();
                let setup = &self.scenario.setup;
                (self.learner.personalization).accepted(&driven_l, setup.dt, setup.target_l);
            }
        }
        Ok(&self.run.records[index])
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
        termination(&self.policy.stopping, &self.run)
    }

    /// Runs [`LearningLoop::step`] until [`LearningLoop::termination`] says the run
    /// is over, then tells the observer the summary. A caller that drove some steps
    /// itself (lane change by lane change, as the Python package's iterator does)
    /// gets the same result: a run that is already over takes no further step.
    ///
    /// # Errors
    /// Those of [`LearningLoop::step`].
    pub fn run(mut self, observer: &mut dyn Observer) -> Result<RunResult, HarnessError> {
        let outcome = loop {
            // A fresh loop is never over: every cap and the success streak are >= 1.
            if let Some(outcome) = self.termination() {
                break outcome;
            }
            self.step(observer)?;
        };
        self.finish(outcome, observer)
    }

    /// Ends the run here with `outcome`, whatever [`LearningLoop::termination`]
    /// says: the summary (after the evaluation phase of a user with spread, see
    /// `loop.frozen_lane_changes`) is told to the observer and returned with the
    /// records and the experience. A drive of varied scenes ends each scene after
    /// one lane change this way.
    ///
    /// # Errors
    /// Those of [`LearningLoop::step`], from the evaluation phase.
    pub fn finish(
        mut self,
        outcome: Outcome,
        observer: &mut dyn Observer,
    ) -> Result<RunResult, HarnessError> {
        let mut summary = self.run.summary(outcome, &self.policy.stopping);
        summary.frozen = self.frozen_evaluation(observer)?;
        observer.finished(&summary);
        Ok(RunResult {
            label: self.scenario.label,
            method: self.policy.method,
            horizon: self.scenario.setup.horizon,
            dt: self.scenario.setup.dt,
            summary,
            records: self.run.records,
            experience: self.learner.experience,
            carried_belief: self.learner.carried_belief,
        })
    }

    /// The lane changes driven so far.
    pub fn records(&self) -> &[LaneChangeRecord] {
        &self.run.records
    }

    /// What has been learned so far.
    pub fn experience(&self) -> &Experience {
        &self.learner.experience
    }

    /// The plan the next lane change will drive.
    pub fn next_plan(&self) -> &Plan {
        &self.learner.next_plan
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
        let (plan, closed_loop) = match self.drive_closed_loop(&plan, refusal.is_some())? {
            Some((plan, stats)) => (plan, Some(stats)),
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

    /// With `[planning.closed_loop]` on, `first` driven in closed loop (the
    /// drive before it handed back when its inputs are the same, [`LastDrive`]).
    fn drive_closed_loop(
        &mut self,
        first: &Plan,
        fell_back: bool,
    ) -> Result<Option<(Plan, ClosedLoopStats)>, HarnessError> {
        let scenario = &mut self.scenario;
        let Some(driver) = &scenario.closed_loop else {
            return Ok(None);
        };
        let (experience, options) = (&self.learner.experience, &self.policy.options);
        if let Some(world) = scenario.world.as_deref_mut() {
            let driven = driver.drive_in(
                &scenario.setup,
                experience,
                options,
                first,
                fell_back,
                Some(world),
            )?;
            return Ok(Some(driven));
        }
        let last = &mut scenario.last_closed_loop;
        if let Some(driven) = last.get(experience, options, first, fell_back) {
            return Ok(Some(driven));
        }
        let driven =
            driver.drive_in(&scenario.setup, experience, options, first, fell_back, None)?;
        last.keep(experience, options, first, fell_back, &driven);
        Ok(Some(driven))
    }

    /// The evaluation phase of a user with spread (`loop.frozen_lane_changes`):
    /// the plan the run ended with, driven again against new draws of the user
    /// without learning, and the nominal plan judged on the same draws. These lane
    /// changes are not records of the run and observers see only their refusals.
    fn frozen_evaluation(
        &mut self,
        observer: &mut dyn Observer,
    ) -> Result<Option<FrozenEvaluation>, HarnessError> {
        let lane_changes = self.policy.stopping.frozen_lane_changes;
        if !self.scenario.user.has_spread() || lane_changes == 0 {
            return Ok(None);
        }
        let mut frozen = FrozenEvaluation {
            lane_changes,
            ..FrozenEvaluation::default()
        };
        for i in 0..lane_changes {
            let (drive, record) = self.drive_next_plan(self.run.records.len() + i, observer)?;
            frozen.takeovers += usize::from(drive.takeover.is_some());
            frozen.ceiling_takeovers += usize::from(record.nominal_plan_taken_over);
        }
        Ok(Some(frozen))
    }

    /// The safety layer (with `safety.enforce`): the learned plan if it is safe, else the standard ALC's
    /// (checked safe when the loop was prepared), with the predicted safety of the
    /// plan returned and the reason for a refusal.
    fn checked_plan(&self) -> Result<(Plan, SafetyMetrics, Option<Violation>), HarnessError> {
        let next_plan = &self.learner.next_plan;
        let predicted = plan_safety(&self.scenario.setup, next_plan)?;
        match (predicted.first_violation, &self.scenario.fallback) {
            (Some(violation), Some((plan, safety))) => Ok((plan.clone(), *safety, Some(violation))),
            _ => Ok((next_plan.clone(), predicted, None)),
        }
    }

    /// Asks the user for the next lane change (a user with spread draws anew),
    /// drives `plan` in the scene, and judges the nominal lane change against the
    /// same draw (the ceiling).
    fn drive(&mut self, plan: Plan) -> Result<(Drive, bool), HarnessError> {
        let scenario = &mut self.scenario;
        let setup = &scenario.setup;
        let expectation = (scenario.user.next(&setup.user_scene()))
            .map_err(|error| HarnessError::from_user(&scenario.label, error))?;
        let horizon_s = setup.horizon as f64 * setup.dt;
        if expectation.lane_change.end_s() > horizon_s + 1e-9 {
            return Err(HarnessError::Refused {
                scenario: scenario.label.clone(),
                refusal: Box::new(Refusal::DrawBeyondHorizon {
                    user: scenario.user.name().to_owned(),
                    start_s: expectation.lane_change.start_s,
                    duration_s: expectation.lane_change.duration_s,
                    horizon_s,
                }),
            });
        }
        let user = scenario.user.as_ref();
        let ceiling = if user.has_spread() {
            let nominal = &scenario.nominal.states[..=setup.horizon];
            judge(setup, user, &expectation, nominal)?.is_some()
        } else {
            false
        };
        let world = scenario.world.as_deref_mut().map(|w| w as &mut dyn World);
        let drive = execute_in(setup, plan, user, &expectation, world)?;
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
        let template = &mut self.scenario.template;
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
        if let Some(driver) = &mut self.scenario.closed_loop {
            self.scenario.last_closed_loop.forget();
            driver.plan_at_speeds(&template.reference_speed, template.terminal)?;
        }
        Ok(())
    }

    /// The record of a driven lane change.
    fn record(&self, drive: &Drive, nominal_plan_taken_over: bool) -> LaneChangeRecord {
        LaneChangeRecord {
            index: self.run.records.len(),
            takeovers_before: self.run.takeovers,
            takeover: drive.takeover,
            max_deviation_m: drive.max_deviation_m,
            perceived_safety_ratio: drive.perceived_safety_ratio,
            times: self.learner.pending_times,
            dt: self.scenario.setup.dt,
            planned_l: drive.plan.states.iter().map(|x| x.l).collect(),
            expected_l: drive.expected_l.clone(),
            driven_l: drive.driven.iter().map(|x| x.l).collect(),
            with_spread: self.scenario.user.has_spread(),
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
    /// `takeover_step`) and tells the observer what it produced: the lesson keeps
    /// what was driven and, separately, what the method's [`Personalization`]
    /// demonstrates from it.
    fn learn(
        &mut self,
        lane_change: usize,
        drive: &Drive,
        takeover_step: usize,
        observer: &mut dyn Observer,
    ) -> Result<(), HarnessError> {
        let setup = &self.scenario.setup;
        let learner = &mut self.learner;
        // The samples update the zone, so they take its features (Eq. 1 or a variant).
        let feature_set = zone_feature_set(&learner.experience, &self.policy.options);
        let mut lesson = lesson(self.policy.method, setup, drive, takeover_step, feature_set)?;
        let driven_l: Vec<f64> = drive.driven.iter().map(|x| x.l).collect();
        let planned_l: Vec<f64> = drive.plan.states.iter().map(|x| x.l).collect();
        let paths = LessonPaths::new(
            &driven_l,
            &planned_l,
            takeover_step,
            setup.dt,
            setup.target_l,
        )
        .with_own_lane_change(learner.experience.own_lane_change.as_ref());
        let demonstration = learner.personalization.demonstrate(&paths);
        if let Some(path) = &demonstration.path {
            let mut states = lesson.executed.clone();
            for (state, &l) in states.iter_mut().zip(path) {
                state.l = l;
            }
            lesson.demonstration = Some(states);
        }
        if self.policy.follow_user_speed && drive.user_speed_differs {
            self.follow_user_speed(drive, takeover_step)?;
        }
        let (setup, learner) = (&self.scenario.setup, &mut self.learner);
        let (template, options) = (&self.scenario.template, &self.policy.options);
        let experience = &learner.experience;
        let result: Result<StepOutcome, &AggregatorError> = match learner
            .last_failure
            .get(experience, &lesson, template, options)
        {
            Some(error) => Err(error),
            None => match learn_from_lesson(
                &mut learner.planner,
                experience,
                &lesson,
                template,
                options,
            ) {
                Ok(outcome) => Ok(outcome),
                Err(error) => Err(learner
                    .last_failure
                    .keep(experience, &lesson, template, options, error)),
            },
        };
        let lane_change_duration_s = setup.standard_alc.lane_change_duration_s;
        match result {
            Ok(mut outcome) => {
                if let Some(start_s) = demonstration.start_s {
                    // Nobody moves into a vehicle beside them
                    // (docs/experiments/0097-no-start-beside-a-vehicle.md).
                    let takeover_s = takeover_step as f64 * setup.dt;
                    let start_s = start_clear_of_vehicles_beside(setup, start_s, takeover_s);
                    let experience = &mut outcome.experience;
                    learner
                        .personalization
                        .observe_start(experience, setup, start_s);
                }
                (learner.personalization).observe_lane_change(&mut outcome.experience, &paths);
                observer.lesson(&LessonEvent::Learned {
                    lane_change,
                    lesson: &lesson,
                    outcome: &outcome,
                    driver: DriverEvidence {
                        onsets: &outcome.experience.onsets,
                        lane_change_duration_s,
                    },
                });
                learner.pending_times = outcome.timings;
                learner.experience = outcome.experience;
                learner.next_plan = outcome.plan;
            }
            Err(error) => {
                observer.lesson(&LessonEvent::Failed {
                    lane_change,
                    lesson: &lesson,
                    error,
                    driver: DriverEvidence {
                        onsets: &learner.experience.onsets,
                        lane_change_duration_s,
                    },
                });
                self.run.learning_failures += 1;
                self.run.last_lesson_failed = true;
                if let Some(record) = self.run.records.get_mut(lane_change) {
                    record.learning_error = Some(error.to_string());
                }
            }
        }
        Ok(())
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

/// The plan's centre line stays between the road's edges (within 1 µm), else
/// [`HarnessError::ExperienceOffRoad`] at its first step past them.
fn check_on_road(setup: &Setup, label: &str, plan: &Plan) -> Result<(), HarnessError> {
    const EDGE_TOLERANCE_M: f64 = 1e-6;
    let road = setup.scene.road();
    let (right_edge, left_edge) = (road.right_edge(), road.left_edge());
    let inside =
        |l: f64| (right_edge - EDGE_TOLERANCE_M..=left_edge + EDGE_TOLERANCE_M).contains(&l);
    match plan.states.iter().position(|x| !inside(x.l)) {
        None => Ok(()),
        Some(step) => Err(HarnessError::ExperienceOffRoad {
            scenario: label.to_owned(),
            step,
            l: plan.states[step].l,
            right_edge,
            left_edge,
        }),
    }
}
