//! Mehrotra predictor-corrector primal-dual interior point on the stage QP
//!
//! ```text
//! min ½ xᵀPx + qᵀx   s.t.   A x = b (X_0, dynamics, terminal),   G x + s = h,  s >= 0,
//! ```
//!
//! with multipliers `y` (equalities) and `λ >= 0` (inequalities), organized like
//! Clarabel.rs and HPIPM:
//!
//! - [`variables`]: the iterate `(x, s, y, λ)` and the Newton direction;
//! - [`residuals`]: the KKT residuals of an iterate and its convergence measures;
//! - [`kkt`]: the Newton system, `s`, `λ` and the soft-bound slacks `σ` eliminated,
//!   factored and solved by the [`Riccati`](super::recursion::Riccati) recursion, and
//!   iterative refinement;
//! - [`step`]: one predictor-corrector iteration and its step length;
//! - [`info`]: the tolerances, the measures, the outcome and the bookkeeping of the
//!   stopping rule;
//! - the constants of all of them are in [`params`](super::params).
//!
//! The cold start is Mehrotra's: the Newton system with `W = I` at `x = 0`, then `s`
//! and `λ` shifted into the positive orthant. The warm start of a re-plan
//! ([`Ipm::prepare_warm_start`]) shifts the previous solution by one step and moves it off the
//! boundary. The stopping rule uses clarabel's measures on the unscaled data (relative
//! primal and dual residuals, absolute or relative gap), with the gap taken relative to
//! the objective *with* its constant: the tracking term expands into `xᵀPx + qᵀx` parts
//! of order 1e5 that cancel against the constant, and a gap relative to them stopped
//! measurably short of the optimum.
//! A primal infeasibility certificate `(y, λ)` with `Aᵀy + Gᵀλ = 0`, `bᵀy + hᵀλ < 0`
//! is checked at every iterate; when the constraints are inconsistent the multipliers
//! of an infeasible-start method grow along such a ray.

use nalgebra::{Vector4, Vector6};

mod info;
mod kkt;
mod residuals;
mod step;
mod variables;
mod warm;

use super::params::{
    INFEASIBILITY_TOLERANCE, REDUCED_INFEASIBILITY, REFINE_MIN_REDUCTION, REFINE_RESIDUAL_FLOOR,
    REFINE_SHORTFALL, START_BALANCE, START_COMPLEMENTARITY, START_SHIFT, START_UNIT_SHIFT,
};
use super::recursion::FactorError;
use crate::qp::StageQp;
use crate::{NumericalCause, SolverFailure};
use info::{Measures, Progress};
pub(crate) use info::{Outcome, Tolerances};
use kkt::Kkt;
use residuals::Residuals;
use variables::Direction;
pub(crate) use variables::Variables;

/// The interior point: the iterate, its residuals, the Newton system and the copies
/// kept for the fallbacks of the stopping rule.
#[derive(Debug, Default)]
pub(crate) struct Ipm {
    /// The current iterate; after [`run`](Self::run), the result.
    pub v: Variables,
    /// The Newton direction.
    d: Direction,
    /// The residuals of `v`.
    residuals: Residuals,
    /// The Newton system.
    kkt: Kkt,
    /// The best iterate that meets the reduced tolerances, returned when the
    /// iterations stagnate near the optimum.
    best: Variables,
    /// The iterate with the best infeasibility certificate at the reduced tolerance
    /// (ratio `‖Aᵀy + Gᵀλ‖∞ / -(bᵀy + hᵀλ)`), returned when the iterations stop.
    certificate: Variables,
    /// The warm start of a re-plan, built by [`prepare_warm_start`](Self::prepare_warm_start).
    shifted: Variables,
    /// The objective of the last run's result, if it solved (`Solved` or
    /// `AlmostSolved`): `v` then holds a solution a re-plan can start from.
    solved_objective: Option<f64>,
    /// The objective of the iterate the current run returns, if it solved.
    returned_objective: Option<f64>,
    /// Iterations of the last run.
    pub iterations: u32,
}

impl Ipm {
    /// Sizes every buffer for `qp` (the only allocation of a solve).
    pub fn resize(&mut self, qp: &StageQp) {
        let (k, n_slack, m_in) = (qp.k, qp.slack_cost.len(), qp.inequalities.len());
        self.v.resize(k, n_slack, m_in);
        self.d.resize(k, n_slack, m_in);
        self.best.resize(k, n_slack, m_in);
        self.certificate.resize(k, n_slack, m_in);
        self.residuals.reset(qp);
        self.kkt.reset(qp);
        self.iterations = 0;
    }

    /// Runs the interior point from Mehrotra's start, or with `warm` from the iterate
    /// of [`prepare_warm_start`](Self::prepare_warm_start); `v` holds the result.
    pub fn run(&mut self, qp: &StageQp, tol: &Tolerances, warm: bool) -> Outcome {
        let outcome = self.iterations(qp, tol, warm);
        self.solved_objective = match (&outcome, self.returned_objective) {
            (Outcome::Solved | Outcome::AlmostSolved, Some(objective)) => Some(objective),
            _ => None,
        };
        outcome
    }

