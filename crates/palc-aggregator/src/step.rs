//! The learning step the harness calls once per takeover.

use std::time::Instant;

use palc_planner::{LateralBound, Plan, Planner, Problem, Weights};
use palc_zone_filter::{StepBounds, StepScene, ZoneModel, lateral_bounds};
use serde::{Deserialize, Serialize};

use crate::{
    AggregatorError, AggregatorOptions, CorrectionInput, Experience, ExpertInput, Lesson,
    project_convex,
};

/// Wall time of each part of one learning step (s): the project's one breakdown of
/// a step's compute time (paper Fig. 13), used by the harness's records and the
/// evaluation's reports alike.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Timings {
    /// Adding the lesson's samples to the zone model (0 without the zone).
    pub zone_fit_s: f64,
    /// Projecting the zone onto lateral bounds, Eqs. (27)-(32) (0 without the zone).
    pub bounds_s: f64,
    /// Building and planning the expert trajectory.
    pub expert_s: f64,
    /// The correction rule, including its inner plans.
    pub correction_s: f64,
    /// The new plan with the corrected weights.
    pub plan_s: f64,
}

impl Timings {
    /// Names of the parts, in the order of [`Timings::parts`].
    pub const PART_NAMES: [&'static str; 5] =
        ["zone fit", "bounds", "expert", "correction", "plan"];

    /// The parts in the order of [`Timings::PART_NAMES`] (s).
    pub fn parts(&self) -> [f64; 5] {
        [
            self.zone_fit_s,
            self.bounds_s,
            self.expert_s,
            self.correction_s,
            self.plan_s,
        ]
    }

    /// The timings of the parts in the order of [`Timings::PART_NAMES`] (s): the
    /// inverse of [`Timings::parts`].
    pub fn from_parts(parts: [f64; 5]) -> Timings {
        let [zone_fit_s, bounds_s, expert_s, correction_s, plan_s] = parts;
        Timings {
            zone_fit_s,
            bounds_s,
            expert_s,
            correction_s,
            plan_s,
        }
    }

    /// Sum of the parts (s).
    pub fn total_s(&self) -> f64 {
        self.parts().iter().sum()
    }
}

/// What the correction rule reported.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct CorrectionReport {
    /// Scaled feature error of the plan with the previous weights against the expert
    /// (incremental rule only).
    pub error_before: Option<f64>,
    /// Scaled feature error of the new plan against the expert (incremental rule only).
    pub error_after: Option<f64>,
    /// Plans solved inside the rule.
    pub inner_solves: usize,
}

/// The result of one learning step.
#[derive(Debug, Clone, PartialEq)]
pub struct StepOutcome {
    /// The updated experience (one more lesson; weights at the planner's horizon and step).
    pub experience: Experience,
    /// The expert trajectory `ψ^E`.
    pub expert: Plan,
    /// The new plan with the corrected weights and the new zone (the next `ψ^(t)`,
    /// Eq. 36).
    pub plan: Plan,
    /// The problem the new plan solved (weights, bounds), for the next lane change.
    pub problem: Problem,
    /// The zone's bounds per step `0..=K`, when the zone is used.
    pub zone_bounds: Option<Vec<StepBounds>>,
    /// What the correction rule reported.
    pub correction: CorrectionReport,
    /// Wall time of each part.
    pub timings: Timings,
}

/// The problem of a plan with what an experience has learned: `template` with its
/// weights replaced by the experience's (resampled to the planner's horizon and step,
/// then projected onto the convex set) and, when `options.use_zone`, its lateral bounds
/// replaced by the zone's wherever the zone gives a bound.
///
/// Zone bounds are not applied at steps 0 and `K`, whose lateral positions the initial
/// and terminal conditions fix (a bound there can only contradict them); where the
/// zone says nothing or finds no safe interval, the template's bound (e.g. the road)
/// stays. Returns the problem and the zone's bounds.
///
/// # Errors
/// Resampling, projection and zone errors; [`AggregatorError::LessonMismatch`] when
/// `step_scenes` is not `K + 1` long while the zone is used.
pub fn plan_problem(
    planner: &Planner,
    experience: &Experience,
    template: &Problem,
    step_scenes: &[StepScene],
    options: &AggregatorOptions,
) -> Result<(Problem, Option<Vec<StepBounds>>), AggregatorError> {
    options.validate()?;
    let weights = current_weights(planner, experience, options)?;
    let bounds = match (&experience.zone, options.use_zone) {
        (Some(zone), true) => Some(zone_bounds(planner, zone, step_scenes, options)?),
        _ => None,
    };
    let problem = with_bounds(template, weights, bounds.as_deref())?;
    Ok((problem, bounds))
}

