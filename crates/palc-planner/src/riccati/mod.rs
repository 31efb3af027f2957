//! The structure-exploiting backend: a Mehrotra predictor-corrector interior point
//! whose Newton systems are solved by a time-varying Riccati recursion over the
//! stages (4 x 4 state and 2 x 2 control blocks), instead of a general sparse LDLᵀ.
//!
//! - [`stage_qp`]: reads the assembled [`QpData`] back into stage form;
//! - [`params`]: the named constants of the recursion and the interior point;
//! - [`recursion`]: the Riccati factorization and solve, terminal rows by a Schur
//!   complement on their multiplier;
//! - [`sparse`]: products with `A_i`, `B_i` in the kinematic bicycle's pattern;
//! - [`ipm`]: the interior point (start, predictor, corrector, refinement, stopping
//!   rule, infeasibility certificate).
//!
//! Every buffer is sized once per plan; nothing is allocated inside the iterations.

mod ipm;
mod params;
mod recursion;
mod sparse;
mod stage_qp;

use crate::backend::{RawSolution, RawStatus};
use crate::qp::{Pattern, QpData};
use crate::{NumericalCause, PlanError, SolverSettings};

use ipm::{Ipm, Outcome, Tolerances};
use stage_qp::{NX, NZ, StageQp};

/// The Riccati interior-point backend with its buffers, kept between plans.
#[derive(Debug, Default)]
pub(crate) struct RiccatiBackend {
    qp: StageQp,
    ipm: Ipm,
    pattern: Option<Pattern>,
}

impl RiccatiBackend {
    /// Solves the assembled QP; with `warm`, from the last solution shifted by one step
    /// (see [`Planner::replan`](crate::Planner::replan)) when the last solve solved a
    /// problem of the same pattern, else from Mehrotra's start.
    pub fn solve(
        &mut self,
        data: &QpData,
        pattern: Pattern,
        horizon: usize,
        settings: &SolverSettings,
        warm: bool,
    ) -> Result<RawSolution, PlanError> {
        let start = std::time::Instant::now();
        self.qp
            .load(data, horizon)
            .map_err(|layout| PlanError::SolverFailed {
                status: NumericalCause::StageLayout(layout).into(),
                iterations: 0,
            })?;
        let reused = self.pattern.as_ref() == Some(&pattern);
        self.pattern = Some(pattern);
        let warm = warm && reused && self.ipm.prepare_warm_start(&self.qp);
        self.ipm.resize(&self.qp);
        let setup_seconds = start.elapsed().as_secs_f64();

        let start = std::time::Instant::now();
        let outcome = self.ipm.run(
            &self.qp,
            &Tolerances {
                max_iter: settings.max_iter,
                gap_abs: settings.tol_gap_abs,
                gap_rel: settings.tol_gap_rel,
                feas: settings.tol_feas,
            },
            warm,
        );
        let solve_seconds = start.elapsed().as_secs_f64();
        let status = match outcome {
            Outcome::Solved => RawStatus::Solved,
            Outcome::AlmostSolved => RawStatus::AlmostSolved,
            Outcome::PrimalInfeasible => RawStatus::PrimalInfeasible,
            Outcome::Failed(reason) => RawStatus::Failed(reason),
        };
        Ok(RawSolution {
            status,
            iterations: self.ipm.iterations,
            primal: self.primal(data.n),
            multipliers: self.multipliers(),
            reused,
            setup_seconds,
            solve_seconds,
        })
    }

    /// The primal iterate in the variable order of [`QpData`].
    fn primal(&self, n: usize) -> Vec<f64> {
        let (k, v) = (self.qp.k, &self.ipm.v);
        let mut x = Vec::with_capacity(n);
        for i in 0..k {
            x.extend(v.ux[i].iter());
        }
        x.extend(v.ux[k].iter().take(NX));
        x.extend(&v.sigma);
        debug_assert_eq!(x.len(), n);
        debug_assert_eq!(NZ * k + NX + v.sigma.len(), n);
        x
    }

    /// The multipliers in the row order of [`QpData`]: `X_0`, dynamics, terminal,
    /// inequalities.
    fn multipliers(&self) -> Vec<f64> {
        let v = &self.ipm.v;
        let mut z = Vec::with_capacity(self.qp.m_eq + v.lambda.len());
        z.extend(v.y_initial.iter());
        for y in &v.y_dynamics {
            z.extend(y.iter());
        }
        z.extend(v.y_terminal.iter().take(self.qp.terminal_rows));
        z.extend(&v.lambda);
        z
    }
}
