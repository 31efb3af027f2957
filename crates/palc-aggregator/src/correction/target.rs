//! The target correction: iterative learning of the per-step lateral targets.

use palc_planner::{Features, Plan, PlanError, Weights, feature};
use serde::{Deserialize, Serialize};

use super::{CorrectionInput, CorrectionOutcome, RewardCorrection, check_horizons};
use crate::{AggregatorError, feature_error, project_convex};

/// Iterative learning control on the lateral target of every stage.
///
/// Per stage, `w1 l² + w2 l = w1 (l − l*)² + const` with the target
/// `l* = −w2 / (2 w1)`: the planner pulls the lane change towards `l*` with
/// stiffness `w1`, smoothed by the heading and steering terms. Where the plan
/// falls short of the expert by `e_c = l^E_c − l_c`, the target moves by `g · e_c`:
///
/// `l*_c ← l*_c + g (l^E_c − l_c)`, i.e. `w2_c ← −2 w1_c l*_c`, `w1` unchanged.
///
/// The plan is a smoothing of the targets (a convex quadratic program whose lateral
/// response to its targets has gain at most one), so with `g ≤ 1` each iteration
/// shrinks the error; the loop keeps the best iterate by the root-mean-square
/// lateral error, halves `g` after an iterate that is not better, and stops below
/// `tolerance_m` or after `max_inner_solves` plans. Only row `w2` changes (it must
/// be learnable, and stages with `w1 ≤ 0` have no target and are left alone), so the
/// convex set is never left: `w2` has no convexity constraint.
///
/// Unlike the feature-matching steps of [`crate::IncrementalRule`], whose plans
/// stay 0.25–0.30 m from the user after personalization on the paper's grid, the
/// plan converges to the expert's lateral path; it ends 0.08–0.12 m from the user
/// in the default scenario (docs/experiments/0009-reward-correction.md).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TargetRule {
    /// Learning gain `g`; finite, in `(0, 1]`. Default `1`: the full error.
    pub gain: f64,
    /// Candidate plans per lesson, `>= 1`. Default `8`.
    pub max_inner_solves: usize,
    /// Root-mean-square lateral error (m) below which the loop stops; finite and
    /// `>= 0`. Default `0.005`: a tenth of the takeover threshold's smallest margin.
    pub tolerance_m: f64,
}

impl Default for TargetRule {
    fn default() -> Self {
        TargetRule {
            gain: 1.0,
            max_inner_solves: 8,
            tolerance_m: 0.005,
        }
    }
}

impl TargetRule {
    /// Checks every field.
    pub fn validate(&self) -> Result<(), AggregatorError> {
        let invalid = |field, value, bound| {
            Err(AggregatorError::InvalidOption {
                field,
                value,
                bound,
            })
        };
        if !(self.gain.is_finite() && self.gain > 0.0 && self.gain <= 1.0) {
            return invalid("correction.gain", self.gain, "finite, in (0, 1]");
        }
        if self.max_inner_solves == 0 {
            return invalid("correction.max_inner_solves", 0.0, "at least 1");
        }
        if !(self.tolerance_m.is_finite() && self.tolerance_m >= 0.0) {
            return invalid(
                "correction.tolerance_m",
                self.tolerance_m,
                "finite and >= 0",
            );
        }
        Ok(())
    }
}

/// Root-mean-square difference of the lateral rows of two feature matrices (m).
fn lateral_error(plan: &Features, expert: &Features) -> f64 {
    let (a, b) = (plan.row(feature::L), expert.row(feature::L));
    let (sum, n) = a.zip(b).fold((0.0, 0usize), |(sum, n), (x, y)| {
        (sum + (x - y).powi(2), n + 1)
    });
    (sum / n.max(1) as f64).sqrt()
}

impl RewardCorrection for TargetRule {
    /// Nothing is kept between lessons: each starts from the current weights.
    type State = ();

    fn name(&self) -> &'static str {
        "target"
    }

    fn correct(
        &self,
        input: &CorrectionInput<'_>,
        _state: Option<&()>,
        plan: &mut dyn FnMut(&Weights) -> Result<Plan, PlanError>,
    ) -> Result<CorrectionOutcome, AggregatorError> {
        self.validate()?;
        check_horizons(input)?;
        if !input.learnable.contains(feature::L) {
            return Err(AggregatorError::ConflictingOptions {
                reason: "the target rule changes w2: learnable_rows must include row 1 (l)",
            });
        }
        let scaled = |f: &Features| feature_error(f, input.expert, input.scale, input.learnable);
        let first = plan(input.weights)?;
        let before = scaled(&first.features);
        let mut best_weights = input.weights.clone();
        let mut best_plan = first;
        let mut best_error = lateral_error(&best_plan.features, input.expert);
        let mut gain = self.gain;
        let mut solves = 1;
        while solves <= self.max_inner_solves && best_error > self.tolerance_m {
            let planned: Vec<f64> = best_plan.features.row(feature::L).collect();
            let expert: Vec<f64> = input.expert.row(feature::L).collect();
            let columns = (best_weights.columns().iter().enumerate())
                .map(|(c, w)| {
                    let mut next = *w;
                    let stiffness = w[feature::L_SQUARED];
                    if stiffness > 0.0 {
                        let target = -w[feature::L] / (2.0 * stiffness);
                        let moved = target + gain * (expert[c] - planned[c]);
                        next[feature::L] = -2.0 * stiffness * moved;
                    }
                    next
                })
                .collect();
            let candidate = project_convex(
                &Weights::from_columns(columns),
                input.convex_set,
                input.learnable,
            )?;
            solves += 1;
            match plan(&candidate) {
                Ok(p) if lateral_error(&p.features, input.expert) < best_error => {
                    best_error = lateral_error(&p.features, input.expert);
                    best_weights = candidate;
                    best_plan = p;
                }
                _ => gain *= 0.5,
            }
        }
        Ok(CorrectionOutcome {
            error_after: scaled(&best_plan.features),
            weights: best_weights,
            state: (),
            error_before: before,
            inner_solves: solves,
            plan: Some(best_plan),
        })
    }
}
