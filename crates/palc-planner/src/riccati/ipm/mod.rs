//! Mehrotra predictor-corrector primal-dual interior point on the stage QP
//!
//! ```text
//! min ½ zᵀPz + qᵀz   s.t.   A z = b (X_0, dynamics, terminal),   G z + s = h,  s >= 0,
//! ```
//!
//! with multipliers `y` (equalities) and `λ >= 0` (inequalities). Each Newton system
//! eliminates `s` and `λ` (`W = λ / s`), then each soft-bound slack `σ` (a scalar tied to
//! one lateral position), and hands the remaining stage QP to the [`Riccati`]
//! recursion: one factorization and two solves (predictor, corrector) per iteration.
//!
//! The start is Mehrotra's: the Newton system with `W = I` at `z = 0`, then `s` and `λ`
//! shifted into the positive orthant. The stopping rule uses clarabel's measures on
//! the unscaled data (relative primal and dual residuals, absolute or relative gap),
//! with the gap taken relative to the objective *with* its constant: the tracking term
//! expands into `zᵀPz + qᵀz` parts of order 1e5 that cancel against the constant, and
//! a gap relative to them stopped measurably short of the optimum.
//! A primal infeasibility certificate `(y, λ)` with `Aᵀy + Gᵀλ = 0`, `bᵀy + hᵀλ < 0`
//! is checked at every iterate; when the constraints are inconsistent the multipliers
//! of an infeasible-start method grow along such a ray.

use nalgebra::{Vector4, Vector6};

mod measures;
mod newton;

use super::recursion::{FactorError, Riccati};
use super::stage_qp::StageQp;
use crate::{NumericalCause, SolverFailure};
use measures::{Measures, norm_inf};

/// Relative tolerance of the infeasibility certificate: `‖Aᵀy + Gᵀλ‖∞ <= TOL · -(bᵀy + hᵀλ)`
/// (clarabel's `tol_infeas_rel`). A feasible problem can pass it only if its solutions
/// have `‖z‖₁ >= 1 / TOL`. The multipliers grow to 1e13 before rounding in `Aᵀy + Gᵀλ`
/// stops the ratio near 1e-9, so a tighter tolerance is not reachable.
const INFEASIBILITY_TOLERANCE: f64 = 1e-8;
/// clarabel's reduced tolerances, used when the iterations stop (`AlmostSolved`, or an
/// infeasibility certificate at the reduced tolerance).
const REDUCED_GAP: f64 = 5e-5;
const REDUCED_FEAS: f64 = 1e-4;
const REDUCED_INFEASIBILITY: f64 = 5e-5;
/// A step that leaves more than this many times the `(1 - α)` share of the dual
/// residual that an exact Newton step leaves switches iterative refinement on.
const REFINE_SHORTFALL: f64 = 10.0;
/// Iterations without a better iterate, once one meets the reduced tolerances, after
/// which the best is returned (`AlmostSolved`): a healthy interior point improves at
/// every step near the optimum, and continuing only lets `W = λ / s` grow until the
/// Newton steps lose all accuracy.
const STAGNATION: u32 = 5;
/// Largest fraction of the step to the boundary, taken when the centring is below
/// `1 - MAX_STEP_FRACTION`.
const MAX_STEP_FRACTION: f64 = 0.9999;
/// Fraction of the step to the boundary of the positive orthant.
const STEP_FRACTION: f64 = 0.995;
/// Largest factor by which one corrected step may grow the mean complementarity `μ` once
/// the iterate's residuals meet the tolerance; a step that grows it more is recomputed
/// without Mehrotra's second-order term `Δs_aff ∘ Δλ_aff` (centring only, the same
/// factorization). After a short predictor that product can be several times `μ`: on a
/// feasible aggregator plan (issue 12, K = 27) a steering bound with `s = 2.5e-5`,
/// `Δs = -5.8e-4`, `Δλ = 241` (predictor 0.043, `μ = 0.047`) made the corrected step
/// double `μ`, and the iterates cycled with period 4 for 100 iterations at a relative
/// gap of 1e-2 with the residuals at 1e-15. Once only the gap is left to close, a step
/// that increases `μ` is a step back; 1 is the loosest bound that says so. Not applied
/// before the residuals meet the tolerance: on an infeasible problem `μ` grows with the
/// multipliers that become the certificate, and both this rule without that condition
/// and dropping the term after every predictor shorter than 0.1 stopped infeasible
/// problems on `InsufficientProgress` instead of `Infeasible`.
const MU_GROWTH: f64 = 1.0;

