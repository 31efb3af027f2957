//! The Newton systems of the interior point: the Newton Hessian and its Riccati
//! factorization, the predictor and corrector steps, their step length, and one step
//! of iterative refinement.

use nalgebra::{Vector4, Vector6};

use super::super::recursion::{FactorError, Rhs, Step};
use super::super::stage_qp::{Inequality, StageQp};
use super::{Ipm, head};

/// `(G z)_j`: row `j` of the inequalities applied to stage variables `z` and slacks `σ`.
#[inline(always)]
pub(super) fn row_times(row: &Inequality, z: &[Vector6<f64>], sigma: &[f64]) -> f64 {
    row.core.map_or(0.0, |(i, l)| row.coef * z[i][l])
        + row.slack.map_or(0.0, |k| row.slack_coef * sigma[k])
}

/// `Δλ_j = -(r_c + λ Δs) / s` of one row, and the step bound `α` tightened so that
/// `s + α Δs >= 0` and `λ + α Δλ >= 0` (a division only where the bound tightens,
/// rare once `α` has settled).
#[inline(always)]
fn dual_step(s: f64, lambda: f64, rc: f64, inv_s: f64, ds: f64, alpha: &mut f64) -> f64 {
    let dl = -(rc + lambda * ds) * inv_s;
    if s + *alpha * ds < 0.0 {
        *alpha = -s / ds;
    }
    if lambda + *alpha * dl < 0.0 {
        *alpha = -lambda / dl;
    }
    dl
}

