//! The residuals of an iterate and the measures the stopping rule reads.
//!
//! For the QP of [`variables`](super::variables), the residuals of the KKT conditions
//! at `(x, s, y, λ)` are
//!
//! ```text
//! r_dual = P x + q + Aᵀ y + Gᵀ λ        (stationarity, per stage and per slack σ),
//! r_eq   = A x - b                     (X_0 of Eq. 20, dynamics of Eqs. 11-14, Eq. 21),
//! r_in   = G x + s - h                 (Eqs. 22-23),
//! ```
//!
//! kept in stage form (the dynamics residual negated as the offset `f_i` of the
//! Riccati right-hand side). One pass over the rows, one over the slacks and one over
//! the stages also give the objectives, the norms of clarabel's relative measures and
//! the primal infeasibility certificate `(bᵀy + hᵀλ, ‖Aᵀy + Gᵀλ‖∞)`.

use nalgebra::{SVector, Vector4, Vector6};

use super::head;
use super::info::Measures;
use super::variables::{Variables, resize_keep};
use crate::qp::{NX, StageQp, flat, flat_mut, hessian_mul};

/// The residuals of the current iterate, in stage form.
#[derive(Debug, Default)]
pub(crate) struct Residuals {
    /// `P x + q` per stage (the gradient of the objective).
    pub grad: Vec<Vector6<f64>>,
    /// `r_dual` per stage.
    pub dual: Vec<Vector6<f64>>,
    /// `r_dual` per soft-bound slack.
    pub dual_sigma: Vec<f64>,
    /// `X_0 - x̂_0`.
    pub initial: Vector4<f64>,
    /// `E X_K - e` (entries `0..m`, the others zero).
    pub terminal: Vector4<f64>,
    /// `r_in` per inequality row.
    pub inequality: Vec<f64>,
    /// `-(X_{i+1} - A_i X_i - B_i U_i - c_i)` per step: the offsets `f_i` of the Riccati
    /// right-hand side that restore the dynamics in one full Newton step.
    pub offsets: Vec<Vector4<f64>>,
    /// `max(‖x̂_0‖∞, ‖c‖∞, ‖e‖∞, ‖h‖∞)`: the data norm of the primal measure.
    norm_b: f64,
    /// `‖q‖∞` (stages and slacks): the data norm of the dual measure.
    norm_q: f64,
}

