//! Checks of a [`Problem`] against a [`PlannerConfig`] before any QP is built.

use crate::{
    LateralBound, LateralBoundsMode, MAX_POSITION, PlanError, PlannerConfig, Position, Problem,
    State, StepRanges, Terminal, Tracking, Weights, check_convexity,
};

pub(crate) fn finite(field: impl FnOnce() -> String, value: f64) -> Result<(), PlanError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(PlanError::NonFinite {
            field: field(),
            value,
        })
    }
}

pub(crate) fn length(field: &'static str, expected: usize, found: usize) -> Result<(), PlanError> {
    if expected == found {
        Ok(())
    } else {
        Err(PlanError::DimensionMismatch {
            field,
            expected,
            found,
        })
    }
}

const STATE_NAMES: [&str; 4] = ["s", "v", "l", "phi"];

/// Every component of a state finite.
pub(crate) fn finite_state(name: &str, state: &State) -> Result<(), PlanError> {
    for (c, x) in state.to_array().into_iter().enumerate() {
        finite(|| format!("{name}.{}", STATE_NAMES[c]), x)?;
    }
    Ok(())
}

/// Every reference speed finite and `>= 0` (Eqs. 12-14).
pub(crate) fn check_reference_speed(speeds: &[f64]) -> Result<(), PlanError> {
    for (i, &v) in speeds.iter().enumerate() {
        finite(|| format!("reference_speed[{i}]"), v)?;
        if v < 0.0 {
            return Err(PlanError::OutOfRange {
                field: format!("reference_speed[{i}]"),
                value: v,
                bound: ">= 0",
            });
        }
    }
    Ok(())
}

/// Every weight finite.
pub(crate) fn finite_weights(weights: &Weights) -> Result<(), PlanError> {
    for (column, w) in weights.columns().iter().enumerate() {
        for (row, &x) in w.iter().enumerate() {
            finite(|| format!("weights[{column}][{row}]"), x)?;
        }
    }
    Ok(())
}

/// Every predicted position finite.
pub(crate) fn finite_positions(name: &str, positions: &[Position]) -> Result<(), PlanError> {
    for (i, p) in positions.iter().enumerate() {
        finite(|| format!("{name}[{i}].s"), p.s)?;
        finite(|| format!("{name}[{i}].l"), p.l)?;
    }
    Ok(())
}

/// A speed of the ego `>= 0`: the model drives forwards only.
pub(crate) fn forward_speed(field: &'static str, v: f64) -> Result<(), PlanError> {
    if v < 0.0 {
        return Err(PlanError::OutOfRange {
            field: field.into(),
            value: v,
            bound: ">= 0 (the model drives forwards only)",
        });
    }
    Ok(())
}

/// Every given terminal component finite.
pub(crate) fn finite_terminal(t: &Terminal) -> Result<(), PlanError> {
    if let Some(s) = t.s {
        finite(|| "terminal.s".into(), s)?;
    }
    finite(|| "terminal.v".into(), t.v)?;
    finite(|| "terminal.l".into(), t.l)
}

/// Every given lateral bound finite.
pub(crate) fn finite_lateral_bounds(bounds: &[Option<LateralBound>]) -> Result<(), PlanError> {
    for (i, b) in bounds.iter().enumerate() {
        let Some(b) = b else { continue };
        if let Some(min) = b.min {
            finite(|| format!("lateral_bounds[{i}].min"), min)?;
        }
        if let Some(max) = b.max {
            finite(|| format!("lateral_bounds[{i}].max"), max)?;
        }
    }
    Ok(())
}

/// Tracking weights finite and `>= 0`, reference states finite.
pub(crate) fn check_tracking(tracking: &Tracking) -> Result<(), PlanError> {
    for (c, &q) in tracking.weights.iter().enumerate() {
        finite(|| format!("tracking.weights[{c}]"), q)?;
        if q < 0.0 {
            return Err(PlanError::OutOfRange {
                field: format!("tracking.weights[{c}]"),
                value: q,
                bound: ">= 0",
            });
        }
    }
    for (i, r) in tracking.reference.iter().enumerate() {
        let Some(r) = r else { continue };
        finite_state(&format!("tracking.reference[{i}]"), r)?;
    }
    Ok(())
}

