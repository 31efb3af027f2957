//! The incremental correction: projected steps from the current weights with
//! backtracking.

use palc_planner::{FEATURE_COUNT, Features, Plan, PlanError, Weights};
use serde::{Deserialize, Serialize};

use super::{CorrectionInput, CorrectionOutcome, RewardCorrection, check_horizons};
use crate::{AggregatorError, feature_error, project_convex};

/// Projected feature-matching steps from the *current* weights:
/// `w ← Proj(w + α (Φ_plan - Φ_expert) / σ²)` on the learnable rows.
///
/// In scaled coordinates (`ω_j = w_j σ_j`, `Φ̃_j = Φ_j / σ_j`) this is the step
/// `ω ← ω + α (Φ̃_plan - Φ̃_E)`, the subgradient step of the apprenticeship objective
/// `w · Φ_E - min_ψ w · Φ(ψ)` in the cost convention: where the plan shows more of a
/// feature than the expert, that feature becomes more expensive.
///
/// Per lesson: plan with the current weights (the problem of the next plan), measure
/// the error `‖(Φ_plan - Φ_E) / σ‖` over the learnable rows, then up to
/// `max_inner_solves` candidate steps from the best iterate so far. A candidate whose
/// plan lowers the error is kept; otherwise (or if its plan fails) `α` is halved, and
/// the loop stops below `min_step_size`. So the returned weights never plan worse, by
/// this measure, than the current ones. `α` starts afresh at `step_size` every lesson,
/// so a run of rejected steps in one lesson cannot freeze the weights for good (the
/// prototype's failure mode, NOTES.md, "The same prototype on the paper's whole grid").
/// Without backtracking the prototype needed 8 / 17 / 5 takeovers instead of 2 / 5 / 5.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct IncrementalRule {
    /// Initial step `α` in scaled coordinates; finite and `> 0`. Default `1`: a unit
    /// scaled feature difference moves a weight by one unit of `1 / σ_j`.
    pub step_size: f64,
    /// Candidate plans per lesson (accepted or rejected), `>= 1`. Default `12`.
    pub max_inner_solves: usize,
    /// The loop stops when `α` falls below this; finite, `> 0` and `<= step_size`.
    /// Default `1e-3` (ten halvings).
    pub min_step_size: f64,
}

impl Default for IncrementalRule {
    fn default() -> Self {
        IncrementalRule {
            step_size: 1.0,
            max_inner_solves: 12,
            min_step_size: 1e-3,
        }
    }
}

impl IncrementalRule {
    /// Checks every field.
    pub fn validate(&self) -> Result<(), AggregatorError> {
        let invalid = |field, value, bound| {
            Err(AggregatorError::InvalidOption {
                field,
                value,
                bound,
            })
        };
        if !(self.step_size.is_finite() && self.step_size > 0.0) {
            return invalid("correction.step_size", self.step_size, "finite and > 0");
        }
        if self.max_inner_solves == 0 {
            return invalid("correction.max_inner_solves", 0.0, "at least 1");
        }
        if !(self.min_step_size.is_finite()
            && self.min_step_size > 0.0
            && self.min_step_size <= self.step_size)
        {
            return invalid(
                "correction.min_step_size",
                self.min_step_size,
                "finite, > 0 and <= step_size",
            );
        }
        Ok(())
    }
}

impl RewardCorrection for IncrementalRule {
    /// Nothing is kept between lessons: each starts from the current weights.
    type State = ();

    fn name(&self) -> &'static str {
        "incremental"
    }

    fn correct(
        &self,
        input: &CorrectionInput<'_>,
        _state: Option<&()>,
        plan: &mut dyn FnMut(&Weights) -> Result<Plan, PlanError>,
    ) -> Result<CorrectionOutcome, AggregatorError> {
        self.validate()?;
        check_horizons(input)?;
        #[allow(
            clippy::expect_used,
            reason = "`check_horizons` just checked the horizons"
        )]
        let error = |f: &Features| {
            feature_error(f, input.expert, input.scale, input.learnable)
                .expect("horizons were checked")
        };
        let first = plan(input.weights)?;
        let before = error(&first.features);
        let mut best_weights = input.weights.clone();
        let mut best_plan = first;
        let mut best_error = before;
        let mut alpha = self.step_size;
        let mut solves = 1;
        let sigma = &input.scale.0;
        for _ in 0..self.max_inner_solves {
            if best_error == 0.0 || input.learnable.is_empty() {
                break;
            }
            let columns: Vec<[f64; FEATURE_COUNT]> = best_weights
                .columns()
                .iter()
                .zip(best_plan.features.columns())
                .zip(input.expert.columns())
                .map(|((w, p), e)| {
                    let mut next = *w;
                    for j in input.learnable.indices() {
                        next[j] += alpha * (p[j] - e[j]) / (sigma[j] * sigma[j]);
                    }
                    next
                })
                .collect();
            let candidate = project_convex(
                &Weights::from_columns(columns),
                input.convex_set,
                input.learnable,
            )?;
            if candidate == best_weights {
                break;
            }
            solves += 1;
            match plan(&candidate) {
                Ok(p) if error(&p.features) < best_error => {
                    best_error = error(&p.features);
                    best_weights = candidate;
                    best_plan = p;
                }
                _ => {
                    alpha *= 0.5;
                    if alpha < self.min_step_size {
                        break;
                    }
                }
            }
        }
        Ok(CorrectionOutcome {
            weights: best_weights,
            state: (),
            error_before: Some(before),
            error_after: Some(best_error),
            inner_solves: solves,
            plan: Some(best_plan),
        })
    }
}
