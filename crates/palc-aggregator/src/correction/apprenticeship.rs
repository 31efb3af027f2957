//! Abbeel & Ng's projection method (the paper's Eqs. 33-36, bounded).

use palc_planner::{FEATURE_COUNT, Features, Plan, PlanError, Weights};
use serde::{Deserialize, Serialize};

use super::{CorrectionInput, CorrectionOutcome, RewardCorrection, check_horizons};
use crate::{AggregatorError, project_convex};

/// The projection point `μ̄` of Abbeel & Ng's projection method, kept between
/// lessons in the experience.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ApprenticeshipState {
    /// `μ̄`, in raw (unscaled) feature units, 10 x K.
    pub mu_bar: Features,
    /// Number of projection updates so far.
    pub updates: u64,
}

/// The paper's reward correction (Eqs. 33-36) as Abbeel & Ng's (2004) projection
/// method; the printed Eq. (35), a minimum over `w` of a linear function, is unbounded.
///
/// Per lesson, in scaled coordinates (`Φ̃_j = Φ_j / σ_j`) and on the learnable rows:
/// `μ = Φ̃(ψ^(t-1))`, `μ_E = Φ̃(ψ^E)`. The first lesson sets `μ̄ = μ`; later ones
/// project `μ_E` onto the line through `μ̄` and `μ`:
/// `μ̄ ← μ̄ + clamp(((μ - μ̄)·(μ_E - μ̄)) / ‖μ - μ̄‖², 0, 1) (μ - μ̄)`
/// (clamped so that `μ̄` stays in the convex hull of observed feature expectations).
/// The reward of A&N is `μ_E - μ̄`; in palc's cost convention the weights are
/// `ω = μ̄ - μ_E`, i.e. `w_j = (μ̄_j - μ_E,j) / σ_j` in raw units. A&N bound `‖ω‖ <= 1`;
/// since the other rows and the planner's extra terms are not scale-free, the bound
/// used here is the norm of the current learnable weights (`‖ω‖ = ‖ω_current‖`, or 1
/// when that is 0). The result is projected onto the convex set.
///
/// Differences from A&N: the expert changes from lesson to lesson (A&N's `μ_E` is
/// fixed); and one weight matrix is returned, the last one, not a mixture of
/// policies. An independent prototype found that replacing `w` by a feature-difference
/// direction discards the smoothing weights (NOTES.md, finding 3): restrict the
/// learnable rows to keep them.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ApprenticeshipRule {}

impl RewardCorrection for ApprenticeshipRule {
    /// The projection point `μ̄`, kept between lessons.
    type State = ApprenticeshipState;

    fn name(&self) -> &'static str {
        "apprenticeship"
    }

    fn correct(
        &self,
        input: &CorrectionInput<'_>,
        state: Option<&ApprenticeshipState>,
        _plan: &mut dyn FnMut(&Weights) -> Result<Plan, PlanError>,
    ) -> Result<CorrectionOutcome<ApprenticeshipState>, AggregatorError> {
        check_horizons(input)?;
        let k = input.weights.horizon();
        let sigma = &input.scale.0;
        let rows: Vec<usize> = input.learnable.indices().collect();
        let scaled = |f: &Features, c: usize, j: usize| f.columns()[c][j] / sigma[j];
        // The previous projection point, if it belongs to this horizon.
        let previous = state.filter(|s| s.mu_bar.horizon() == k);
        let mu_bar: Features = match previous {
            None => input.planned.clone(),
            Some(state) => {
                let (mut num, mut den) = (0.0, 0.0);
                for c in 0..k {
                    for &j in &rows {
                        let bar = scaled(&state.mu_bar, c, j);
                        let d = scaled(input.planned, c, j) - bar;
                        num += d * (scaled(input.expert, c, j) - bar);
                        den += d * d;
                    }
                }
                let t = if den > 0.0 {
                    (num / den).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let columns = (0..k)
                    .map(|c| {
                        let bar = &state.mu_bar.columns()[c];
                        let mu = &input.planned.columns()[c];
                        std::array::from_fn(|j| bar[j] + t * (mu[j] - bar[j]))
                    })
                    .collect();
                Features::from_columns(columns)
            }
        };
        // ω = μ̄ - μ_E on the learnable rows, scaled to the norm of the current ω.
        let mut omega = vec![[0.0; FEATURE_COUNT]; k];
        let (mut norm, mut current) = (0.0, 0.0);
        for c in 0..k {
            for &j in &rows {
                let o = scaled(&mu_bar, c, j) - scaled(input.expert, c, j);
                omega[c][j] = o;
                norm += o * o;
                let w = input.weights.columns()[c][j] * sigma[j];
                current += w * w;
            }
        }
        let (norm, current) = (norm.sqrt(), current.sqrt());
        let mut columns = input.weights.columns().to_vec();
        if norm > 0.0 {
            let factor = if current > 0.0 { current } else { 1.0 } / norm;
            for c in 0..k {
                for &j in &rows {
                    columns[c][j] = factor * omega[c][j] / sigma[j];
                }
            }
        }
        let weights = project_convex(
            &Weights::from_columns(columns),
            input.convex_set,
            input.learnable,
        )?;
        Ok(CorrectionOutcome {
            weights,
            state: ApprenticeshipState {
                mu_bar,
                updates: previous.map_or(0, |s| s.updates) + 1,
            },
            error_before: None,
            error_after: None,
            plan: None,
            inner_solves: 0,
        })
    }
}
