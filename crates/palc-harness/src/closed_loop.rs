//! Closed-loop execution of a lane change (`[planning.closed_loop]`, off by
//! default): the ego drives the first `N` steps of a plan, then plans again from
//! the state it has reached, with fresh predictions of the other vehicles and the
//! same learned weights and zone, and so on to the end of the horizon.
//!
//! **Shrinking horizon.** A re-plan at step `e` covers the remaining `K − e`
//! steps and keeps the terminal conditions of the one-shot plan (lateral position,
//! speed and, under the ACC, station at step `K`). The weights are time-indexed
//! (column `i − 1` weighs stage `i`, which is how the planner decides *when* to
//! move), so a re-plan at step `e` takes columns `e..K` of the experience's
//! weights: every stage keeps the weight it had in the one-shot plan. A receding
//! horizon of fixed length would need weights and terminal conditions beyond step
//! `K`, which nothing has learned, and would push the end of the lane change
//! further out at every re-plan. With exact predictions the shrinking horizon
//! gives back the one-shot plan (the cost is a sum of stage costs, so the tail of
//! an optimal plan is optimal for the tail problem).
//!
//! **Predictions.** As [`crate::Setup::new`] does, by rolling out a copy of the
//! current scene with every background vehicle on its own model; the ego in that
//! rollout follows the plan it is executing (in `Setup::new` it keeps its lane,
//! as no plan exists yet).
//!
//! **Safety layer.** With `planning.safety.enforce`, every re-plan is driven to its
//! end in a copy of the current scene before the ego drives it; a plan with a
//! safe-distance violation is refused (a recorded [`Violation`]) and the lane
//! change falls back to the standard ALC's weights, without the zone, re-planned
//! from the same state; if that plan is unsafe as well, the ego keeps the plan it
//! is driving (checked when it was made). A re-plan the planner cannot solve also
//! keeps the current plan, and is counted.
//!
//! The result is one trajectory over steps `0..=K`, what the system drives when
//! nobody takes over; [`crate::advanced::execute`] then drives it with the user,
//! who takes over at the first driven step that deviates from the expected one,
//! exactly as in open loop, so that lessons are labelled the same way.

use palc_aggregator::{AggregatorOptions, Experience, plan_problem};
use palc_planner::{
    Control, Plan, Planner, PlannerConfig, Position, State, Terminal, Weights, features,
};
use palc_traffic::Scene;
use palc_zone_filter::StepScene;

use crate::HarnessError;
use crate::drive::problem;
use crate::guard::{drive_states, guarded_step};
use crate::record::ClosedLoopStats;
use crate::safety::{SafetyMetrics, SafetyMonitor, Violation};
use crate::setup::Setup;
use crate::world::{Traffic, World};

pub use crate::config::ClosedLoopConfig;

/// Which weights a re-plan uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Policy {
    /// The experience's weights and zone.
    Learned,
    /// The standard ALC's weights, without the zone (the safety layer's fallback).
    Standard,
}

/// The closed-loop driver of one scenario: the scenario, the planner's settings,
/// the period and, with the safety layer, the standard ALC's weights.
#[derive(Debug, Clone)]
pub struct ClosedLoop {
    planner: PlannerConfig,
    period: usize,
    /// The standard ALC's weights at the scenario's horizon, when the safety layer
    /// is on (the fallback).
    standard: Option<Weights>,
    /// The reference speeds (`K`) and the terminal condition the plans follow, when
    /// not the scenario's ([`ClosedLoop::plan_at_speeds`]).
    speeds: Option<(Vec<f64>, Terminal)>,
}

/// One re-plan's result: the plan, or why the ego keeps the current one.
#[derive(Debug, Clone, PartialEq)]
pub enum Replan {
    /// A plan the ego can drive (checked safe, or not checked).
    Drive(Plan),
    /// The safety layer refused the plan.
    Refused(Violation),
    /// The planner failed.
    Failed,
}

impl ClosedLoop {
    /// A closed-loop driver re-planning every `period` steps with `planner`'s
    /// settings (its horizon is set per re-plan); `standard` is the standard ALC's
    /// weights at the scenario's horizon when the safety layer is on.
    ///
    /// # Errors
    /// [`HarnessError::InvalidConfig`] for a period of 0 steps.
    pub fn new(
        planner: PlannerConfig,
        period: usize,
        standard: Option<Weights>,
    ) -> Result<Self, HarnessError> {
        if period == 0 {
            return Err(HarnessError::InvalidConfig {
                field: "planning.closed_loop.replan_period_s".to_owned(),
                value: 0.0,
                bound: "at least one step".to_owned(),
            });
        }
        Ok(Self {
            planner,
            period,
            standard,
            speeds: None,
        })
    }