/// `out += Gᵀ v`, split into stage variables and slacks.
fn add_g_transpose(qp: &StageQp, v: &[f64], out: &mut [Vector6<f64>], out_sigma: &mut [f64]) {
    for (row, &v) in qp.inequalities.iter().zip(v) {
        if let Some((i, l)) = row.core {
            out[i][l] += row.coef * v;
        }
        if let Some(j) = row.slack {
            out_sigma[j] += row.slack_coef * v;
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
    dz: &[Vector6<f64>],
    g_sigma: &[f64],
    d_sigma: &mut [f64],
) {
    let n = qp.slack_core.len();
    let (d_sigma, g_sigma, h_sv, inv_h_ss) =
        (&mut d_sigma[..n], &g_sigma[..n], &h_sv[..n], &inv_h_ss[..n]);
    for (j, core) in qp.slack_core.iter().enumerate() {
        let coupled = core.map_or(0.0, |(i, l)| h_sv[j] * dz[i][l]);
        d_sigma[j] = -(g_sigma[j] + coupled) * inv_h_ss[j];
    }
}

impl Ipm {
    /// `Δλ = -r_c / s - W Δs`, and the largest `α <= 1` with `s + α Δs >= 0` and
    /// `λ + α Δλ >= 0`.
    pub(super) fn dual_step_to_boundary(&mut self) -> f64 {
        let mut alpha = 1.0_f64;
        for j in 0..self.s.len() {
            let (s, l, rc, inv_s) = (self.s[j], self.lambda[j], self.rc[j], self.inv_s[j]);
            self.d_lambda[j] = dual_step(s, l, rc, inv_s, self.ds[j], &mut alpha);
        }
        alpha
    }

    /// One step of iterative refinement of the Newton step: the residual
    /// `e = P Δz + Aᵀ Δy + Gᵀ Δλ + r_d` of the stationarity rows (the other rows hold
    /// by construction), then the correction from the same factorization with `-e` on
    /// the right-hand side and zero equality residuals.
    pub(super) fn refine(&mut self, qp: &StageQp) {
        let k = qp.k;
        for i in 0..=k {
            self.e[i] = qp.hessian[i] * self.dz[i] + self.r_dual[i];
        }
        self.e_sigma.copy_from_slice(&self.r_dual_sigma);
        head(&mut self.e[0], &(self.y_initial_new - self.y_initial));
        for i in 0..k {
            let d = &qp.dynamics[i];
            let dy = self.y_dynamics_new[i] - self.y_dynamics[i];
            head(&mut self.e[i + 1], &dy);
            head(&mut self.e[i], &-d.sparse.a_tr_mul(&dy));
            let mut tail = self.e[i].fixed_rows_mut::<2>(4);
            tail -= d.sparse.b_tr_mul(&dy);
        }
        let dnu = self.y_terminal_new - self.y_terminal;
        head(&mut self.e[k], &qp.terminal.tr_mul(&dnu));
        add_g_transpose(qp, &self.d_lambda, &mut self.e, &mut self.e_sigma);
        eliminate_slacks(qp, &self.h_sv, &self.inv_h_ss, &mut self.e, &self.e_sigma);
        let rhs = Rhs {
            linear: &self.e,
            offsets: &self.zero_offsets,
            initial: Vector4::zeros(),
            terminal: Vector4::zeros(),
        };
        let (mut dy0, mut dnu) = (Vector4::zeros(), Vector4::zeros());
        self.riccati.solve(
            &qp.dynamics,
            &rhs,
            Step {
                z: &mut self.dz_c,
                y_dynamics: &mut self.y_dynamics_c,
                y_initial: &mut dy0,
                y_terminal: &mut dnu,
            },
        );
        recover_slacks(
            qp,
            &self.h_sv,
            &self.inv_h_ss,
            &self.dz_c,
            &self.e_sigma,
            &mut self.d_sigma_c,
        );
        for i in 0..=k {
            self.dz[i] += self.dz_c[i];
        }
        for i in 0..k {
            self.y_dynamics_new[i] += self.y_dynamics_c[i];
        }
        self.y_initial_new += dy0;
        self.y_terminal_new += dnu;
        for (d_sigma, correction) in self.d_sigma.iter_mut().zip(&self.d_sigma_c) {
            *d_sigma += correction;
        }
        for (ds, row) in self.ds.iter_mut().zip(&qp.inequalities) {
            *ds -= row_times(row, &self.dz_c, &self.d_sigma_c);
        }
    }

    /// `P + Gᵀ W G` in stage form, the slacks eliminated, and its Riccati factorization.
    ///
    /// A slack `σ` and its variable `l` share the rows `R`; eliminating `σ` adds
    /// `Σ_R W c² - (Σ_R W c c_σ)² / Σ_R W c_σ²` to `l`'s diagonal. Written so, the
    /// difference cancels catastrophically once a bound is active (`W ~ 1e12` next to an
    /// `O(1)` result) and the iterations stall; the Lagrange identity gives the same
    /// value as a sum of non-negative terms, `Σ_{p<q} W_p W_q (c_p c_σq - c_q c_σp)² /
    /// Σ_R W c_σ²`, which is what is added.
    pub(super) fn factor(&mut self, qp: &StageQp) -> Result<(), FactorError> {
        self.newton_diag.fill(Vector6::zeros());
        for (row, &w) in qp.inequalities.iter().zip(&self.w) {
            if let (Some((i, l)), None) = (row.core, row.slack) {
                self.newton_diag[i][l] += w * row.coef * row.coef;
            }
        }
        for (j, rows) in qp.slack_rows.iter().enumerate() {
            let rows = rows.iter().take_while(|&&r| r != usize::MAX);
            let (mut h_ss, mut h_sv, mut pairs) = (0.0, 0.0, 0.0);
            for (n, &p) in rows.clone().enumerate() {
                let (rp, wp) = (&qp.inequalities[p], self.w[p]);
                let cp = if rp.core.is_some() { rp.coef } else { 0.0 };
                h_ss += wp * rp.slack_coef * rp.slack_coef;
                h_sv += wp * cp * rp.slack_coef;
                for &q in rows.clone().skip(n + 1) {
                    let (rq, wq) = (&qp.inequalities[q], self.w[q]);
                    let cq = if rq.core.is_some() { rq.coef } else { 0.0 };
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

    /// Solves the factored Newton system for the current `ξ` and residuals:
    /// `(P + GᵀWG) Δz + Aᵀ y⁺ = -(Pz + q + Gᵀξ)`, `A Δz = -r_eq`, then `Δs = -r_in - G Δz`
    /// and `Δλ = -(r_c + λ Δs) / s`; returns the largest step `α <= 1` that keeps `s`
    /// and `λ` non-negative.
    pub(super) fn newton_step(&mut self, qp: &StageQp) -> f64 {
        self.g.copy_from_slice(&self.grad);
        self.g_sigma.copy_from_slice(&qp.slack_cost);
        add_g_transpose(qp, &self.xi, &mut self.g, &mut self.g_sigma);
        eliminate_slacks(qp, &self.h_sv, &self.inv_h_ss, &mut self.g, &self.g_sigma);
        let rhs = Rhs {
            linear: &self.g,
            offsets: &self.offsets,
            initial: -self.r_initial,
            terminal: -self.r_terminal,
        };
        self.riccati.solve(
            &qp.dynamics,
            &rhs,
            Step {
                z: &mut self.dz,
                y_dynamics: &mut self.y_dynamics_new,
                y_initial: &mut self.y_initial_new,
                y_terminal: &mut self.y_terminal_new,
            },
        );
        recover_slacks(
            qp,
            &self.h_sv,
            &self.inv_h_ss,
            &self.dz,
            &self.g_sigma,
            &mut self.d_sigma,
        );
        // Slices of one length, bound once: no bounds checks or field reloads in the loop.
        let rows = &qp.inequalities[..];
        let n = rows.len();
        let Self {
            dz,
            d_sigma,
            r_in,
            rc,
            lambda,
            inv_s,
            s,
            ds,
            d_lambda,
            ..
        } = self;
        let (r_in, rc, lambda, inv_s, s) =
            (&r_in[..n], &rc[..n], &lambda[..n], &inv_s[..n], &s[..n]);
        let (ds, d_lambda) = (&mut ds[..n], &mut d_lambda[..n]);
        let mut alpha = 1.0_f64;
        for j in 0..n {
            let step_s = -r_in[j] - row_times(&rows[j], dz, d_sigma);
            ds[j] = step_s;
            d_lambda[j] = dual_step(s[j], lambda[j], rc[j], inv_s[j], step_s, &mut alpha);
        }
        alpha
    }
}
