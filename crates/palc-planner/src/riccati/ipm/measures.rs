//! Residuals of an iterate and the measures of the stopping rule and of the
//! infeasibility certificate.

use nalgebra::Vector6;

use super::super::stage_qp::{NX, StageQp};
use super::newton::row_times;
use super::{Ipm, Tolerances, head};

/// Convergence measures of one iterate.
#[derive(Debug, Clone, Copy)]
pub(super) struct Measures {
    pub res_primal: f64,
    pub res_dual: f64,
    pub gap_abs: f64,
    pub gap_rel: f64,
    /// `bᵀy + hᵀλ` and `‖Aᵀy + Gᵀλ‖∞`.
    pub certificate_value: f64,
    pub certificate_residual: f64,
}

impl Measures {
    /// How far from the stopping rule: at most 1 when it is met.
    pub fn merit(&self, tol: &Tolerances) -> f64 {
        let gap = (self.gap_abs / tol.gap_abs).min(self.gap_rel / tol.gap_rel);
        (self.res_primal / tol.feas)
            .max(self.res_dual / tol.feas)
            .max(gap)
    }

    pub fn meets(&self, gap_abs: f64, gap_rel: f64, feas: f64) -> bool {
        (self.gap_abs < gap_abs || self.gap_rel < gap_rel)
            && self.res_primal < feas
            && self.res_dual < feas
    }

    pub fn infeasible(&self, tolerance: f64) -> bool {
        self.certificate_value < 0.0
            && self.certificate_residual <= tolerance * -self.certificate_value
    }
}

pub(super) fn norm_inf<'a>(values: impl IntoIterator<Item = &'a f64>) -> f64 {
    values.into_iter().fold(0.0_f64, |m, v| m.max(v.abs()))
}

impl Ipm {
    /// Residuals and convergence measures of the current iterate.
    pub(super) fn residuals(&mut self, qp: &StageQp) -> Measures {
        let k = qp.k;
        let m = qp.terminal_rows;
        // Pass over the inequalities: Gᵀλ into r_dual / r_dual_sigma, r_in, hᵀλ, norms.
        for v in self.r_dual.iter_mut() {
            *v = Vector6::zeros();
        }
        self.r_dual_sigma.fill(0.0);
        let (mut hl, mut norm_s, mut norm_lambda, mut norm_r_in) = (0.0, 0.0_f64, 0.0_f64, 0.0_f64);
        {
            let Self {
                lambda,
                s,
                r_dual,
                r_dual_sigma,
                z,
                sigma,
                r_in,
                ..
            } = self;
            let n = qp.inequalities.len();
            let (lambda, s, r_in) = (&lambda[..n], &s[..n], &mut r_in[..n]);
            for (j, row) in qp.inequalities.iter().enumerate() {
                let (l, s) = (lambda[j], s[j]);
                if let Some((i, c)) = row.core {
                    r_dual[i][c] += row.coef * l;
                }
                if let Some(n) = row.slack {
                    r_dual_sigma[n] += row.slack_coef * l;
                }
                let gz = row_times(row, z, sigma);
                let r = gz + s - row.h;
                r_in[j] = r;
                hl += row.h * l;
                norm_s = norm_s.max(s.abs());
                norm_lambda = norm_lambda.max(l.abs());
                norm_r_in = norm_r_in.max(r.abs());
            }
        }
        // Pass over the slacks.
        let (mut qx, mut certificate_residual, mut dual, mut norm_z) =
            (0.0, 0.0_f64, 0.0_f64, 0.0_f64);
        for j in 0..self.sigma.len() {
            certificate_residual = certificate_residual.max(self.r_dual_sigma[j].abs());
            qx += qp.slack_cost[j] * self.sigma[j];
            self.r_dual_sigma[j] += qp.slack_cost[j];
            dual = dual.max(self.r_dual_sigma[j].abs());
            norm_z = norm_z.max(self.sigma[j].abs());
        }
        // Pass over the stages: Aᵀy, Pz, the dynamics residuals, bᵀy, objectives, norms.
        self.r_initial = self.z[0].fixed_rows::<4>(0) - qp.x0;
        let mut by = qp.x0.dot(&self.y_initial);
        let mut norm_y = self.y_initial.amax().max(self.y_terminal.amax());
        let mut primal = self.r_initial.amax().max(norm_r_in);
        let mut xpx = 0.0;
        for i in 0..=k {
            let incoming = if i == 0 {
                self.y_initial
            } else {
                self.y_dynamics[i - 1]
            };
            head(&mut self.r_dual[i], &incoming);
            if i < k {
                let d = &qp.dynamics[i];
                let y = self.y_dynamics[i];
                head(&mut self.r_dual[i], &-d.sparse.a_tr_mul(&y));
                let mut tail = self.r_dual[i].fixed_rows_mut::<2>(4);
                tail -= d.sparse.b_tr_mul(&y);
                by += d.c.dot(&y);
                norm_y = norm_y.max(y.amax());
                let x = self.z[i].fixed_rows::<4>(0).into_owned();
                let u = self.z[i].fixed_rows::<2>(4).into_owned();
                let r = self.z[i + 1].fixed_rows::<4>(0)
                    - d.sparse.a_mul(&x)
                    - d.sparse.b_mul(&u)
                    - d.c;
                primal = primal.max(r.amax());
                self.offsets[i] = -r;
            } else {
                head(&mut self.r_dual[k], &qp.terminal.tr_mul(&self.y_terminal));
            }
            certificate_residual = certificate_residual.max(self.r_dual[i].amax());
            let pz = qp.hessian[i] * self.z[i];
            xpx += self.z[i].dot(&pz);
            qx += qp.linear[i].dot(&self.z[i]);
            let grad = pz + qp.linear[i];
            self.r_dual[i] += grad;
            self.grad[i] = grad;
            dual = dual.max(self.r_dual[i].amax());
            norm_z = norm_z.max(self.z[i].amax());
        }
        for j in 0..m {
            by += qp.terminal_rhs[j] * self.y_terminal[j];
        }
        self.r_terminal = qp.terminal * self.z[k].fixed_rows::<4>(0) - qp.terminal_rhs;
        for j in m..NX {
            self.r_terminal[j] = 0.0;
        }
        primal = primal.max(self.r_terminal.amax());
        let norm_y = norm_y.max(norm_lambda);

        // With the constant, so that the relative gap is relative to the plan's
        // objective and not to terms that cancel against the constant.
        let pobj = 0.5 * xpx + qx + qp.constant;
        let dobj = -0.5 * xpx - by - hl + qp.constant;
        let gap_abs = (pobj - dobj).abs();
        Measures {
            res_primal: primal / (self.norm_b + norm_z + norm_s).max(1.0),
            res_dual: dual / (self.norm_q + norm_z + norm_y).max(1.0),
            gap_abs,
            gap_rel: gap_abs / pobj.abs().min(dobj.abs()).max(1.0),
            certificate_value: by + hl,
            certificate_residual,
        }
    }
}
