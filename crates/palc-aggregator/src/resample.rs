//! Carrying a weight matrix from one horizon and step to another.

use palc_planner::{FEATURE_COUNT, Weights};

use crate::AggregatorError;

/// Resamples `weights`, learned with step `from_dt`, to `horizon` columns of step
/// `to_dt`.
///
/// Rule: column `c` weighs stage `c + 1`, which uses `X_c` and `U_c`, i.e. the time
/// `t = c · Δt` since the start of the plan. New column `c'` takes the value at
/// `t' = c' · to_dt`, linearly interpolated in time between the two old columns around
/// it; beyond the old horizon (`t' > (K_old - 1) · from_dt`) the last old column is
/// held. Weights are *not* rescaled by `to_dt / from_dt`: every term of the cost (the
/// learned ones, the acceleration penalty, the tracking and soft-bound terms) is a sum
/// over stages, so their ratios, and hence the optimum, do not depend on how many
/// stages there are. Time alignment is what carried experience between scenes in the
/// prototype (NOTES.md, "Experience transfer").
///
/// Every new column is a convex combination of old columns, so weights in the convex
/// set of [`crate::ConvexSet`] stay in it mathematically. A numerical check with a
/// tolerance relative to each block's largest entry (as `palc_planner::check_convexity`
/// has) may still refuse an interpolated column whose tiny diagonal (e.g. `w3 = ε`)
/// sits next to a coupling that was admissible in one of the two old columns; so
/// [`crate::learn_from_lesson`] and [`crate::plan_problem`] project resampled weights
/// with [`crate::project_convex`] before planning, and so should any other caller.
///
/// # Errors
/// [`AggregatorError::Resample`] for an empty matrix, `horizon == 0`, or a step that
/// is not finite and positive.
pub fn resample_weights(
    weights: &Weights,
    from_dt: f64,
    horizon: usize,
    to_dt: f64,
) -> Result<Weights, AggregatorError> {
    let columns = resample_columns(weights.columns(), from_dt, horizon, to_dt, 0.0)?;
    Ok(Weights::from_columns(columns))
}

/// [`resample_weights`] with the time base moved by `shift_s`: new column `c'`
/// takes the old value at `t' − shift_s`, so that what the old matrix did at time
/// `t` the new one does at `t + shift_s`. Before the old start
/// (`t' − shift_s < 0`) the first old column is held, beyond its end the last.
///
/// This is how an experience anchored at the user's start carries into a scene
/// where that start is predicted `shift_s` later (or earlier, for a negative
/// shift) after the start of the plan.
///
/// # Errors
/// As [`resample_weights`], and for a `shift_s` that is not finite.
pub fn resample_weights_shifted(
    weights: &Weights,
    from_dt: f64,
    horizon: usize,
    to_dt: f64,
    shift_s: f64,
) -> Result<Weights, AggregatorError> {
    if !shift_s.is_finite() {
        return Err(AggregatorError::Resample {
            reason: format!("shift_s = {shift_s} s must be finite"),
        });
    }
    let columns = resample_columns(weights.columns(), from_dt, horizon, to_dt, shift_s)?;
    Ok(Weights::from_columns(columns))
}

/// [`resample_weights`] on raw columns (also used for feature expectations).
pub(crate) fn resample_columns(
    columns: &[[f64; FEATURE_COUNT]],
    from_dt: f64,
    horizon: usize,
    to_dt: f64,
    shift_s: f64,
) -> Result<Vec<[f64; FEATURE_COUNT]>, AggregatorError> {
    let fail = |reason: String| Err(AggregatorError::Resample { reason });
    if columns.is_empty() {
        return fail("the weight matrix has no column".into());
    }
    if horizon == 0 {
        return fail("the new horizon is 0; it must be at least 1".into());
    }
    for (name, dt) in [("from_dt", from_dt), ("to_dt", to_dt)] {
        if !(dt.is_finite() && dt > 0.0) {
            return fail(format!("{name} = {dt} s must be finite and > 0"));
        }
    }
    if horizon == columns.len() && from_dt == to_dt && shift_s == 0.0 {
        return Ok(columns.to_vec());
    }
    let last = columns.len() - 1;
    Ok((0..horizon)
        .map(|c| {
            let position = ((c as f64 * to_dt - shift_s) / from_dt).max(0.0);
            let below = position.floor();
            if below >= last as f64 {
                return columns[last];
            }
            let i = below as usize;
            let fraction = position - below;
            if fraction == 0.0 {
                return columns[i];
            }
            let (a, b) = (&columns[i], &columns[i + 1]);
            std::array::from_fn(|j| a[j] + fraction * (b[j] - a[j]))
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp(k: usize) -> Weights {
        Weights::from_columns((0..k).map(|c| [c as f64; FEATURE_COUNT]).collect())
    }

    #[test]
    fn same_grid_is_identity() {
        let w = ramp(5);
        assert_eq!(resample_weights(&w, 0.1, 5, 0.1).unwrap(), w);
    }

    #[test]
    fn halving_dt_interpolates_and_holds_the_last_column() {
        let w = ramp(3); // columns at t = 0, 0.1, 0.2 with values 0, 1, 2
        let r = resample_weights(&w, 0.1, 7, 0.05).unwrap();
        let got: Vec<f64> = r.row(0).collect();
        let expected = [0.0, 0.5, 1.0, 1.5, 2.0, 2.0, 2.0];
        for (g, e) in got.iter().zip(expected) {
            assert!((g - e).abs() < 1e-12, "{got:?}");
        }
    }

    #[test]
    fn longer_horizon_holds_last_column() {
        let r = resample_weights(&ramp(2), 0.1, 4, 0.1).unwrap();
        assert_eq!(r.row(3).collect::<Vec<_>>(), vec![0.0, 1.0, 1.0, 1.0]);
    }

    #[test]
    fn a_shift_moves_the_time_base_and_holds_both_ends() {
        let w = ramp(4); // values 0, 1, 2, 3 at t = 0, 0.1, 0.2, 0.3
        let later = resample_weights_shifted(&w, 0.1, 6, 0.1, 0.15).unwrap();
        let got: Vec<f64> = later.row(0).collect();
        let expected = [0.0, 0.0, 0.5, 1.5, 2.5, 3.0];
        for (g, e) in got.iter().zip(expected) {
            assert!((g - e).abs() < 1e-12, "{got:?}");
        }
        let earlier = resample_weights_shifted(&w, 0.1, 3, 0.1, -0.1).unwrap();
        assert_eq!(earlier.row(0).collect::<Vec<_>>(), vec![1.0, 2.0, 3.0]);
        let none = resample_weights_shifted(&w, 0.1, 4, 0.1, 0.0).unwrap();
        assert_eq!(none, w);
        assert!(resample_weights_shifted(&w, 0.1, 4, 0.1, f64::NAN).is_err());
    }

    #[test]
    fn invalid_inputs_are_refused() {
        let w = ramp(3);
        assert!(resample_weights(&w, 0.0, 3, 0.1).is_err());
        assert!(resample_weights(&w, 0.1, 0, 0.1).is_err());
        assert!(resample_weights(&w, 0.1, 3, f64::NAN).is_err());
        assert!(resample_weights(&Weights::zeros(0), 0.1, 3, 0.1).is_err());
    }
}
