//! The Newton (KKT) systems of the interior point, solved by the Riccati recursion.
//!
//! With `W = diag(λ / s)`, the Newton system of the KKT conditions reduces, after
//! eliminating `Δs = -r_in - G Δx` and `Δλ = -(r_c + λ ∘ Δs) / s`, to the
//! equality-constrained QP
//!
//! ```text
//! (P + Gᵀ W G) Δx + Aᵀ y⁺ = -(P x + q + Gᵀ ξ),   A Δx = -r_eq,   ξ = λ + W r_in - r_c / s,
//! ```
//!
//! whose right-hand side `r_c` is `s ∘ λ` in the predictor and
//! `s ∘ λ + Δs_aff ∘ Δλ_aff - σ μ` in the corrector (Mehrotra). Each soft-bound slack
//! `σ` is a scalar tied to one lateral position by its rows; it is eliminated next
//! (a Schur complement on a scalar), and what is left has the stage structure of
//! Eqs. (9)-(23): 6 x 6 blocks `H_i + diag(d_i)`, the dynamics and the terminal rows,
//! which the [`Riccati`] recursion factors once per iteration and solves twice
//! (predictor and corrector), plus once per step of iterative refinement.

use nalgebra::{Vector4, Vector6};

use super::super::recursion::{FactorError, Rhs, Riccati, Step};
use super::head;
use super::residuals::Residuals;
use super::step::dual_step;
use super::variables::{Direction, Variables, resize_keep};
use crate::qp::{StageQp, flat, flat_mut, hessian_mul};

/// The Newton system's data, its factorization and its solve buffers.
#[derive(Debug, Default)]
pub(crate) struct Kkt {
    /// `W = λ / s` per inequality row.
    pub w: Vec<f64>,
    /// `1 / s` per inequality row.
    pub inv_s: Vec<f64>,
    /// `ξ = λ + W r_in - r_c / s` per inequality row.
    pub xi: Vec<f64>,
    /// `r_c` per inequality row (the complementarity right-hand side).
    pub rc: Vec<f64>,
    /// `diag(Gᵀ W G)` after the slack elimination, per stage: the Newton Hessian is
    /// the cost block plus this diagonal.
    newton_diag: Vec<Vector6<f64>>,
    /// `1 / Σ_R W c_σ²` per slack.
    inv_h_ss: Vec<f64>,
    /// `Σ_R W c c_σ` per slack: its coupling to its stage variable.
    h_sv: Vec<f64>,
    /// The linear term of the stage-form right-hand side.
    g: Vec<Vector6<f64>>,
    /// The linear term of each slack's row of the right-hand side.
    g_sigma: Vec<f64>,
    riccati: Riccati,
    // Iterative refinement: the residual of the stationarity rows and the correction.
    e: Vec<Vector6<f64>>,
    e_sigma: Vec<f64>,
    zero_offsets: Vec<Vector4<f64>>,
    correction: Direction,
}

/// `out += Gᵀ v`, split into stage variables and slacks.
fn add_g_transpose(qp: &StageQp, v: &[f64], out: &mut [Vector6<f64>], out_sigma: &mut [f64]) {
    let out = flat_mut(out);
    for (row, &v) in qp.inequalities.iter().zip(v) {
        if let Some(x) = row.var_in(out) {
            *x += row.coef * v;
        }
        if let Some(x) = row.slack_in(out_sigma) {
            *x += row.slack_coef * v;
        }
    }
}

/// Eliminates each slack from a right-hand side: `g_l -= h_σl g_σ / h_σσ`.
fn eliminate_slacks(
    qp: &StageQp,
    h_sv: &[f64],
    inv_h_ss: &[f64],
    g: &mut [Vector6<f64>],
    g_sigma: &[f64],
) {
    let n = qp.slack_core.len();
    let (g_sigma, h_sv, inv_h_ss) = (&g_sigma[..n], &h_sv[..n], &inv_h_ss[..n]);
    for (j, core) in qp.slack_core.iter().enumerate() {
        if let Some((i, l)) = *core {
            g[i][l] -= h_sv[j] * g_sigma[j] * inv_h_ss[j];
        }
    }
}

/// Recovers each slack's step from its variable's: `Δσ = -(g_σ + h_σl Δl) / h_σσ`.
fn recover_slacks(
    qp: &StageQp,
    h_sv: &[f64],
    inv_h_ss: &[f64],
    d_ux: &[Vector6<f64>],
    g_sigma: &[f64],
    d_sigma: &mut [f64],
) {
    let n = qp.slack_core.len();
    let (d_sigma, g_sigma, h_sv, inv_h_ss) =
        (&mut d_sigma[..n], &g_sigma[..n], &h_sv[..n], &inv_h_ss[..n]);
    for (j, core) in qp.slack_core.iter().enumerate() {
        let coupled = core.map_or(0.0, |(i, l)| h_sv[j] * d_ux[i][l]);
        d_sigma[j] = -(g_sigma[j] + coupled) * inv_h_ss[j];
    }
}