    /// Steps between re-plans.
    pub fn period(&self) -> usize {
        self.period
    }

    /// Whether the safety layer's fallback (the standard ALC's weights) is set.
    pub fn has_fallback(&self) -> bool {
        self.standard.is_some()
    }

    /// Re-plans with `reference_speed` (one per step of the scenario's horizon) and
    /// `terminal` instead of the scenario's speeds: those the learning loop's plans
    /// follow once they have learned the user's
    /// ([`AggregatorOptions::follow_user_speed`]).
    ///
    /// # Errors
    /// [`HarnessError::InvalidConfig`] for a reference of another length than the
    /// planner's horizon, or a speed that is not finite and non-negative.
    pub fn plan_at_speeds(
        &mut self,
        reference_speed: &[f64],
        terminal: Terminal,
    ) -> Result<(), HarnessError> {
        let k = self.planner.horizon;
        if reference_speed.len() != k {
            return Err(HarnessError::InvalidConfig {
                field: "closed_loop.reference_speed".to_owned(),
                value: reference_speed.len() as f64,
                bound: format!("one speed per step of the horizon, {k}"),
            });
        }
        let speeds = reference_speed.iter().chain([&terminal.v]).enumerate();
        if let Some((i, &v)) = speeds
            .into_iter()
            .find(|(_, v)| !(v.is_finite() && **v >= 0.0))
        {
            return Err(HarnessError::InvalidConfig {
                field: if i < k {
                    format!("closed_loop.reference_speed[{i}]")
                } else {
                    "closed_loop.terminal.v".to_owned()
                },
                value: v,
                bound: "a finite speed >= 0 m/s".to_owned(),
            });
        }
        self.speeds = Some((reference_speed.to_vec(), terminal));
        Ok(())
    }

    /// The closed-loop driver of `closed` in the scenario of `setup`, planning with
    /// `planner`'s settings and, under the safety layer, falling back to
    /// `standard_weights`; `None` when `planning.closed_loop.enabled` is off.
    ///
    /// # Errors
    /// [`HarnessError::InvalidConfig`] naming `planning.closed_loop.replan_period_s`
    /// for a period longer than the horizon.
    pub(crate) fn for_config(
        closed: ClosedLoopConfig,
        standard_weights: Option<&Weights>,
        setup: &Setup,
        planner: &PlannerConfig,
    ) -> Result<Option<Self>, HarnessError> {
        if !closed.enabled {
            return Ok(None);
        }
        closed.validate("planning.closed_loop", setup.dt)?;
        closed.check_horizon("planning.closed_loop", setup.dt, setup.horizon)?;
        let standard = standard_weights.cloned();
        Self::new(planner.clone(), closed.period_steps(setup.dt), standard).map(Some)
    }

    /// Drives a lane change in closed loop from `first` (the plan the safety layer
    /// let through, or its fallback when `fell_back`), re-planning with
    /// `experience` (weights at the scenario's horizon) and `options`. Returns the
    /// trajectory the system drives over steps `0..=K` and what the loop did.
    ///
    /// # Errors
    /// Scene errors while driving, and aggregator errors that no re-plan can
    /// recover from (invalid options or experience).
    pub fn drive(
        &self,
        setup: &Setup,
        experience: &Experience,
        options: &AggregatorOptions,
        first: &Plan,
        fell_back: bool,
    ) -> Result<(Plan, ClosedLoopStats), HarnessError> {
        self.drive_in(setup, experience, options, first, fell_back, None)
    }

