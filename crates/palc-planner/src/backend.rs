//! What every QP backend returns to the planner.

use crate::SolverFailure;

/// How a backend finished, in backend-neutral terms.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum RawStatus {
    /// Solved to the requested tolerances.
    Solved,
    /// Solved to reduced tolerances only.
    AlmostSolved,
    /// A certificate of primal infeasibility was found (in `RawSolution::multipliers`).
    PrimalInfeasible,
    /// A certificate of dual infeasibility (an unbounded direction) was found; only
    /// clarabel looks for one.
    #[cfg_attr(not(feature = "clarabel"), allow(dead_code))]
    DualInfeasible,
    /// Stopped without a solution.
    Failed(SolverFailure),
}

/// Raw result of one solve, in the flat variable and row order of
/// [`StageQp`](crate::qp::StageQp).
#[derive(Debug, Clone)]
pub(crate) struct RawSolution {
    pub status: RawStatus,
    pub iterations: u32,
    /// The primal variables `x` of the QP.
    pub primal: Vec<f64>,
    /// The multipliers `z` of all rows (clarabel's name), equality rows first (length
    /// `m_eq + m_in`); on primal infeasibility, the certificate. Read only then: the
    /// Riccati backend leaves it empty otherwise.
    pub multipliers: Vec<f64>,
    pub reused: bool,
    pub setup_seconds: f64,
    pub solve_seconds: f64,
}