impl Kkt {
    /// Sizes every buffer for `qp` (the only allocation of a solve).
    pub fn reset(&mut self, qp: &StageQp) {
        let (k, n_slack, m_in) = (qp.k, qp.slack_cost.len(), qp.inequalities.len());
        for v in [&mut self.newton_diag, &mut self.g, &mut self.e] {
            resize_keep(v, k + 1, Vector6::zeros());
        }
        resize_keep(&mut self.zero_offsets, k, Vector4::zeros());
        for v in [
            &mut self.inv_h_ss,
            &mut self.h_sv,
            &mut self.g_sigma,
            &mut self.e_sigma,
        ] {
            resize_keep(v, n_slack, 0.0);
        }
        for v in [&mut self.w, &mut self.inv_s, &mut self.xi, &mut self.rc] {
            resize_keep(v, m_in, 0.0);
        }
        self.correction.resize(k, n_slack, m_in);
        self.riccati.resize(k);
    }

    /// `P + Gᵀ W G` in stage form, the slacks eliminated, and its Riccati factorization.
    ///
    /// A slack `σ` and its variable `l` share the rows `R`; eliminating `σ` adds
    /// `Σ_R W c² - (Σ_R W c c_σ)² / Σ_R W c_σ²` to `l`'s diagonal. Written so, the
    /// difference cancels catastrophically once a bound is active (`W ~ 1e12` next to an
    /// `O(1)` result) and the iterations stall; the Lagrange identity gives the same
    /// value as a sum of non-negative terms, `Σ_{p<q} W_p W_q (c_p c_σq - c_q c_σp)² /
    /// Σ_R W c_σ²`, which is what is added.
    pub fn factor(&mut self, qp: &StageQp) -> Result<(), FactorError> {
        self.newton_diag.fill(Vector6::zeros());
        let diag = flat_mut(&mut self.newton_diag);
        for (row, &w) in qp.inequalities.iter().zip(&self.w) {
            if row.slack().is_none() {
                if let Some(x) = row.var_in(diag) {
                    *x += w * row.coef * row.coef;
                }
            }
        }
        for (j, rows) in qp.slack_rows.iter().enumerate() {
            let rows = rows.iter().map_while(|&r| r);
            let (mut h_ss, mut h_sv, mut pairs) = (0.0, 0.0, 0.0);
            for (n, p) in rows.clone().enumerate() {
                let (rp, wp) = (&qp.inequalities[p], self.w[p]);
                let cp = if rp.core().is_some() { rp.coef } else { 0.0 };
                h_ss += wp * rp.slack_coef * rp.slack_coef;
                h_sv += wp * cp * rp.slack_coef;
                for q in rows.clone().skip(n + 1) {
                    let (rq, wq) = (&qp.inequalities[q], self.w[q]);
                    let cq = if rq.core().is_some() { rq.coef } else { 0.0 };
                    let minor = cp * rq.slack_coef - cq * rp.slack_coef;
                    pairs += wp * wq * minor * minor;
                }
            }
            self.inv_h_ss[j] = 1.0 / h_ss;
            self.h_sv[j] = h_sv;
            if let Some((i, l)) = qp.slack_core[j] {
                self.newton_diag[i][l] += pairs * self.inv_h_ss[j];
            }
        }
        self.riccati.factor(
            &qp.hessian,
            &self.newton_diag,
            &qp.dynamics,
            &qp.terminal,
            qp.terminal_rows,
        )
    }

