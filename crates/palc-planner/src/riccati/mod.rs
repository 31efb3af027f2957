//! The structure-exploiting backend: a Mehrotra predictor-corrector interior point
//! whose Newton systems are solved by a time-varying Riccati recursion over the
//! stages (4 x 4 state and 2 x 2 control blocks), instead of a general sparse LDLᵀ.
//!
//! - [`stage_qp`]: reads the assembled [`QpData`] back into stage form;
//! - [`recursion`]: the Riccati factorization and solve, terminal rows by a Schur
//!   complement on their multiplier;
//! - [`sparse`]: products with `A_i`, `B_i` in the kinematic bicycle's pattern;
//! - [`ipm`]: the interior point (start, predictor, corrector, refinement, stopping
//!   rule, infeasibility certificate).
//!
//! Every buffer is sized once per plan; nothing is allocated inside the iterations.

mod ipm;
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
    pub fn solve(
        &mut self,
        data: &QpData,
        pattern: Pattern,
        horizon: usize,
        settings: &SolverSettings,
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
            x: self.primal(data.n),
            z: self.multipliers(),
            reused,
            setup_seconds,
            solve_seconds,
        })
    }

    /// The primal iterate in the variable order of [`QpData`].
    fn primal(&self, n: usize) -> Vec<f64> {
        let k = self.qp.k;
        let mut x = Vec::with_capacity(n);
        for i in 0..k {
            x.extend(self.ipm.z[i].iter());
        }
        x.extend(self.ipm.z[k].iter().take(NX));
        x.extend(&self.ipm.sigma);
        debug_assert_eq!(x.len(), n);
        debug_assert_eq!(NZ * k + NX + self.ipm.sigma.len(), n);
        x
    }

    /// The multipliers in the row order of [`QpData`]: `X_0`, dynamics, terminal,
    /// inequalities.
    fn multipliers(&self) -> Vec<f64> {
        let mut z = Vec::with_capacity(self.qp.m_eq + self.ipm.lambda.len());
        z.extend(self.ipm.y_initial.iter());
        for y in &self.ipm.y_dynamics {
            z.extend(y.iter());
        }
        z.extend(self.ipm.y_terminal.iter().take(self.qp.terminal_rows));
        z.extend(&self.ipm.lambda);
        z
    }
}