    /// The iterations of [`run`](Self::run).
    fn iterations(&mut self, qp: &StageQp, tol: &Tolerances, warm: bool) -> Outcome {
        self.returned_objective = None;
        if warm {
            self.v.copy_from(&self.shifted);
        } else if let Err(e) = self.start(qp) {
            return Outcome::Failed(describe(e).into());
        }
        let mut progress = Progress::default();
        loop {
            let measures = self.residuals.compute(qp, &self.v);
            if measures.meets(tol.gap_abs, tol.gap_rel, tol.feas) {
                self.returned_objective = Some(measures.objective);
                return Outcome::Solved;
            }
            if measures.infeasible(INFEASIBILITY_TOLERANCE) {
                return Outcome::PrimalInfeasible;
            }
            if measures.infeasible(REDUCED_INFEASIBILITY) && progress.offer_certificate(&measures) {
                self.certificate.copy_from(&self.v);
            }
            if progress.offer_best(measures, tol) {
                self.best.copy_from(&self.v);
            }
            if let Some(reason) = progress.stop_reason(self.iterations, tol) {
                return self.stop(&progress, &measures, reason);
            }
            self.iterations += 1;
            // An exact Newton step scales the dual residual by (1 - α). Near the
            // optimum, `W = λ / s` spans many orders of magnitude and the step loses
            // accuracy in the stationarity rows; once a step falls short of that
            // reduction, every later corrector step gets one refinement step.
            progress.refining |= progress.previous.is_some_and(|(res_dual, alpha)| {
                measures.res_dual > REFINE_RESIDUAL_FLOOR * tol.feas
                    && measures.res_dual
                        > REFINE_SHORTFALL * (1.0 - alpha).max(REFINE_MIN_REDUCTION) * res_dual
            });
            let feasible = measures.res_primal < tol.feas && measures.res_dual < tol.feas;
            match self.iterate(qp, progress.refining, feasible) {
                Ok(alpha) => progress.record_step(measures.res_dual, alpha),
                Err(e) => return self.stop(&progress, &measures, describe(e).into()),
            }
        }
    }

    /// The end without convergence: the best iterate if it meets clarabel's reduced
    /// tolerances (`AlmostSolved`), an infeasibility certificate at the reduced
    /// tolerance, or the failure `reason`.
    fn stop(&mut self, progress: &Progress, current: &Measures, reason: SolverFailure) -> Outcome {
        if let Some((best, _)) = progress.best {
            self.returned_objective = Some(best.objective);
            self.v.copy_from(&self.best);
            return Outcome::AlmostSolved;
        }
        if current.infeasible(REDUCED_INFEASIBILITY) {
            return Outcome::PrimalInfeasible;
        }
        // An earlier iterate's certificate: after a breakdown of the usual Riccati
        // pass, the steps of the projected one can leave the certificate worse than it
        // was (issue 12, a hard-zone case at `PROPTEST_CASES=20000`).
        if progress.has_certificate() {
            self.v.copy_from(&self.certificate);
            return Outcome::PrimalInfeasible;
        }
        Outcome::Failed(reason)
    }

    /// Mehrotra's starting point.
    fn start(&mut self, qp: &StageQp) -> Result<(), FactorError> {
        let Self {
            v,
            d,
            residuals,
            kkt,
            ..
        } = self;
        // The Newton system at x = 0.
        v.zero();
        residuals.compute_at_origin(qp);
        kkt.w.fill(1.0);
        kkt.factor(qp)?;
        for (xi, row) in kkt.xi.iter_mut().zip(&qp.inequalities) {
            *xi = -row.h;
        }
        // rc, λ and 1/s are zero here, so the Δλ the step computes is unused noise-free 0.
        kkt.rc.fill(0.0);
        kkt.inv_s.fill(0.0);
        kkt.solve(qp, v, residuals, d, true);
        v.ux.copy_from_slice(&d.ux);
        v.sigma.copy_from_slice(&d.sigma);
        v.y_initial = d.y_initial;
        v.y_dynamics.copy_from_slice(&d.y_dynamics);
        v.y_terminal = d.y_terminal;
        // Δs = h - G x; s = h - G x and λ = G x - h, shifted into the orthant.
        for j in 0..v.s.len() {
            v.s[j] = d.s[j];
            v.lambda[j] = -d.s[j];
        }
        let shift = |v: &mut [f64]| {
            let min = v.iter().copied().fold(f64::INFINITY, f64::min);
            let delta = (-START_SHIFT * min).max(0.0);
            v.iter_mut().for_each(|x| *x += delta);
        };
        shift(&mut v.s);
        shift(&mut v.lambda);
        let sl: f64 = v.s.iter().zip(&v.lambda).map(|(s, l)| s * l).sum();
        let (sum_s, sum_l) = (v.s.iter().sum::<f64>(), v.lambda.iter().sum::<f64>());
        if sl > START_COMPLEMENTARITY * v.s.len() as f64 && sum_s > 0.0 && sum_l > 0.0 {
            let (ds, dl) = (START_BALANCE * sl / sum_l, START_BALANCE * sl / sum_s);
            v.s.iter_mut().for_each(|x| *x += ds);
            v.lambda.iter_mut().for_each(|x| *x += dl);
        } else {
            v.s.iter_mut().for_each(|x| *x += START_UNIT_SHIFT);
            v.lambda.iter_mut().for_each(|x| *x += START_UNIT_SHIFT);
        }
        Ok(())
    }
}

/// Adds `add` to the state part of `v`.
fn head(v: &mut Vector6<f64>, add: &Vector4<f64>) {
    let mut h = v.fixed_rows_mut::<4>(0);
    h += add;
}

fn describe(e: FactorError) -> NumericalCause {
    match e {
        FactorError::ControlBlock(step) => NumericalCause::ControlBlock { step },
        FactorError::Terminal => NumericalCause::TerminalSchur,
    }
}
