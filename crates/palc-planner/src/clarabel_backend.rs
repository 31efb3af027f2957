//! The clarabel backend: keeps one solver per sparsity pattern and only overwrites
//! values between plans.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, SolverStatus, SupportedConeT};

use crate::backend::{RawSolution, RawStatus};
use crate::qp::{Pattern, StageQp};
use crate::sparse_qp::{CscPattern, SparseQp};
use crate::{NumericalCause, PlanError, SolverFailure, SolverSettings};

struct Cached {
    pattern: Pattern,
    p: CscPattern,
    a: CscPattern,
    solver: DefaultSolver<f64>,
}

/// A clarabel solver cached by sparsity pattern.
#[derive(Default)]
pub(crate) struct ClarabelBackend {
    cached: Option<Cached>,
    /// The QP's sparse form, derived from the stage form for each plan.
    data: SparseQp,
    p_nz: Vec<f64>,
    a_nz: Vec<f64>,
}

impl std::fmt::Debug for ClarabelBackend {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ClarabelBackend")
            .field("cached", &self.cached.is_some())
            .finish()
    }
}

fn settings(s: &SolverSettings) -> DefaultSettings<f64> {
    DefaultSettings {
        verbose: false,
        max_iter: s.max_iter,
        tol_gap_abs: s.tol_gap_abs,
        tol_gap_rel: s.tol_gap_rel,
        tol_feas: s.tol_feas,
        equilibrate_enable: s.equilibrate_enable,
        iterative_refinement_enable: s.iterative_refinement_enable,
        // No bound is ever infinite, so presolve would find nothing to remove; off, it
        // also guarantees that data updates are accepted.
        presolve_enable: false,
        input_sparse_dropzeros: false,
        max_threads: 1,
        direct_solve_method: "qdldl".to_string(),
        ..DefaultSettings::default()
    }
}

impl ClarabelBackend {
    pub fn solve(
        &mut self,
        qp: &StageQp,
        pattern: Pattern,
        solver_settings: &SolverSettings,
    ) -> Result<RawSolution, PlanError> {
        let start = std::time::Instant::now();
        self.data.fill(qp);
        let data = &self.data;
        let reusable = solver_settings.reuse_structure
            && self
                .cached
                .as_ref()
                .is_some_and(|c| c.pattern == pattern && c.solver.is_data_update_allowed());
        let mut reused = false;
        if reusable {
            #[allow(
                clippy::expect_used,
                reason = "`reusable` holds only with a cached solver"
            )]
            let cached = self.cached.as_mut().expect("checked above");
            cached.p.scatter(&data.p_vals, &mut self.p_nz);
            cached.a.scatter(&data.a_vals, &mut self.a_nz);
            let updated = cached
                .solver
                .update_data(&self.p_nz, &data.q, &self.a_nz, &data.b);
            reused = updated.is_ok();
        }
        if !reused {
            let p = CscPattern::new(data.n, data.n, &data.p_rows, &data.p_cols);
            let a = CscPattern::new(data.m_eq + data.m_in, data.n, &data.a_rows, &data.a_cols);
            p.scatter(&data.p_vals, &mut self.p_nz);
            a.scatter(&data.a_vals, &mut self.a_nz);
            let p_mat = CscMatrix::new(
                p.m,
                p.n,
                p.colptr.clone(),
                p.rowval.clone(),
                self.p_nz.clone(),
            );
            let a_mat = CscMatrix::new(
                a.m,
                a.n,
                a.colptr.clone(),
                a.rowval.clone(),
                self.a_nz.clone(),
            );
            let cones = [
                SupportedConeT::ZeroConeT(data.m_eq),
                SupportedConeT::NonnegativeConeT(data.m_in),
            ];
            let solver = DefaultSolver::new(
                &p_mat,
                &data.q,
                &a_mat,
                &data.b,
                &cones,
                settings(solver_settings),
            )
            .map_err(|_| PlanError::SolverFailed {
                status: NumericalCause::ClarabelRefused.into(),
                iterations: 0,
            })?;
            self.cached = Some(Cached {
                pattern,
                p,
                a,
                solver,
            });
        }
        let setup_seconds = start.elapsed().as_secs_f64();
        #[allow(clippy::expect_used, reason = "the cache is filled just above")]
        let cached = self.cached.as_mut().expect("set above");
        let start = std::time::Instant::now();
        cached.solver.solve();
        let solve_seconds = start.elapsed().as_secs_f64();
        let solution = &cached.solver.solution;
        let status = match solution.status {
            SolverStatus::Solved => RawStatus::Solved,
            SolverStatus::AlmostSolved => RawStatus::AlmostSolved,
            SolverStatus::PrimalInfeasible | SolverStatus::AlmostPrimalInfeasible => {
                RawStatus::PrimalInfeasible
            }
            SolverStatus::DualInfeasible | SolverStatus::AlmostDualInfeasible => {
                RawStatus::DualInfeasible
            }
            SolverStatus::MaxIterations => RawStatus::Failed(SolverFailure::MaxIterations),
            SolverStatus::MaxTime => RawStatus::Failed(SolverFailure::MaxTime),
            SolverStatus::InsufficientProgress => {
                RawStatus::Failed(SolverFailure::InsufficientProgress)
            }
            SolverStatus::NumericalError => RawStatus::Failed(NumericalCause::Factorization.into()),
            SolverStatus::Unsolved | SolverStatus::CallbackTerminated => {
                RawStatus::Failed(NumericalCause::ClarabelRefused.into())
            }
        };
        Ok(RawSolution {
            status,
            iterations: solution.iterations,
            primal: solution.x.clone(),
            multipliers: solution.z.clone(),
            reused,
            setup_seconds,
            solve_seconds,
        })
    }
}