/// Stopping tolerances (from [`SolverSettings`](crate::SolverSettings)).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Tolerances {
    pub max_iter: u32,
    pub gap_abs: f64,
    pub gap_rel: f64,
    pub feas: f64,
}

/// How the interior point ended.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Outcome {
    Solved,
    AlmostSolved,
    PrimalInfeasible,
    Failed(SolverFailure),
}

/// A copy of the primal-dual iterate.
#[derive(Debug, Default)]
struct Iterate {
    z: Vec<Vector6<f64>>,
    sigma: Vec<f64>,
    y_initial: Vector4<f64>,
    y_dynamics: Vec<Vector4<f64>>,
    y_terminal: Vector4<f64>,
    s: Vec<f64>,
    lambda: Vec<f64>,
}

/// The iterate, the residuals and every buffer of the Newton systems.
#[derive(Debug, Default)]
pub(crate) struct Ipm {
    // Iterate: stage variables, slacks, multipliers, inequality slacks and duals.
    pub z: Vec<Vector6<f64>>,
    pub sigma: Vec<f64>,
    pub y_initial: Vector4<f64>,
    pub y_dynamics: Vec<Vector4<f64>>,
    pub y_terminal: Vector4<f64>,
    pub s: Vec<f64>,
    pub lambda: Vec<f64>,
    pub iterations: u32,
    // Residuals.
    /// `Pz + q` per stage.
    grad: Vec<Vector6<f64>>,
    r_dual: Vec<Vector6<f64>>,
    r_dual_sigma: Vec<f64>,
    r_initial: Vector4<f64>,
    r_terminal: Vector4<f64>,
    r_in: Vec<f64>,
    // Newton system.
    w: Vec<f64>,
    inv_s: Vec<f64>,
    xi: Vec<f64>,
    rc: Vec<f64>,
    /// `diag(Gᵀ W G)` after the slack elimination, per stage: the Newton Hessian is
    /// the cost block plus this diagonal.
    newton_diag: Vec<Vector6<f64>>,
    /// `1 / Σ_R W c_σ²` per slack.
    inv_h_ss: Vec<f64>,
    h_sv: Vec<f64>,
    g: Vec<Vector6<f64>>,
    g_sigma: Vec<f64>,
    offsets: Vec<Vector4<f64>>,
    // Newton step.
    dz: Vec<Vector6<f64>>,
    d_sigma: Vec<f64>,
    ds: Vec<f64>,
    d_lambda: Vec<f64>,
    y_initial_new: Vector4<f64>,
    y_dynamics_new: Vec<Vector4<f64>>,
    y_terminal_new: Vector4<f64>,
    // Iterative refinement: the residual of the stationarity rows and the correction.
    e: Vec<Vector6<f64>>,
    e_sigma: Vec<f64>,
    d_sigma_c: Vec<f64>,
    zero_offsets: Vec<Vector4<f64>>,
    dz_c: Vec<Vector6<f64>>,
    y_dynamics_c: Vec<Vector4<f64>>,
    riccati: Riccati,
    // The best iterate so far, returned when the iterations stagnate near the optimum.
    best_iterate: Iterate,
    best: Option<Measures>,
    best_merit: f64,
    // Data norms.
    norm_b: f64,
    norm_q: f64,
    // The iterate with the best infeasibility certificate at the reduced tolerance
    // (ratio `‖Aᵀy + Gᵀλ‖∞ / -(bᵀy + hᵀλ)`), returned when the iterations stop.
    certificate_iterate: Iterate,
    certificate_ratio: f64,
}