    /// As [`ClosedLoop::drive`], in `world`'s traffic when given: the world places
    /// the scene at the trigger and moves the other vehicles, and every re-plan
    /// predicts them from the states it reported ([`crate::World`]).
    ///
    /// # Errors
    /// Those of [`ClosedLoop::drive`], and the world's failure.
    pub fn drive_in(
        &self,
        setup: &Setup,
        experience: &Experience,
        options: &AggregatorOptions,
        first: &Plan,
        fell_back: bool,
        world: Option<&mut dyn World>,
    ) -> Result<(Plan, ClosedLoopStats), HarnessError> {
        let k = setup.horizon;
        let mut stats = ClosedLoopStats {
            fallback_step: fell_back.then_some(0),
            ..ClosedLoopStats::default()
        };
        let mut policy = if fell_back && self.standard.is_some() {
            Policy::Standard
        } else {
            Policy::Learned
        };
        let mut traffic = Traffic::of(world);
        let mut scene = setup.scene.clone();
        traffic.place(&scene, setup.dt)?;
        let mut current = first.clone();
        // The step of the trajectory at which `current` starts.
        let mut start = 0;
        let mut states = vec![first.states[0]];
        let mut controls = Vec::with_capacity(k);
        let mut lateral_violation = vec![first.lateral_violation.first().copied().unwrap_or(0.0)];
        let mut step = 0;
        while step < k {
            let until = (step + self.period).min(k);
            for i in step..until {
                let j = i - start;
                let previous = states.last().copied().unwrap_or(current.states[j]);
                let next = guarded_step(
                    setup,
                    &scene,
                    &previous,
                    &current.states[j],
                    &current.states[j + 1],
                );
                controls.push(current.controls[j]);
                states.push(next);
                lateral_violation
                    .push(current.lateral_violation.get(j + 1).copied().unwrap_or(0.0));
                traffic.advance(&mut scene, setup.dt, setup.ego_state(&next))?;
            }
            step = until;
            // Re-plan while at least two steps remain.
            if k - step < 2 {
                continue;
            }
            // The rest of the current plan, from the state driven (the plan's own
            // unless the longitudinal guard held the ego back).
            let mut tail = current.states[step - start..].to_vec();
            if let (Some(first), Some(&driven)) = (tail.first_mut(), states.last()) {
                *first = driven;
            }
            let tail = &tail[..];
            let mut outcome =
                self.replan(setup, experience, options, &scene, tail, step, policy)?;
            stats.replans += 1;
            if let Replan::Refused(violation) = outcome {
                stats.refusals += 1;
                stats.first_refusal.get_or_insert(violation);
                if policy == Policy::Learned && self.standard.is_some() {
                    policy = Policy::Standard;
                    stats.fallback_step = Some(step);
                    outcome =
                        self.replan(setup, experience, options, &scene, tail, step, policy)?;
                    stats.replans += 1;
                    if let Replan::Refused(_) = outcome {
                        stats.refusals += 1;
                    }
                }
            }
            match outcome {
                Replan::Drive(plan) => {
                    current = plan;
                    start = step;
                }
                Replan::Failed => stats.replan_failures += 1,
                Replan::Refused(_) => {}
            }
        }
        let plan = driven_plan(
            setup,
            experience,
            (states, controls, lateral_violation),
            first,
        )?;
        Ok((plan, stats))
    }

    /// One re-plan at step `step` of the lane change from `scene`, the scene
    /// reached there; `tail` is the rest of the plan the ego is driving (its first
    /// state is the current one, `K − step + 1` states). The plan covers the
    /// remaining `K − step` steps with the columns `step..K` of the policy's
    /// weights; with the safety layer on it is driven to its end in a copy of
    /// `scene` and refused on a violation.
    ///
    /// # Errors
    /// [`HarnessError::InvalidConfig`] for a `step` outside `1..K` or a `tail` of
    /// another length; scene errors of the rollouts.
    #[allow(clippy::too_many_arguments)]
    pub fn replan(
        &self,
        setup: &Setup,
        experience: &Experience,
        options: &AggregatorOptions,
        scene: &Scene,
        tail: &[State],
        step: usize,
        policy: Policy,
    ) -> Result<Replan, HarnessError> {
        let k = setup.horizon;
        if step == 0 || step >= k || tail.len() != k - step + 1 {
            return Err(HarnessError::InvalidConfig {
                field: "closed_loop.replan.step".to_owned(),
                value: step as f64,
                bound: format!(
                    "a step in 1..{k} with the {} remaining states of the plan",
                    k.saturating_sub(step) + 1
                ),
            });
        }
        let remaining = k - step;
        let (preceding, adjacent) = predict(setup, scene, tail)?;
        let mut template = problem(setup, experience.weights.clone(), Vec::new());
        if let Some((reference_speed, terminal)) = &self.speeds {
            template.reference_speed.clone_from(reference_speed);
            template.terminal = *terminal;
        }
        template.initial = tail[0];
        template.reference_speed.drain(..step);
        template.preceding = (preceding[..remaining].iter())
            .map(|p| Position { s: p[0], l: p[1] })
            .collect();
        template.adjacent = (adjacent[..remaining].iter())
            .map(|p| Position { s: p[0], l: p[1] })
            .collect();
        template.lateral_bounds = vec![None; remaining + 1];
        let shifted = |weights: &Weights| {
            Weights::from_columns(weights.columns()[step.min(weights.horizon())..].to_vec())
        };
        let policy_experience = match (policy, &self.standard) {
            (Policy::Standard, Some(standard)) => Experience {
                weights: shifted(standard),
                zone: None,
                ..experience.clone()
            },
            _ => Experience {
                weights: shifted(&experience.weights),
                ..experience.clone()
            },
        };
        template.weights = policy_experience.weights.clone();
        // The zone's view of each remaining step: the current plan's position and
        // speed, the fresh predictions.
        let step_scenes: Vec<StepScene> = (0..=remaining)
            .map(|i| {
                let state = tail.get(i).copied().unwrap_or(tail[tail.len() - 1]);
                StepScene {
                    ego_s: state.s,
                    reference_l: state.l,
                    ego_speed: state.v.max(setup.lane_keeping[step + i][1] * 1e-3),
                    preceding: preceding[i],
                    adjacent: adjacent[i],
                }
            })
            .collect();
        let mut planner = Planner::new(PlannerConfig {
            horizon: remaining,
            ..self.planner.clone()
        })?;
        let Ok((problem, _)) = plan_problem(
            &planner,
            &policy_experience,
            &template,
            &step_scenes,
            options,
        ) else {
            return Ok(Replan::Failed);
        };
        let Ok(plan) = planner.plan(&problem) else {
            return Ok(Replan::Failed);
        };
        if self.standard.is_some() {
            let safety = safety_from(setup, scene, &plan.states, step)?;
            if let Some(violation) = safety.first_violation {
                return Ok(Replan::Refused(violation));
            }
        }
        Ok(Replan::Drive(plan))
    }
}