impl Residuals {
    /// Sizes the buffers for `qp` and computes its data norms.
    pub fn reset(&mut self, qp: &StageQp) {
        let (k, n_slack, m_in) = (qp.k, qp.slack_cost.len(), qp.inequalities.len());
        resize_keep(&mut self.grad, k + 1, Vector6::zeros());
        resize_keep(&mut self.dual, k + 1, Vector6::zeros());
        resize_keep(&mut self.dual_sigma, n_slack, 0.0);
        resize_keep(&mut self.inequality, m_in, 0.0);
        resize_keep(&mut self.offsets, k, Vector4::zeros());
        self.initial = Vector4::zeros();
        self.terminal = Vector4::zeros();
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

    /// The parts of the residuals at the origin (`x`, `s`, `y`, `λ` all zero) that
    /// the Newton right-hand side reads (`grad`, `offsets`, `initial`, `terminal`,
    /// `inequality`), computed with the same operations as [`compute`](Self::compute)
    /// (bit for bit the same values) but without its passes over the multipliers and
    /// its measures: Mehrotra's start needs only these, and the full pass was 3 % of
    /// a cold plan's instructions (K = 120). `dual` and `dual_sigma` are left as they
    /// are: nothing reads them before the first [`compute`](Self::compute).
    pub fn compute_at_origin(&mut self, qp: &StageQp) {
        let k = qp.k;
        let zero4 = Vector4::zeros();
        let zero6 = Vector6::zeros();
        for (r, row) in self.inequality.iter_mut().zip(&qp.inequalities) {
            *r = 0.0 + 0.0 - row.h;
        }
        self.initial = zero4 - qp.x0;
        for i in 0..k {
            let d = &qp.dynamics[i];
            let r =
                zero4 - d.sparse.a_mul(&zero4) - d.sparse.b_mul(&nalgebra::Vector2::zeros()) - d.c;
            self.offsets[i] = -r;
        }
        for i in 0..=k {
            self.grad[i] = hessian_mul(&qp.hessian[i], &zero6) + qp.linear[i];
        }
        self.terminal = qp.terminal * zero4 - qp.terminal_rhs;
        for j in qp.terminal_rows..NX {
            self.terminal[j] = 0.0;
        }
    }

    /// The residuals of `v` and its convergence measures.
    pub fn compute(&mut self, qp: &StageQp, v: &Variables) -> Measures {
        let k = qp.k;
        let m = qp.terminal_rows;
        // Pass over the inequalities: Gᵀλ into r_dual, r_in, hᵀλ, norms.
        self.dual.fill(Vector6::zeros());
        self.dual_sigma.fill(0.0);
        let (mut hl, mut norm_s, mut norm_lambda, mut norm_r_in) = (0.0, 0.0_f64, 0.0_f64, 0.0_f64);
        {
            let n = qp.inequalities.len();
            let (lambda, s, r_in) = (&v.lambda[..n], &v.s[..n], &mut self.inequality[..n]);
            let (dual, dual_sigma) = (flat_mut(&mut self.dual), &mut self.dual_sigma);
            let ux = flat(&v.ux);
            for (j, row) in qp.inequalities.iter().enumerate() {
                let (l, s) = (lambda[j], s[j]);
                if let Some(x) = row.var_in(dual) {
                    *x += row.coef * l;
                }
                if let Some(x) = row.slack_in(dual_sigma) {
                    *x += row.slack_coef * l;
                }
                let gx = row.times(ux, &v.sigma);
                let r = gx + s - row.h;
                r_in[j] = r;
                hl += row.h * l;
                norm_s = max(norm_s, s.abs());
                norm_lambda = max(norm_lambda, l.abs());
                norm_r_in = max(norm_r_in, r.abs());
            }
        }
        // Pass over the slacks.
        let (mut qx, mut certificate_residual, mut dual, mut norm_x) =
            (0.0, 0.0_f64, 0.0_f64, 0.0_f64);
        for j in 0..v.sigma.len() {
            certificate_residual = max(certificate_residual, self.dual_sigma[j].abs());
            qx += qp.slack_cost[j] * v.sigma[j];
            self.dual_sigma[j] += qp.slack_cost[j];
            dual = max(dual, self.dual_sigma[j].abs());
            norm_x = max(norm_x, v.sigma[j].abs());
        }
        // Pass over the stages: Aᵀy, Px, the dynamics residuals, bᵀy, objectives, norms.
        self.initial = v.ux[0].fixed_rows::<4>(0) - qp.x0;
        let mut by = qp.x0.dot(&v.y_initial);
        let mut norm_y = max(amax(&v.y_initial), amax(&v.y_terminal));
        let mut primal = max(amax(&self.initial), norm_r_in);
        let mut xpx = 0.0;
        // Slices bound once to their lengths (`K + 1` stages, `K` steps): no bounds
        // checks in the loop, which were a sixth of this pass.
        let (ux, hessian, linear) = (&v.ux[..=k], &qp.hessian[..=k], &qp.linear[..=k]);
        let (dual_rows, grad) = (&mut self.dual[..=k], &mut self.grad[..=k]);
        let (y_dynamics, dynamics, offsets) = (
            &v.y_dynamics[..k],
            &qp.dynamics[..k],
            &mut self.offsets[..k],
        );
        for i in 0..=k {
            let incoming = if i == 0 {
                v.y_initial
            } else {
                y_dynamics[i - 1]
            };
            let dual_i = &mut dual_rows[i];
            head(dual_i, &incoming);
            if i < k {
                let d = &dynamics[i];
                let y = y_dynamics[i];
                head(dual_i, &-d.sparse.a_tr_mul(&y));
                let mut tail = dual_i.fixed_rows_mut::<2>(4);
                tail -= d.sparse.b_tr_mul(&y);
                by += d.c.dot(&y);
                norm_y = max(norm_y, amax(&y));
                let x = ux[i].fixed_rows::<4>(0).into_owned();
                let u = ux[i].fixed_rows::<2>(4).into_owned();
                let r =
                    ux[i + 1].fixed_rows::<4>(0) - d.sparse.a_mul(&x) - d.sparse.b_mul(&u) - d.c;
                primal = max(primal, amax(&r));
                offsets[i] = -r;
            } else {
                head(dual_i, &qp.terminal.tr_mul(&v.y_terminal));
            }
            certificate_residual = max(certificate_residual, amax(dual_i));
            let px = hessian_mul(&hessian[i], &ux[i]);
            xpx += ux[i].dot(&px);
            qx += linear[i].dot(&ux[i]);
            let g = px + linear[i];
            *dual_i += g;
            grad[i] = g;
            dual = max(dual, amax(dual_i));
            norm_x = max(norm_x, amax(&ux[i]));
        }
        for j in 0..m {
            by += qp.terminal_rhs[j] * v.y_terminal[j];
        }
        self.terminal = qp.terminal * v.ux[k].fixed_rows::<4>(0) - qp.terminal_rhs;
        for j in m..NX {
            self.terminal[j] = 0.0;
        }
        primal = max(primal, amax(&self.terminal));
        let norm_y = max(norm_y, norm_lambda);

        // With the constant, so that the relative gap is relative to the plan's
        // objective and not to terms that cancel against the constant.
        let pobj = 0.5 * xpx + qx + qp.constant;
        let dobj = -0.5 * xpx - by - hl + qp.constant;
        let gap_abs = (pobj - dobj).abs();
        Measures {
            res_primal: primal / (self.norm_b + norm_x + norm_s).max(1.0),
            res_dual: dual / (self.norm_q + norm_x + norm_y).max(1.0),
            gap_abs,
            gap_rel: gap_abs / pobj.abs().min(dobj.abs()).max(1.0),
            certificate_value: by + hl,
            certificate_residual,
            objective: pobj,
        }
    }
}

/// `‖v‖∞`.
fn norm_inf<'a>(values: impl IntoIterator<Item = &'a f64>) -> f64 {
    values.into_iter().fold(0.0_f64, |m, v| m.max(v.abs()))
}

