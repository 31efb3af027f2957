//! Typed refusals of the planner.

use std::fmt;
use std::ops::RangeInclusive;

use thiserror::Error;

/// An invalid [`PlannerConfig`](crate::PlannerConfig).
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum ConfigError {
    /// A field lies outside its allowed range.
    #[error("config field `{field}` = {value:e} is out of range: must be {bound}")]
    OutOfRange {
        /// The field, e.g. `dt`.
        field: &'static str,
        /// Its value.
        value: f64,
        /// The allowed range, in words.
        bound: &'static str,
    },
    /// The chosen backend was not compiled in: its cargo feature is off.
    #[error(
        "config field `backend` = {backend} needs the `{feature}` feature of palc-planner, which is off; enable it or use `riccati`"
    )]
    BackendUnavailable {
        /// The backend, as spelled in a configuration file, e.g. `clarabel`.
        backend: &'static str,
        /// The cargo feature that provides it.
        feature: &'static str,
    },
}

/// Sets of steps, printed as `3..=7, 10`.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct StepRanges(pub Vec<RangeInclusive<usize>>);

impl StepRanges {
    /// Groups sorted step indices into maximal runs of consecutive steps.
    pub fn from_steps(steps: impl IntoIterator<Item = usize>) -> Self {
        let mut ranges: Vec<RangeInclusive<usize>> = Vec::new();
        for step in steps {
            match ranges.last_mut() {
                Some(last) if *last.end() + 1 == step => *last = *last.start()..=step,
                _ => ranges.push(step..=step),
            }
        }
        Self(ranges)
    }

    /// `true` when no step is listed.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// `true` when `step` is listed.
    pub fn contains(&self, step: usize) -> bool {
        self.0.iter().any(|r| r.contains(&step))
    }
}

impl fmt::Display for StepRanges {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.0.is_empty() {
            return f.write_str("none");
        }
        for (k, r) in self.0.iter().enumerate() {
            if k > 0 {
                f.write_str(", ")?;
            }
            if r.start() == r.end() {
                write!(f, "{}", r.start())?;
            } else {
                write!(f, "{}..={}", r.start(), r.end())?;
            }
        }
        Ok(())
    }
}

/// Why a plan was refused.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum PlanError {
    /// The planner configuration is invalid.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// An input has the wrong length.
    #[error("`{field}` has length {found}, expected {expected}")]
    DimensionMismatch {
        /// The input, e.g. `reference_speed`.
        field: &'static str,
        /// Required length.
        expected: usize,
        /// Given length.
        found: usize,
    },
    /// A [`ProblemBuilder`](crate::ProblemBuilder) was built without a required input.
    #[error("`{field}` was not given; set it on the problem builder")]
    MissingField {
        /// The input, e.g. `initial`.
        field: &'static str,
    },
    /// An input number is NaN or infinite.
    #[error("`{field}` is {value}, expected a finite number")]
    NonFinite {
        /// The input with its index, e.g. `weights[3][8]`.
        field: String,
        /// The value.
        value: f64,
    },
    /// An input number is finite but outside its allowed range.
    #[error("`{field}` = {value:?} is out of range: must be {bound}")]
    OutOfRange {
        /// The input with its index.
        field: String,
        /// The value.
        value: f64,
        /// The allowed range, in words.
        bound: &'static str,
    },
    /// A stage's Hessian block `[[Q_i, F_i/2], [F_iᵀ/2, R_i]]` (Eqs. 16-19) is not
    /// positive semidefinite, so the QP is not convex.
    #[error(
        "weights make the cost non-convex at stage {stage} (weight column {column}): {block} = {value:e}"
    )]
    NonConvex {
        /// Stage `i` of Eq. (15), `1..=K`.
        stage: usize,
        /// Weight column `i - 1`.
        column: usize,
        /// The offending block, in words.
        block: &'static str,
        /// The offending quantity (a negative curvature or an uncompensated coupling).
        value: f64,
    },
    /// Hard lateral bounds with `l_min > l_max`.
    #[error(
        "lateral zone too narrow (l_min > l_max) at steps {steps}; widen the zone or use soft lateral bounds"
    )]
    ZoneTooNarrow {
        /// The steps with an empty zone.
        steps: StepRanges,
    },
    /// A hard lateral bound excludes the fixed initial or terminal lateral position.
    #[error(
        "{which} lateral position l = {l} lies outside the hard bound [{min}, {max}] at step {step}"
    )]
    BoundaryOutsideZone {
        /// `initial` or `terminal`.
        which: &'static str,
        /// The step (0 or K).
        step: usize,
        /// The fixed lateral position.
        l: f64,
        /// Lower bound (`-inf` when absent).
        min: f64,
        /// Upper bound (`inf` when absent).
        max: f64,
    },
    /// The solver proved the constraints inconsistent; the steps are those whose
    /// constraints carry the infeasibility certificate.
    #[error(
        "problem is infeasible: lateral bounds at steps {lateral_steps} and steering bounds at steps {steering_steps} cannot hold together with the initial and terminal states"
    )]
    Infeasible {
        /// Steps whose lateral bounds take part in the certificate.
        lateral_steps: StepRanges,
        /// Steps whose steering bounds take part in the certificate.
        steering_steps: StepRanges,
    },
    /// The cost is unbounded below on the feasible set (e.g. a linear term with no
    /// curvature and no bound); add curvature or an acceleration penalty.
    #[error("problem is unbounded below; add curvature to the cost or an acceleration penalty")]
    Unbounded,
    /// The solver stopped without a solution.
    #[error("qp solver failed with status {status} after {iterations} iterations")]
    SolverFailed {
        /// Why it stopped, in the same terms for both backends.
        status: SolverFailure,
        /// Iterations done.
        iterations: u32,
    },
}

/// Why a QP backend stopped without a solution; both backends report the same reasons.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
#[non_exhaustive]
pub enum SolverFailure {
    /// `solver.max_iter` iterations were done without meeting the tolerances.
    #[error("max iterations")]
    MaxIterations,
    /// The iterates stopped improving before meeting even the reduced tolerances of
    /// `AlmostSolved` (the Riccati backend: three steps in a row shorter than 1e-8, or
    /// no better iterate for a while; clarabel: its own rule).
    #[error("insufficient progress")]
    InsufficientProgress,
    /// clarabel's time limit was reached (the planner sets none; kept for completeness).
    #[error("time limit")]
    MaxTime,
    /// A numerical failure, with its cause.
    #[error("numerical failure: {0}")]
    Numerical(#[from] NumericalCause),
}

/// The cause of a [`SolverFailure::Numerical`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
#[non_exhaustive]
pub enum NumericalCause {
    /// The Riccati recursion met a reduced control block `R̄_i` that is not positive
    /// definite (non-convex or non-finite data).
    #[error("control block of step {step} not positive definite")]
    ControlBlock {
        /// The step `i`.
        step: usize,
    },
    /// The Riccati recursion's terminal Schur complement is not positive definite even
    /// after regularization.
    #[error("terminal schur complement not positive definite")]
    TerminalSchur,
    /// clarabel's KKT factorization failed (its `NumericalError`).
    #[error("kkt factorization failed")]
    Factorization,
    /// clarabel refused the QP or the settings when the solver was built, or stopped
    /// without a status (`Unsolved`, `CallbackTerminated`).
    #[error("clarabel refused the problem")]
    ClarabelRefused,
}