/// Learns from one lesson: updates the zone (when used), plans the expert, corrects
/// the weights and plans the next lane change.
///
/// `template` carries the scenario (initial state, reference speeds, predictions,
/// terminal condition, lateral bounds of the road); its weights and tracking are
/// replaced. `experience` is not modified: the updated one is in the outcome, so on any
/// error (e.g. [`AggregatorError::ExpertFailed`] for an infeasible expert problem) the
/// caller still holds the experience as it was.
///
/// # Errors
/// Invalid options or lesson, zone and planner errors, as [`AggregatorError`].
pub fn learn_from_lesson(
    planner: &mut Planner,
    experience: &Experience,
    lesson: &Lesson,
    template: &Problem,
    options: &AggregatorOptions,
) -> Result<StepOutcome, AggregatorError> {
    options.validate()?;
    experience.validate()?;
    let horizon = planner.config().horizon;
    let dt = planner.config().dt;
    lesson.validate(horizon, options.use_zone)?;
    let weights = current_weights(planner, experience, options)?;
    let mut timings = Timings::default();

    let start = Instant::now();
    let zone = if options.use_zone {
        let mut zone = match &experience.zone {
            Some(zone) => zone.clone(),
            None => ZoneModel::new(options.zone)?,
        };
        zone.update(&lesson.samples)?;
        Some(zone)
    } else {
        experience.zone.clone()
    };
    timings.zone_fit_s = start.elapsed().as_secs_f64();

    let start = Instant::now();
    let bounds = match (&zone, options.use_zone) {
        (Some(zone), true) => Some(zone_bounds(planner, zone, &lesson.step_scenes, options)?),
        _ => None,
    };
    let plan_problem = with_bounds(template, weights.clone(), bounds.as_deref())?;
    timings.bounds_s = start.elapsed().as_secs_f64();

    let start = Instant::now();
    let generator = options.expert.generator();
    let expert_problem = generator.problem(&ExpertInput {
        template,
        plan_problem: &plan_problem,
        lesson,
        zone_bounds: bounds.as_deref(),
        bounds_config: &options.bounds,
    })?;
    let expert = planner
        .plan(&expert_problem)
        .map_err(|source| AggregatorError::ExpertFailed {
            expert: generator.name(),
            source,
        })?;
    timings.expert_s = start.elapsed().as_secs_f64();

    let start = Instant::now();
    let state = experience
        .apprenticeship
        .as_ref()
        .filter(|_| experience.metadata.dt == dt);
    let input = CorrectionInput {
        weights: &weights,
        planned: &lesson.planned.features,
        expert: &expert.features,
        learnable: &options.learnable_rows,
        scale: &options.feature_scale,
        convex_set: &options.convex_set,
    };
    let mut candidate = plan_problem.clone();
    let (outcome, apprenticeship) =
        options
            .correction
            .correct(&input, state, &mut |w: &Weights| {
                candidate.weights = w.clone();
                planner.plan(&candidate)
            })?;
    timings.correction_s = start.elapsed().as_secs_f64();

    let start = Instant::now();
    let problem = Problem {
        weights: outcome.weights.clone(),
        ..plan_problem
    };
    // The rule has solved this very problem when it measured its best iterate.
    let plan = match outcome.plan {
        Some(plan) => plan,
        None => planner.plan(&problem)?,
    };
    timings.plan_s = start.elapsed().as_secs_f64();

    let mut metadata = experience.metadata.clone();
    metadata.lessons += 1;
    metadata.dt = dt;
    Ok(StepOutcome {
        experience: Experience {
            metadata,
            weights: outcome.weights,
            zone,
            apprenticeship,
            anchor_s: experience.anchor_s,
            onsets: experience.onsets.clone(),
            demonstration: Some(expert.states.iter().map(|x| x.l).collect()),
            own_lane_change: experience.own_lane_change.clone(),
        },
        expert,
        plan,
        problem,
        zone_bounds: bounds,
        correction: CorrectionReport {
            error_before: outcome.error_before,
            error_after: outcome.error_after,
            inner_solves: outcome.inner_solves,
        },
        timings,
    })
}

/// The experience's weights at the planner's horizon and step, projected.
fn current_weights(
    planner: &Planner,
    experience: &Experience,
    options: &AggregatorOptions,
) -> Result<Weights, AggregatorError> {
    let config = planner.config();
    let resampled = experience.weights_for(config.horizon, config.dt)?;
    project_convex(&resampled, &options.convex_set, &options.learnable_rows)
}

fn zone_bounds(
    planner: &Planner,
    zone: &ZoneModel,
    step_scenes: &[StepScene],
    options: &AggregatorOptions,
) -> Result<Vec<StepBounds>, AggregatorError> {
    let expected = planner.config().horizon + 1;
    if step_scenes.len() != expected {
        return Err(AggregatorError::LessonMismatch {
            field: "step_scenes",
            expected,
            found: step_scenes.len(),
        });
    }
    Ok(lateral_bounds(zone, step_scenes, &options.bounds)?)
}

/// `template` with `weights`, no tracking, and the zone's bounds where it gives one
/// (except at steps 0 and `K`).
fn with_bounds(
    template: &Problem,
    weights: Weights,
    zone: Option<&[StepBounds]>,
) -> Result<Problem, AggregatorError> {
    let mut lateral = template.lateral_bounds.clone();
    if let Some(zone) = zone {
        if zone.len() != lateral.len() {
            return Err(AggregatorError::LessonMismatch {
                field: "template.lateral_bounds",
                expected: zone.len(),
                found: lateral.len(),
            });
        }
        let last = lateral.len().saturating_sub(1);
        for (i, bound) in zone.iter().enumerate() {
            if let StepBounds::Bounded { min, max } = *bound {
                if i != 0 && i != last {
                    lateral[i] = Some(LateralBound::new(min, max));
                }
            }
        }
    }
    Ok(Problem {
        weights,
        lateral_bounds: lateral,
        tracking: None,
        ..template.clone()
    })
}