/// `max(a, b)` for the running norms: like `f64::max` it ignores a NaN `b`, but in one
/// comparison instead of `f64::max`'s NaN handling, which made the norms a third of
/// this pass (the accumulators start at zero and never hold a NaN).
#[inline(always)]
fn max(a: f64, b: f64) -> f64 {
    if b > a { b } else { a }
}

/// `‖v‖∞` of a stage vector, with [`max`].
#[inline(always)]
fn amax<const R: usize>(v: &SVector<f64, R>) -> f64 {
    v.iter().fold(0.0, |m, x| max(m, x.abs()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{
        LateralBound, LateralBoundsMode, PlannerConfig, Position, Problem, State, Terminal, Weights,
    };

    /// Mehrotra's start reads the same residuals from the pass at the origin as from
    /// the full pass at a zero iterate, bit for bit (signs of zero included), with hard
    /// and soft bounds.
    #[test]
    fn the_residuals_at_the_origin_are_those_of_the_full_pass_at_zero() {
        for mode in [
            LateralBoundsMode::Hard,
            LateralBoundsMode::Soft { weight: 100.0 },
        ] {
            let config = PlannerConfig {
                horizon: 12,
                lateral_bounds_mode: mode,
                ..PlannerConfig::default()
            };
            let k = config.horizon;
            let speed = 20.0;
            let problem = Problem {
                initial: State {
                    s: 100.0,
                    v: speed,
                    l: 0.4,
                    phi: 0.01,
                },
                reference_speed: vec![speed; k],
                curvature: 0.001,
                weights: Weights::constant(
                    k,
                    [0.1, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 10.0, 1e-3, 1e-3],
                ),
                preceding: vec![Position { s: 130.0, l: 0.0 }; k],
                adjacent: vec![Position { s: 90.0, l: 3.5 }; k],
                terminal: Terminal {
                    s: None,
                    v: speed,
                    l: 3.5,
                },
                lateral_bounds: vec![Some(LateralBound::new(-1.75, 5.25)); k + 1],
                tracking: None,
            };
            let mut qp = StageQp::default();
            qp.assemble(&config, &problem);
            let mut v = Variables::default();
            v.resize(k, qp.slack_cost.len(), qp.inequalities.len());
            v.zero();
            let (mut full, mut origin) = (Residuals::default(), Residuals::default());
            full.reset(&qp);
            origin.reset(&qp);
            full.compute(&qp, &v);
            origin.compute_at_origin(&qp);
            let bits = |x: &[f64]| x.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            let offsets = |r: &Residuals| {
                r.offsets
                    .iter()
                    .flat_map(|o| bits(o.as_slice()))
                    .collect::<Vec<_>>()
            };
            assert_eq!(bits(flat(&full.grad)), bits(flat(&origin.grad)), "{mode:?}");
            assert_eq!(bits(&full.inequality), bits(&origin.inequality), "{mode:?}");
            assert_eq!(offsets(&full), offsets(&origin), "{mode:?}");
            assert_eq!(
                bits(full.initial.as_slice()),
                bits(origin.initial.as_slice())
            );
            assert_eq!(
                bits(full.terminal.as_slice()),
                bits(origin.terminal.as_slice())
            );
        }
    }
}
