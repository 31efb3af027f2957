//! The structure-exploiting backend: a Mehrotra predictor-corrector interior point
//! whose Newton systems are solved by a time-varying Riccati recursion over the
//! stages (4 x 4 state and 2 x 2 control blocks), instead of a general sparse LDLᵀ.
//!
//! - the QP it solves is the stage form of [`StageQp`], read as it is assembled;
//! - [`params`]: the named constants of the recursion and the interior point;
//! - [`recursion`]: the Riccati factorization and solve, terminal rows by a Schur
//!   complement on their multiplier;
//! - the products with `A_i`, `B_i` in the kinematic bicycle's pattern are those of
//!   [`StepDynamics`](crate::dynamics::StepDynamics), shared with the assembly;
//! - [`ipm`]: the interior point (start, predictor, corrector, refinement, stopping
//!   rule, infeasibility certificate).
//!
//! Every buffer is sized once per plan; nothing is allocated inside the iterations.

mod ipm;
mod params;
mod recursion;

use crate::backend::{RawSolution, RawStatus};
use crate::qp::{NX, NZ, Pattern, StageQp};

use ipm::{Ipm, Outcome, Tolerances};

/// The Riccati interior-point backend with its buffers, kept between plans.
#[derive(Debug, Default)]
pub(crate) struct RiccatiBackend {
    ipm: Ipm,
    pattern: Option<Pattern>,
}

impl RiccatiBackend {
    /// Solves the assembled QP; with `warm`, from the last solution shifted by one step
    /// (see [`Planner::replan`](crate::Planner::replan)) when the last solve solved a
    /// problem of the same pattern, else from Mehrotra's start.
    pub fn solve(
        &mut self,
        qp: &StageQp,
        pattern: Pattern,
        settings: &crate::SolverSettings,
        warm: bool,
    ) -> RawSolution {
        let start = std::time::Instant::now();
        let reused = self.pattern.as_ref() == Some(&pattern);
        self.pattern = Some(pattern);
        let warm = warm && reused && self.ipm.prepare_warm_start(qp);
        self.ipm.resize(qp);
        let setup_seconds = start.elapsed().as_secs_f64();

        let start = std::time::Instant::now();
        let outcome = self.ipm.run(
            qp,
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
        // The multipliers are read only as an infeasibility certificate.
        let multipliers = if matches!(status, RawStatus::PrimalInfeasible) {
            self.multipliers(qp)
        } else {
            Vec::new()
        };
        RawSolution {
            status,
            iterations: self.ipm.iterations,
            primal: self.primal(qp),
            multipliers,
            reused,
            setup_seconds,
            solve_seconds,
        }
    }

    /// The primal iterate as the flat vector `[X_0, U_0, ..., X_K, σ]` of [`StageQp`].
    fn primal(&self, qp: &StageQp) -> Vec<f64> {
        let (k, v) = (qp.k, &self.ipm.v);
        let mut x = Vec::with_capacity(qp.n());
        for i in 0..k {
            x.extend(v.ux[i].iter());
        }
        x.extend(v.ux[k].iter().take(NX));
        x.extend(&v.sigma);
        debug_assert_eq!(x.len(), qp.n());
        debug_assert_eq!(NZ * k + NX + v.sigma.len(), qp.n());
        x
    }

    /// The multipliers in the row order of [`StageQp`]: `X_0`, dynamics, terminal,
    /// inequalities.
    fn multipliers(&self, qp: &StageQp) -> Vec<f64> {
        let v = &self.ipm.v;
        let mut z = Vec::with_capacity(qp.m_eq + v.lambda.len());
        z.extend(v.y_initial.iter());
        for y in &v.y_dynamics {
            z.extend(y.iter());
        }
        z.extend(v.y_terminal.iter().take(qp.terminal_rows));
        z.extend(&v.lambda);
        z
    }
}
