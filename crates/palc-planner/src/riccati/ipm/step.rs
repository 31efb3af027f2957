//! One Mehrotra predictor-corrector iteration and its step length.
//!
//! The predictor (affine) direction solves the Newton system with `r_c = s ∘ λ`; its
//! longest step `α_aff` to the boundary of `s, λ >= 0` gives
//! `μ_aff = (s + α_aff Δs)ᵀ(λ + α_aff Δλ) / m` and the centring `σ = (μ_aff / μ)³`. The
//! corrector solves the same factored system with
//! `r_c = s ∘ λ + Δs_aff ∘ Δλ_aff - σ μ`, and the iterate moves by a fraction of the
//! step to the boundary (the line search of an interior point: the step is the largest
//! that keeps `s` and `λ` positive, shortened so that they stay off the boundary).

use super::super::params::{CENTERING_EXPONENT, MAX_STEP_FRACTION, MU_GROWTH, STEP_FRACTION};
use super::super::recursion::FactorError;
use super::Ipm;
use crate::qp::StageQp;

/// `Δλ_j = -(r_c + λ Δs) / s` of one row, and the step bound `α` tightened so that
/// `s + α Δs >= 0` and `λ + α Δλ >= 0` (a division only where the bound tightens,
/// rare once `α` has settled).
#[inline(always)]
pub(super) fn dual_step(s: f64, lambda: f64, rc: f64, inv_s: f64, ds: f64, alpha: &mut f64) -> f64 {
    let dl = -(rc + lambda * ds) * inv_s;
    if s + *alpha * ds < 0.0 {
        *alpha = -s / ds;
    }
    if lambda + *alpha * dl < 0.0 {
        *alpha = -lambda / dl;
    }
    dl
}

impl Ipm {
    /// One predictor-corrector iteration; returns the step length.
    /// `refine`: one step of iterative refinement after each corrector solve.
    /// `feasible`: the residuals of the iterate meet the stopping tolerance.
    pub(super) fn iterate(
        &mut self,
        qp: &StageQp,
        refine: bool,
        feasible: bool,
    ) -> Result<f64, FactorError> {
        let Self {
            v,
            d,
            kkt,
            residuals: r,
            ..
        } = self;
        let n = v.s.len();
        let m_in = n as f64;
        // Predictor: r_c = s∘λ, so ξ = λ + W r_in - r_c / s = W r_in.
        let mu = {
            let (s, lambda, r_in) = (&v.s[..n], &v.lambda[..n], &r.inequality[..n]);
            let (inv_s, w, rc, xi) = (
                &mut kkt.inv_s[..n],
                &mut kkt.w[..n],
                &mut kkt.rc[..n],
                &mut kkt.xi[..n],
            );
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
        kkt.factor(qp)?;
        // The predictor's step needs only Δx (for Δs, Δλ): no multipliers.
        let alpha = kkt.solve(qp, v, r, d, false);
        let centering = {
            let (s, lambda, r_in) = (&v.s[..n], &v.lambda[..n], &r.inequality[..n]);
            let (inv_s, w) = (&kkt.inv_s[..n], &kkt.w[..n]);
            let (ds, d_lambda) = (&d.s[..n], &d.lambda[..n]);
            let (rc, xi) = (&mut kkt.rc[..n], &mut kkt.xi[..n]);
            let mut mu_affine = 0.0;
            for j in 0..n {
                mu_affine += (s[j] + alpha * ds[j]) * (lambda[j] + alpha * d_lambda[j]);
            }
            let centering = (mu_affine / m_in / mu)
                .clamp(0.0, 1.0)
                .powi(CENTERING_EXPONENT);
            // Corrector with centring, from the affine step.
            let shift = centering * mu;
            for j in 0..n {
                rc[j] = s[j] * lambda[j] + ds[j] * d_lambda[j] - shift;
                xi[j] = lambda[j] + w[j] * r_in[j] - rc[j] * inv_s[j];
            }
            centering
        };
        let mut alpha = kkt.solve(qp, v, r, d, true);
        if refine {
            kkt.refine(qp, v, r, d);
            alpha = kkt.dual_step_to_boundary(v, d);
        }
        // Bolder steps when the predictor was good (little centring needed).
        let fraction = (1.0 - centering).clamp(STEP_FRACTION, MAX_STEP_FRACTION);
        let mut alpha = (fraction * alpha).min(1.0);
        if feasible && v.mean_complementarity_after(d, alpha) > MU_GROWTH * mu {
            // The second-order term misled the step: centre only (the last Δs, Δλ are
            // the corrector's; r_c is rebuilt from s∘λ).
            let shift = centering * mu;
            for j in 0..n {
                kkt.rc[j] = v.s[j] * v.lambda[j] - shift;
                kkt.xi[j] = v.lambda[j] + kkt.w[j] * r.inequality[j] - kkt.rc[j] * kkt.inv_s[j];
            }
            alpha = kkt.solve(qp, v, r, d, true);
            if refine {
                kkt.refine(qp, v, r, d);
                alpha = kkt.dual_step_to_boundary(v, d);
            }
            alpha = (fraction * alpha).min(1.0);
        }
        v.take_step(d, alpha);
        Ok(alpha)
    }
}
