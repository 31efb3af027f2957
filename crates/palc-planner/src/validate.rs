//! Checks of a [`Problem`] against a [`PlannerConfig`] before any QP is built.

use crate::{
    LateralBoundsMode, MAX_POSITION, PlanError, PlannerConfig, Problem, StepRanges, check_convexity,
};

fn finite(field: impl FnOnce() -> String, value: f64) -> Result<(), PlanError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(PlanError::NonFinite {
            field: field(),
            value,
        })
    }
}

fn length(field: &'static str, expected: usize, found: usize) -> Result<(), PlanError> {
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

    let names = ["s", "v", "l", "phi"];
    for (c, x) in problem.initial.to_array().into_iter().enumerate() {
        finite(|| format!("initial.{}", names[c]), x)?;
    }
    finite(|| "curvature".into(), problem.curvature)?;
    for (i, &v) in problem.reference_speed.iter().enumerate() {
        finite(|| format!("reference_speed[{i}]"), v)?;
        if v < 0.0 {
            return Err(PlanError::OutOfRange {
                field: format!("reference_speed[{i}]"),
                value: v,
                bound: ">= 0",
            });
        }
    }
    for (column, w) in problem.weights.columns().iter().enumerate() {
        for (row, &x) in w.iter().enumerate() {
            finite(|| format!("weights[{column}][{row}]"), x)?;
        }
    }
    for (name, positions) in [
        ("preceding", &problem.preceding),
        ("adjacent", &problem.adjacent),
    ] {
        for (i, p) in positions.iter().enumerate() {
            finite(|| format!("{name}[{i}].s"), p.s)?;
            finite(|| format!("{name}[{i}].l"), p.l)?;
        }
    }
    let t = &problem.terminal;
    if let Some(s) = t.s {
        finite(|| "terminal.s".into(), s)?;
    }
    finite(|| "terminal.v".into(), t.v)?;
    finite(|| "terminal.l".into(), t.l)?;
    for (field, v) in [("initial.v", problem.initial.v), ("terminal.v", t.v)] {
        if v < 0.0 {
            return Err(PlanError::OutOfRange {
                field: field.into(),
                value: v,
                bound: ">= 0 (the model drives forwards only)",
            });
        }
    }
    for (i, b) in problem.lateral_bounds.iter().enumerate() {
        let Some(b) = b else { continue };
        if let Some(min) = b.min {
            finite(|| format!("lateral_bounds[{i}].min"), min)?;
        }
        if let Some(max) = b.max {
            finite(|| format!("lateral_bounds[{i}].max"), max)?;
        }
    }
    if let Some(tracking) = &problem.tracking {
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
            for (c, x) in r.to_array().into_iter().enumerate() {
                finite(|| format!("tracking.reference[{i}].{}", names[c]), x)?;
            }
        }
    }

    check_positions(problem)?;
    check_convexity(&problem.weights)?;

    if config.lateral_bounds_mode == LateralBoundsMode::Hard {
        check_hard_bounds(k, problem)?;
    }
    Ok(())
}

/// Every longitudinal position within [`MAX_POSITION`] of the origin.
fn check_positions(problem: &Problem) -> Result<(), PlanError> {
    let check = |field: &dyn Fn() -> String, s: f64| {
        if s.abs() <= MAX_POSITION {
            Ok(())
        } else {
            Err(PlanError::OutOfRange {
                field: field(),
                value: s,
                bound: "within 1e9 m of the origin (pass s relative to the ego)",
            })
        }
    };
    check(&|| "initial.s".into(), problem.initial.s)?;
    for (name, positions) in [
        ("preceding", &problem.preceding),
        ("adjacent", &problem.adjacent),
    ] {
        for (i, p) in positions.iter().enumerate() {
            check(&|| format!("{name}[{i}].s"), p.s)?;
        }
    }
    if let Some(s) = problem.terminal.s {
        check(&|| "terminal.s".into(), s)?;
    }
    if let Some(tracking) = &problem.tracking {
        for (i, r) in tracking.reference.iter().enumerate() {
            if let Some(r) = r {
                check(&|| format!("tracking.reference[{i}].s"), r.s)?;
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