impl Ipm {
    /// Sizes every buffer for `qp` (the only allocation of a solve).
    pub fn resize(&mut self, qp: &StageQp) {
        let (k, n_slack, m_in) = (qp.k, qp.slack_cost.len(), qp.inequalities.len());
        let sized = self.z.len() == k + 1
            && self.y_dynamics.len() == k
            && self.sigma.len() == n_slack
            && self.s.len() == m_in;
        if sized {
            // Same sizes as the last plan: every buffer is overwritten before it is
            // read, except the iterate, which starts at zero.
            self.z.fill(Vector6::zeros());
            self.y_dynamics.fill(Vector4::zeros());
            self.sigma.fill(0.0);
            self.s.fill(0.0);
            self.lambda.fill(0.0);
        } else {
            self.allocate(k, n_slack, m_in);
        }
        self.y_initial = Vector4::zeros();
        self.y_terminal = Vector4::zeros();
        self.iterations = 0;
        self.best = None;
        self.set_norms(qp);
    }

    /// Sizes and zeroes every buffer.
    fn allocate(&mut self, k: usize, n_slack: usize, m_in: usize) {
        for v in [
            &mut self.z,
            &mut self.grad,
            &mut self.r_dual,
            &mut self.g,
            &mut self.dz,
            &mut self.e,
            &mut self.dz_c,
        ] {
            v.clear();
            v.resize(k + 1, Vector6::zeros());
        }
        for v in [
            &mut self.y_dynamics,
            &mut self.offsets,
            &mut self.y_dynamics_new,
            &mut self.zero_offsets,
            &mut self.y_dynamics_c,
        ] {
            v.clear();
            v.resize(k, Vector4::zeros());
        }
        for v in [
            &mut self.sigma,
            &mut self.r_dual_sigma,
            &mut self.inv_h_ss,
            &mut self.h_sv,
            &mut self.g_sigma,
            &mut self.d_sigma,
            &mut self.e_sigma,
            &mut self.d_sigma_c,
        ] {
            v.clear();
            v.resize(n_slack, 0.0);
        }
        for v in [
            &mut self.s,
            &mut self.lambda,
            &mut self.r_in,
            &mut self.w,
            &mut self.inv_s,
            &mut self.xi,
            &mut self.rc,
            &mut self.ds,
            &mut self.d_lambda,
        ] {
            v.clear();
            v.resize(m_in, 0.0);
        }
        self.newton_diag.clear();
        self.newton_diag.resize(k + 1, Vector6::zeros());
        for b in [&mut self.best_iterate, &mut self.certificate_iterate] {
            b.z.clear();
            b.z.resize(k + 1, Vector6::zeros());
            b.y_dynamics.clear();
            b.y_dynamics.resize(k, Vector4::zeros());
            b.sigma.clear();
            b.sigma.resize(n_slack, 0.0);
            for v in [&mut b.s, &mut b.lambda] {
                v.clear();
                v.resize(m_in, 0.0);
            }
        }
        self.best = None;
        self.riccati.resize(k);
        self.y_initial = Vector4::zeros();
        self.y_terminal = Vector4::zeros();
        self.iterations = 0;
    }

    /// The norms of the data used by the stopping rule.
    fn set_norms(&mut self, qp: &StageQp) {
        let m = qp.terminal_rows;
        self.norm_b = norm_inf(qp.x0.iter())
            .max(qp.dynamics.iter().fold(0.0, |n, d| n.max(d.c.amax())))
            .max(norm_inf(qp.terminal_rhs.iter().take(m)))
            .max(norm_inf(qp.inequalities.iter().map(|r| &r.h)));
        self.norm_q = qp
            .linear
            .iter()
            .fold(0.0_f64, |n, g| n.max(g.amax()))
            .max(norm_inf(&qp.slack_cost));
    }