/// Dimensions, finiteness, ranges, convexity and, for hard bounds, the infeasibilities
/// visible without solving.
pub(crate) fn validate_problem(config: &PlannerConfig, problem: &Problem) -> Result<(), PlanError> {
    let k = config.horizon;
    length("reference_speed", k, problem.reference_speed.len())?;
    length("weights", k, problem.weights.horizon())?;
    length("preceding", k, problem.preceding.len())?;
    length("adjacent", k, problem.adjacent.len())?;
    length("lateral_bounds", k + 1, problem.lateral_bounds.len())?;
    if let Some(tracking) = &problem.tracking {
        length("tracking.reference", k + 1, tracking.reference.len())?;
    }

    finite_state("initial", &problem.initial)?;
    finite(|| "curvature".into(), problem.curvature)?;
    check_reference_speed(&problem.reference_speed)?;
    finite_weights(&problem.weights)?;
    finite_positions("preceding", &problem.preceding)?;
    finite_positions("adjacent", &problem.adjacent)?;
    finite_terminal(&problem.terminal)?;
    forward_speed("initial.v", problem.initial.v)?;
    forward_speed("terminal.v", problem.terminal.v)?;
    finite_lateral_bounds(&problem.lateral_bounds)?;
    if let Some(tracking) = &problem.tracking {
        check_tracking(tracking)?;
    }

    check_positions(problem)?;
    check_convexity(&problem.weights)?;

    if config.lateral_bounds_mode == LateralBoundsMode::Hard {
        check_hard_bounds(k, problem)?;
    }
    Ok(())
}

/// A longitudinal position within [`MAX_POSITION`] of the origin.
pub(crate) fn within_max_position(field: impl FnOnce() -> String, s: f64) -> Result<(), PlanError> {
    if s.abs() <= MAX_POSITION {
        Ok(())
    } else {
        Err(PlanError::OutOfRange {
            field: field(),
            value: s,
            bound: "within 1e9 m of the origin (pass s relative to the ego)",
        })
    }
}

/// Every longitudinal position within [`MAX_POSITION`] of the origin.
fn check_positions(problem: &Problem) -> Result<(), PlanError> {
    within_max_position(|| "initial.s".into(), problem.initial.s)?;
    for (name, positions) in [
        ("preceding", &problem.preceding),
        ("adjacent", &problem.adjacent),
    ] {
        for (i, p) in positions.iter().enumerate() {
            within_max_position(|| format!("{name}[{i}].s"), p.s)?;
        }
    }
    if let Some(s) = problem.terminal.s {
        within_max_position(|| "terminal.s".into(), s)?;
    }
    if let Some(tracking) = &problem.tracking {
        for (i, r) in tracking.reference.iter().enumerate() {
            if let Some(r) = r {
                within_max_position(|| format!("tracking.reference[{i}].s"), r.s)?;
            }
        }
    }
    Ok(())
}

fn check_hard_bounds(k: usize, problem: &Problem) -> Result<(), PlanError> {
    let narrow = StepRanges::from_steps(problem.lateral_bounds.iter().enumerate().filter_map(
        |(i, b)| match b {
            Some(b) => match (b.min, b.max) {
                (Some(min), Some(max)) if min > max => Some(i),
                _ => None,
            },
            None => None,
        },
    ));
    if !narrow.is_empty() {
        return Err(PlanError::ZoneTooNarrow { steps: narrow });
    }
    for (which, step, l) in [
        ("initial", 0, problem.initial.l),
        ("terminal", k, problem.terminal.l),
    ] {
        if let Some(b) = problem.lateral_bounds[step] {
            let min = b.min.unwrap_or(f64::NEG_INFINITY);
            let max = b.max.unwrap_or(f64::INFINITY);
            if l < min || l > max {
                return Err(PlanError::BoundaryOutsideZone {
                    which,
                    step,
                    l,
                    min,
                    max,
                });
            }
        }
    }
    Ok(())
}