/// `(s − origin_s, l)` of a vehicle per step.
type Positions = Vec<[f64; 2]>;

/// Predicted preceding and adjacent vehicles `(s − origin_s, l)` at the steps of
/// `tail`, from a copy of `scene` in which the ego drives `tail`.
fn predict(
    setup: &Setup,
    scene: &Scene,
    tail: &[State],
) -> Result<(Positions, Positions), HarnessError> {
    let mut rollout = scene.clone();
    let mut preceding = Vec::with_capacity(tail.len());
    let mut adjacent = Vec::with_capacity(tail.len());
    let frame = |v: Option<&palc_traffic::Vehicle>| {
        v.map_or([1e4, 0.0], |v| [v.state.s - setup.origin_s, v.state.l])
    };
    for (i, state) in tail.iter().enumerate() {
        if i > 0 {
            rollout.step(setup.dt, setup.ego_state(state))?;
        }
        preceding.push(frame(rollout.preceding()));
        adjacent.push(frame(rollout.adjacent()));
    }
    Ok((preceding, adjacent))
}

/// The safety of `states` driven from `scene` (reached at `step` of the lane
/// change) to their end, in a copy of it; steps are those of the lane change.
fn safety_from(
    setup: &Setup,
    scene: &Scene,
    states: &[State],
    step: usize,
) -> Result<SafetyMetrics, HarnessError> {
    let mut rollout = scene.clone();
    // The monitor of the whole lane change: its start lane and preceding vehicle
    // are those at the trigger.
    let mut monitor = SafetyMonitor::new(setup.safety, &setup.scene, setup.target_l);
    drive_states(setup, &mut rollout, states, |i, _, scene| {
        monitor.observe(step + i, scene);
        false
    })?;
    Ok(monitor.metrics())
}

/// The trajectory a lane change drove, pieced from its re-plans, as one plan:
/// its features and learned cost under `experience`'s weights (the objective is
/// the learned cost), the first plan's solver statistics.
pub(crate) fn driven_plan(
    setup: &Setup,
    experience: &Experience,
    (states, controls, lateral_violation): (Vec<State>, Vec<Control>, Vec<f64>),
    first: &Plan,
) -> Result<Plan, HarnessError> {
    let full = problem(setup, experience.weights.clone(), Vec::new());
    let features = features(&states, &controls, &full.preceding, &full.adjacent)?;
    let learned_cost = experience.weights.dot(&features).unwrap_or(f64::NAN);
    Ok(Plan {
        states,
        controls,
        objective: learned_cost,
        learned_cost,
        extras: palc_planner::Extras::default(),
        features,
        lateral_violation,
        stats: first.stats,
    })
}