    /// Runs the interior point from Mehrotra's start; the iterate holds the result.
    pub fn run(&mut self, qp: &StageQp, tol: &Tolerances) -> Outcome {
        if let Err(e) = self.start(qp) {
            return Outcome::Failed(describe(e).into());
        }
        let mut stalled = 0;
        let mut since_best = 0;
        let mut refining = false;
        let mut previous = None;
        self.best_merit = f64::INFINITY;
        self.certificate_ratio = f64::INFINITY;
        loop {
            let measures = self.residuals(qp);
            if measures.meets(tol.gap_abs, tol.gap_rel, tol.feas) {
                return Outcome::Solved;
            }
            if measures.infeasible(INFEASIBILITY_TOLERANCE) {
                return Outcome::PrimalInfeasible;
            }
            if measures.infeasible(REDUCED_INFEASIBILITY) {
                let ratio = measures.certificate_residual / -measures.certificate_value;
                if ratio < self.certificate_ratio {
                    self.certificate_ratio = ratio;
                    let mut c = std::mem::take(&mut self.certificate_iterate);
                    save(&mut c, self);
                    self.certificate_iterate = c;
                }
            }
            let merit = measures.merit(tol);
            // Only an iterate that meets the reduced tolerances can be returned.
            let candidate = measures.meets(REDUCED_GAP, REDUCED_GAP, REDUCED_FEAS);
            if candidate && merit < self.best_merit {
                self.save_best(merit, measures);
                since_best = 0;
            } else {
                since_best += 1;
            }
            let stagnant = since_best >= STAGNATION
                && self
                    .best
                    .is_some_and(|b| b.meets(REDUCED_GAP, REDUCED_GAP, REDUCED_FEAS));
            if self.iterations >= tol.max_iter || stalled >= 3 || stagnant {
                let reason = if stalled >= 3 || stagnant {
                    SolverFailure::InsufficientProgress
                } else {
                    SolverFailure::MaxIterations
                };
                return self.stop(&measures, reason);
            }
            self.iterations += 1;
            // An exact Newton step scales the dual residual by (1 - α). Near the
            // optimum, `W = λ / s` spans many orders of magnitude and the step loses
            // accuracy in the stationarity rows; once a step falls short of that
            // reduction, every later corrector step gets one refinement step.
            refining |= previous.is_some_and(|(res_dual, alpha): (f64, f64)| {
                measures.res_dual > 0.1 * tol.feas
                    && measures.res_dual > REFINE_SHORTFALL * (1.0 - alpha).max(1e-3) * res_dual
            });
            let refine = refining;
            let feasible = measures.res_primal < tol.feas && measures.res_dual < tol.feas;
            match self.iterate(qp, refine, feasible) {
                Ok(alpha) => {
                    stalled = if alpha < 1e-8 { stalled + 1 } else { 0 };
                    previous = Some((measures.res_dual, alpha));
                }
                Err(e) => return self.stop(&measures, describe(e).into()),
            }
        }
    }

    /// The end without convergence: the best iterate if it meets clarabel's reduced
    /// tolerances (`AlmostSolved`), an infeasibility certificate at the reduced
    /// tolerance, or the failure `reason`.
    fn stop(&mut self, current: &Measures, reason: SolverFailure) -> Outcome {
        if self
            .best
            .is_some_and(|b| b.meets(REDUCED_GAP, REDUCED_GAP, REDUCED_FEAS))
        {
            self.restore_best();
            return Outcome::AlmostSolved;
        }
        if current.infeasible(REDUCED_INFEASIBILITY) {
            return Outcome::PrimalInfeasible;
        }
        // An earlier iterate's certificate: after a breakdown of the usual Riccati
        // pass, the steps of the projected one can leave the certificate worse than it
        // was (issue 12, a hard-zone case at `PROPTEST_CASES=20000`).
        if self.certificate_ratio <= REDUCED_INFEASIBILITY {
            let c = std::mem::take(&mut self.certificate_iterate);
            restore(self, &c);
            self.certificate_iterate = c;
            return Outcome::PrimalInfeasible;
        }
        Outcome::Failed(reason)
    }

    fn save_best(&mut self, merit: f64, measures: Measures) {
        self.best_merit = merit;
        self.best = Some(measures);
        let b = &mut self.best_iterate;
        b.z.copy_from_slice(&self.z);
        b.sigma.copy_from_slice(&self.sigma);
        b.y_dynamics.copy_from_slice(&self.y_dynamics);
        b.s.copy_from_slice(&self.s);
        b.lambda.copy_from_slice(&self.lambda);
        b.y_initial = self.y_initial;
        b.y_terminal = self.y_terminal;
    }