    /// Solves the factored Newton system for the current `ξ`, `r_c` and residuals into
    /// `d`: `(P + GᵀWG) Δx + Aᵀ y⁺ = -(Px + q + Gᵀξ)`, `A Δx = -r_eq`, then
    /// `Δs = -r_in - G Δx` and `Δλ = -(r_c + λ Δs) / s`; returns the largest step
    /// `α <= 1` that keeps `s` and `λ` non-negative.
    ///
    /// Without `multipliers` (the predictor), the equality multipliers of `d` are not
    /// computed and keep stale values.
    pub fn solve(
        &mut self,
        qp: &StageQp,
        v: &Variables,
        r: &Residuals,
        d: &mut Direction,
        multipliers: bool,
    ) -> f64 {
        self.g.copy_from_slice(&r.grad);
        self.g_sigma.copy_from_slice(&qp.slack_cost);
        add_g_transpose(qp, &self.xi, &mut self.g, &mut self.g_sigma);
        eliminate_slacks(qp, &self.h_sv, &self.inv_h_ss, &mut self.g, &self.g_sigma);
        let rhs = Rhs {
            linear: &self.g,
            offsets: &r.offsets,
            initial: -r.initial,
            terminal: -r.terminal,
        };
        self.riccati.solve(
            &qp.dynamics,
            &rhs,
            Step {
                ux: &mut d.ux,
                y_dynamics: &mut d.y_dynamics,
                y_initial: &mut d.y_initial,
                y_terminal: &mut d.y_terminal,
                multipliers,
            },
        );
        recover_slacks(
            qp,
            &self.h_sv,
            &self.inv_h_ss,
            &d.ux,
            &self.g_sigma,
            &mut d.sigma,
        );
        // Slices of one length, bound once: no bounds checks or field reloads in the loop.
        let rows = &qp.inequalities[..];
        let n = rows.len();
        let (r_in, rc, lambda, inv_s, s) = (
            &r.inequality[..n],
            &self.rc[..n],
            &v.lambda[..n],
            &self.inv_s[..n],
            &v.s[..n],
        );
        let (ds, d_lambda) = (&mut d.s[..n], &mut d.lambda[..n]);
        let mut alpha = 1.0_f64;
        let d_ux = flat(&d.ux);
        for j in 0..n {
            let step_s = -r_in[j] - rows[j].times(d_ux, &d.sigma);
            ds[j] = step_s;
            d_lambda[j] = dual_step(s[j], lambda[j], rc[j], inv_s[j], step_s, &mut alpha);
        }
        alpha
    }

    /// One step of iterative refinement of the Newton step `d`: the residual
    /// `e = P Δx + Aᵀ y⁺ + Gᵀ Δλ + r_dual - Aᵀ y` of the stationarity rows (the other
    /// rows hold by construction), then the correction from the same factorization with
    /// `-e` on the right-hand side and zero equality residuals.
    pub fn refine(&mut self, qp: &StageQp, v: &Variables, r: &Residuals, d: &mut Direction) {
        let k = qp.k;
        for i in 0..=k {
            self.e[i] = hessian_mul(&qp.hessian[i], &d.ux[i]) + r.dual[i];
        }
        self.e_sigma.copy_from_slice(&r.dual_sigma);
        head(&mut self.e[0], &(d.y_initial - v.y_initial));
        for i in 0..k {
            let dynamics = &qp.dynamics[i];
            let dy = d.y_dynamics[i] - v.y_dynamics[i];
            head(&mut self.e[i + 1], &dy);
            head(&mut self.e[i], &-dynamics.sparse.a_tr_mul(&dy));
            let mut tail = self.e[i].fixed_rows_mut::<2>(4);
            tail -= dynamics.sparse.b_tr_mul(&dy);
        }
        let dnu = d.y_terminal - v.y_terminal;
        head(&mut self.e[k], &qp.terminal.tr_mul(&dnu));
        add_g_transpose(qp, &d.lambda, &mut self.e, &mut self.e_sigma);
        eliminate_slacks(qp, &self.h_sv, &self.inv_h_ss, &mut self.e, &self.e_sigma);
        let rhs = Rhs {
            linear: &self.e,
            offsets: &self.zero_offsets,
            initial: Vector4::zeros(),
            terminal: Vector4::zeros(),
        };
        let c = &mut self.correction;
        let (mut dy0, mut dnu) = (Vector4::zeros(), Vector4::zeros());
        self.riccati.solve(
            &qp.dynamics,
            &rhs,
            Step {
                ux: &mut c.ux,
                y_dynamics: &mut c.y_dynamics,
                y_initial: &mut dy0,
                y_terminal: &mut dnu,
                multipliers: true,
            },
        );
        recover_slacks(
            qp,
            &self.h_sv,
            &self.inv_h_ss,
            &c.ux,
            &self.e_sigma,
            &mut c.sigma,
        );
        for i in 0..=k {
            d.ux[i] += c.ux[i];
        }
        for i in 0..k {
            d.y_dynamics[i] += c.y_dynamics[i];
        }
        d.y_initial += dy0;
        d.y_terminal += dnu;
        for (d_sigma, correction) in d.sigma.iter_mut().zip(&c.sigma) {
            *d_sigma += correction;
        }
        let c_ux = flat(&c.ux);
        for (ds, row) in d.s.iter_mut().zip(&qp.inequalities) {
            *ds -= row.times(c_ux, &c.sigma);
        }
    }

    /// `Δλ = -r_c / s - W Δs` for the `Δs` of `d`, and the largest `α <= 1` with
    /// `s + α Δs >= 0` and `λ + α Δλ >= 0`.
    pub fn dual_step_to_boundary(&self, v: &Variables, d: &mut Direction) -> f64 {
        let mut alpha = 1.0_f64;
        for j in 0..v.s.len() {
            let (s, l, rc, inv_s) = (v.s[j], v.lambda[j], self.rc[j], self.inv_s[j]);
            d.lambda[j] = dual_step(s, l, rc, inv_s, d.s[j], &mut alpha);
        }
        alpha
    }
}
