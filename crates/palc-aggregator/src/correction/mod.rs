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

/// What a correction rule returns.
#[derive(Debug, Clone, PartialEq)]
pub struct CorrectionOutcome {
    /// The corrected weights; in the convex set.
    pub weights: Weights,
    /// New apprenticeship state (projection point), when the rule keeps one.
    pub apprenticeship: Option<ApprenticeshipState>,
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

/// A reward correction rule: turns a lesson's features into one new weight matrix.
///
/// `plan` solves the next plan's problem with candidate weights (the same planner and
/// problem as the final plan), for rules that measure their effect.
pub trait RewardCorrection {
    /// A short name for reports (`apprenticeship`, `incremental`).
    fn name(&self) -> &'static str;

    /// Corrects the weights.
    fn correct(
        &self,
        input: &CorrectionInput<'_>,
        state: Option<&ApprenticeshipState>,
        plan: &mut dyn FnMut(&Weights) -> Result<Plan, PlanError>,
    ) -> Result<CorrectionOutcome, AggregatorError>;
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
    /// The rule behind the option.
    pub fn rule(&self) -> &dyn RewardCorrection {
        match self {
            CorrectionRule::Apprenticeship(r) => r,
            CorrectionRule::Incremental(r) => r,
            CorrectionRule::Target(r) => r,
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