    fn restore_best(&mut self) {
        let b = &self.best_iterate;
        self.z.copy_from_slice(&b.z);
        self.sigma.copy_from_slice(&b.sigma);
        self.y_dynamics.copy_from_slice(&b.y_dynamics);
        self.s.copy_from_slice(&b.s);
        self.lambda.copy_from_slice(&b.lambda);
        self.y_initial = b.y_initial;
        self.y_terminal = b.y_terminal;
    }

    /// Mehrotra's starting point.
    fn start(&mut self, qp: &StageQp) -> Result<(), FactorError> {
        self.residuals(qp);
        self.w.fill(1.0);
        self.factor(qp)?;
        for (xi, row) in self.xi.iter_mut().zip(&qp.inequalities) {
            *xi = -row.h;
        }
        // rc, λ and 1/s are zero here, so the Δλ the step computes is unused noise-free 0.
        self.rc.fill(0.0);
        self.inv_s.fill(0.0);
        self.newton_step(qp);
        self.z.copy_from_slice(&self.dz);
        self.sigma.copy_from_slice(&self.d_sigma);
        self.y_initial = self.y_initial_new;
        self.y_dynamics.copy_from_slice(&self.y_dynamics_new);
        self.y_terminal = self.y_terminal_new;
        // ds = h - G z; s = h - G z and λ = G z - h, shifted into the orthant.
        for j in 0..self.s.len() {
            self.s[j] = self.ds[j];
            self.lambda[j] = -self.ds[j];
        }
        let shift = |v: &mut [f64]| {
            let min = v.iter().copied().fold(f64::INFINITY, f64::min);
            let delta = (-1.5 * min).max(0.0);
            v.iter_mut().for_each(|x| *x += delta);
        };
        shift(&mut self.s);
        shift(&mut self.lambda);
        let sl: f64 = self.s.iter().zip(&self.lambda).map(|(s, l)| s * l).sum();
        let (sum_s, sum_l) = (self.s.iter().sum::<f64>(), self.lambda.iter().sum::<f64>());
        if sl > 1e-8 * self.s.len() as f64 && sum_s > 0.0 && sum_l > 0.0 {
            let (ds, dl) = (0.5 * sl / sum_l, 0.5 * sl / sum_s);
            self.s.iter_mut().for_each(|x| *x += ds);
            self.lambda.iter_mut().for_each(|x| *x += dl);
        } else {
            self.s.iter_mut().for_each(|x| *x += 1.0);
            self.lambda.iter_mut().for_each(|x| *x += 1.0);
        }
        Ok(())
    }

