//! The feature map `Φ(ψ)` of Eq. (34), the only place where it is defined.

use crate::{Control, FEATURE_COUNT, Features, PlanError, Position, State};

/// The ten features of one stage from `X_{i-1}`, `U_{i-1}` and the predicted
/// preceding and adjacent positions at step `i - 1` (Eq. 34).
///
/// `dist^p` and `dist^a` are the full *squared* Euclidean distances
/// `(s - s^p)² + (l - l^p)²` (NOTES item 5), so that the planner's cost equals `w · Φ`.
pub fn stage_features(
    state: &State,
    control: &Control,
    preceding: &Position,
    adjacent: &Position,
) -> [f64; FEATURE_COUNT] {
    let State { s, l, phi, .. } = *state;
    let delta = control.delta;
    let squared = |p: &Position| (s - p.s).powi(2) + (l - p.l).powi(2);
    [
        l * l,
        l,
        phi * phi,
        phi,
        l * delta,
        phi * delta,
        s * delta,
        delta * delta,
        squared(preceding),
        squared(adjacent),
    ]
}

/// The feature matrix `Φ(ψ)` (10 x K) of a trajectory: column `i - 1` holds the
/// features of stage `i`, from `states[i-1]`, `controls[i-1]`, `preceding[i-1]` and
/// `adjacent[i-1]` (Eqs. 15 and 34).
///
/// `states` has `K + 1` entries (its last one has no feature) or `K`; the other
/// slices have `K`.
pub fn features(
    states: &[State],
    controls: &[Control],
    preceding: &[Position],
    adjacent: &[Position],
) -> Result<Features, PlanError> {
    let k = controls.len();
    if states.len() != k + 1 && states.len() != k {
        return Err(PlanError::DimensionMismatch {
            field: "states",
            expected: k + 1,
            found: states.len(),
        });
    }
    for (field, found) in [("preceding", preceding.len()), ("adjacent", adjacent.len())] {
        if found != k {
            return Err(PlanError::DimensionMismatch {
                field,
                expected: k,
                found,
            });
        }
    }
    Ok(Features::from_columns(
        (0..k)
            .map(|i| stage_features(&states[i], &controls[i], &preceding[i], &adjacent[i]))
            .collect(),
    ))
}
