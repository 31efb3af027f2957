//! Reward correction rules (Eqs. 33-36 and an incremental rule).
//!
//! Sign convention, everywhere in palc: the planner *minimizes* the cost
//! `J = w · Φ(ψ)` (Eq. 15). The paper's Eq. (36) maximizes `w · Φ` (a reward); here a
//! reward weight `r` is the cost weight `w = -r`. A rule that wants the plan to show
//! *less* of feature `j` raises `w_j`.

mod apprenticeship;
mod incremental;
mod target;

pub use apprenticeship::{ApprenticeshipRule, ApprenticeshipState};
pub use incremental::IncrementalRule;
pub use target::TargetRule;

use palc_planner::{Features, Plan, PlanError, Weights};
use serde::{Deserialize, Serialize};

use crate::{AggregatorError, ConvexSet, FeatureScale, LearnableRows};

/// What a correction rule may read.
#[derive(Debug, Clone, Copy)]
pub struct CorrectionInput<'a> {
    /// The current weights (resampled to the horizon, convex).
    pub weights: &'a Weights,
    /// `Φ(ψ^(t-1))`: the features of the plan that was driven (Eq. 35).
    pub planned: &'a Features,
    /// `Φ(ψ^E)`: the expert's features.
    pub expert: &'a Features,
    /// The rows the rule may change.
    pub learnable: &'a LearnableRows,
    /// Per-row feature scale.
    pub scale: &'a FeatureScale,
    /// The convex set every returned matrix lies in.
    pub convex_set: &'a ConvexSet,
}

/// What a correction rule returns; `S` is the rule's own state
/// ([`RewardCorrection::State`]).
#[derive(Debug, Clone, PartialEq)]
pub struct CorrectionOutcome<S = ()> {
    /// The corrected weights; in the convex set.
    pub weights: Weights,
    /// The rule's state after this lesson, to give to its next lesson (the
    /// projection point of [`ApprenticeshipRule`]; `()` for a rule that keeps none).
    pub state: S,
    /// Scaled feature error of the plan with the *current* weights against the expert,
    /// when the rule measured it (incremental rule).
    pub error_before: Option<f64>,
    /// Scaled feature error of the plan with the returned weights against the expert,
    /// when the rule measured it (incremental rule).
    pub error_after: Option<f64>,
    /// Plans solved inside the rule.
    pub inner_solves: usize,
    /// The plan of the returned weights, when the rule solved it with the `plan`
    /// it was given (the next plan's problem): the step takes it as the next plan
    /// instead of solving the same problem again.
    pub plan: Option<Plan>,
}

impl<S> CorrectionOutcome<S> {
    /// The outcome without the rule's state, and the state.
    pub fn split_state(self) -> (CorrectionOutcome, S) {
        let CorrectionOutcome {
            weights,
            state,
            error_before,
            error_after,
            inner_solves,
            plan,
        } = self;
        let outcome = CorrectionOutcome {
            weights,
            state: (),
            error_before,
            error_after,
            inner_solves,
            plan,
        };
        (outcome, state)
    }
}

/// A reward correction rule: turns a lesson's features into one new weight matrix.
///
/// `plan` solves the next plan's problem with candidate weights (the same planner and
/// problem as the final plan), for rules that measure their effect. A rule that
/// carries something from one lesson to the next names its type as
/// [`RewardCorrection::State`]: it receives the state its last lesson returned
/// (`None` at the first lesson, or when the caller dropped it) and returns the next.
pub trait RewardCorrection {
    /// What the rule keeps between lessons; `()` when it keeps nothing.
    type State;

    /// A short name for reports (`apprenticeship`, `incremental`).
    fn name(&self) -> &'static str;

    /// Corrects the weights.
    fn correct(
        &self,
        input: &CorrectionInput<'_>,
        state: Option<&Self::State>,
        plan: &mut dyn FnMut(&Weights) -> Result<Plan, PlanError>,
    ) -> Result<CorrectionOutcome<Self::State>, AggregatorError>;
}

/// Which correction rule the step uses.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "rule", rename_all = "snake_case", deny_unknown_fields)]
pub enum CorrectionRule {
    /// [`ApprenticeshipRule`] (the paper, Eqs. 33-36).
    Apprenticeship(ApprenticeshipRule),
    /// [`IncrementalRule`]: projected feature-matching steps.
    Incremental(IncrementalRule),
    /// [`TargetRule`] (the default): iterative learning of the lateral targets.
    Target(TargetRule),
}

impl Default for CorrectionRule {
    fn default() -> Self {
        CorrectionRule::Target(TargetRule::default())
    }
}

impl CorrectionRule {
    /// The rule's short name ([`RewardCorrection::name`]).
    pub fn name(&self) -> &'static str {
        match self {
            CorrectionRule::Apprenticeship(r) => r.name(),
            CorrectionRule::Incremental(r) => r.name(),
            CorrectionRule::Target(r) => r.name(),
        }
    }

    /// Corrects the weights with the rule behind the option.
    ///
    /// `apprenticeship` is the projection point the experience keeps: the
    /// apprenticeship rule reads it and returns the next one; the other rules keep
    /// no state, and it is returned unchanged.
    pub fn correct(
        &self,
        input: &CorrectionInput<'_>,
        apprenticeship: Option<&ApprenticeshipState>,
        plan: &mut dyn FnMut(&Weights) -> Result<Plan, PlanError>,
    ) -> Result<(CorrectionOutcome, Option<ApprenticeshipState>), AggregatorError> {
        match self {
            CorrectionRule::Apprenticeship(r) => {
                let (outcome, state) = r.correct(input, apprenticeship, plan)?.split_state();
                Ok((outcome, Some(state)))
            }
            CorrectionRule::Incremental(r) => {
                Ok((r.correct(input, None, plan)?, apprenticeship.cloned()))
            }
            CorrectionRule::Target(r) => {
                Ok((r.correct(input, None, plan)?, apprenticeship.cloned()))
            }
        }
    }
}

/// Checks that two feature matrices have the weights' horizon.
fn check_horizons(input: &CorrectionInput<'_>) -> Result<(), AggregatorError> {
    let k = input.weights.horizon();
    for (field, found) in [
        ("planned.features", input.planned.horizon()),
        ("expert.features", input.expert.horizon()),
    ] {
        if found != k {
            return Err(AggregatorError::LessonMismatch {
                field,
                expected: k,
                found,
            });
        }
    }
    Ok(())
}