    /// One predictor-corrector iteration; returns the step length.
    /// `feasible`: the residuals of the iterate meet the stopping tolerance.
    fn iterate(&mut self, qp: &StageQp, refine: bool, feasible: bool) -> Result<f64, FactorError> {
        let n = self.s.len();
        let m_in = n as f64;
        // Predictor: r_c = s∘λ, so ξ = λ + W r_in - r_c / s = W r_in.
        let mu = {
            let Self {
                s,
                lambda,
                inv_s,
                w,
                rc,
                xi,
                r_in,
                ..
            } = self;
            let (s, lambda, r_in) = (&s[..n], &lambda[..n], &r_in[..n]);
            let (inv_s, w, rc, xi) = (&mut inv_s[..n], &mut w[..n], &mut rc[..n], &mut xi[..n]);
            let mut sl = 0.0;
            for j in 0..n {
                inv_s[j] = 1.0 / s[j];
                w[j] = lambda[j] * inv_s[j];
                rc[j] = s[j] * lambda[j];
                xi[j] = w[j] * r_in[j];
                sl += rc[j];
            }
            sl / m_in
        };
        self.factor(qp)?;
        let alpha = self.newton_step(qp);
        let centering = {
            let Self {
                s,
                lambda,
                inv_s,
                w,
                rc,
                xi,
                r_in,
                ds,
                d_lambda,
                ..
            } = self;
            let (s, lambda, r_in, inv_s, w) =
                (&s[..n], &lambda[..n], &r_in[..n], &inv_s[..n], &w[..n]);
            let (ds, d_lambda) = (&ds[..n], &d_lambda[..n]);
            let (rc, xi) = (&mut rc[..n], &mut xi[..n]);
            let mut mu_affine = 0.0;
            for j in 0..n {
                mu_affine += (s[j] + alpha * ds[j]) * (lambda[j] + alpha * d_lambda[j]);
            }
            let centering = (mu_affine / m_in / mu).clamp(0.0, 1.0).powi(3);
            // Corrector with centring, from the affine step.
            let shift = centering * mu;
            for j in 0..n {
                rc[j] = s[j] * lambda[j] + ds[j] * d_lambda[j] - shift;
                xi[j] = lambda[j] + w[j] * r_in[j] - rc[j] * inv_s[j];
            }
            centering
        };
        let mut alpha = self.newton_step(qp);
        if refine {
            self.refine(qp);
            alpha = self.dual_step_to_boundary();
        }
        // Bolder steps when the predictor was good (little centring needed).
        let fraction = (1.0 - centering).clamp(STEP_FRACTION, MAX_STEP_FRACTION);
        let mut alpha = (fraction * alpha).min(1.0);
        if feasible && self.mean_complementarity_after(alpha) > MU_GROWTH * mu {
            // The second-order term misled the step: centre only (the last Δs, Δλ are
            // the corrector's; r_c is rebuilt from s∘λ).
            let shift = centering * mu;
            for j in 0..n {
                self.rc[j] = self.s[j] * self.lambda[j] - shift;
                self.xi[j] = self.lambda[j] + self.w[j] * self.r_in[j] - self.rc[j] * self.inv_s[j];
            }
            alpha = self.newton_step(qp);
            if refine {
                self.refine(qp);
                alpha = self.dual_step_to_boundary();
            }
            alpha = (fraction * alpha).min(1.0);
        }

        for (z, dz) in self.z.iter_mut().zip(&self.dz) {
            *z += alpha * dz;
        }
        for (x, dx) in self.sigma.iter_mut().zip(&self.d_sigma) {
            *x += alpha * dx;
        }
        for (x, dx) in self.s.iter_mut().zip(&self.ds) {
            *x += alpha * dx;
        }
        for (x, dx) in self.lambda.iter_mut().zip(&self.d_lambda) {
            *x += alpha * dx;
        }
        self.y_initial += alpha * (self.y_initial_new - self.y_initial);
        for (y, y_new) in self.y_dynamics.iter_mut().zip(&self.y_dynamics_new) {
            *y += alpha * (y_new - *y);
        }
        self.y_terminal += alpha * (self.y_terminal_new - self.y_terminal);
        Ok(alpha)
    }
}

impl Ipm {
    /// `(s + α Δs)ᵀ(λ + α Δλ) / m` for the last Newton step.
    fn mean_complementarity_after(&self, alpha: f64) -> f64 {
        let n = self.s.len();
        let (s, lambda, ds, d_lambda) = (
            &self.s[..n],
            &self.lambda[..n],
            &self.ds[..n],
            &self.d_lambda[..n],
        );
        let mut sum = 0.0;
        for j in 0..n {
            sum += (s[j] + alpha * ds[j]) * (lambda[j] + alpha * d_lambda[j]);
        }
        sum / n as f64
    }
}

/// Copies the iterate of `ipm` into `b`.
fn save(b: &mut Iterate, ipm: &Ipm) {
    b.z.copy_from_slice(&ipm.z);
    b.sigma.copy_from_slice(&ipm.sigma);
    b.y_dynamics.copy_from_slice(&ipm.y_dynamics);
    b.s.copy_from_slice(&ipm.s);
    b.lambda.copy_from_slice(&ipm.lambda);
    b.y_initial = ipm.y_initial;
    b.y_terminal = ipm.y_terminal;
}

/// Copies `b` into the iterate of `ipm`.
fn restore(ipm: &mut Ipm, b: &Iterate) {
    ipm.z.copy_from_slice(&b.z);
    ipm.sigma.copy_from_slice(&b.sigma);
    ipm.y_dynamics.copy_from_slice(&b.y_dynamics);
    ipm.s.copy_from_slice(&b.s);
    ipm.lambda.copy_from_slice(&b.lambda);
    ipm.y_initial = b.y_initial;
    ipm.y_terminal = b.y_terminal;
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
