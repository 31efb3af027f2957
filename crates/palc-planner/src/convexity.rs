//! Convexity of the learned cost: each stage's Hessian block must be PSD.

use crate::{PlanError, Weights, feature};

/// Checks that every stage's Hessian block `[[Q_i, F_i/2], [F_iᵀ/2, R_i]]` of
/// Eqs. (16)-(19) is positive semidefinite, so that the QP is convex.
///
/// Over `(s, l, φ, δ)` the block is an arrow matrix: diagonal
/// `(w9 + w10, w1 + w9 + w10, w3, w8)` with couplings `w7/2, w5/2, w6/2` to `δ`
/// (`v` and `a` do not appear). It is PSD iff the three state diagonals are `>= 0`, a
/// coupling vanishes wherever its diagonal does, and the Schur complement
/// `w8 - Σ c_j² / d_j >= 0`. The acceleration penalty and a tracking term only add
/// PSD terms; this check deliberately ignores them so that the weights alone are convex
/// (the set the aggregator keeps `w` in). Comparisons use a relative tolerance of
/// `1e-10` on the block's largest entry.
pub fn check_convexity(weights: &Weights) -> Result<(), PlanError> {
    for (column, w) in weights.columns().iter().enumerate() {
        let stage = column + 1;
        let fail = |block: &'static str, value: f64| PlanError::NonConvex {
            stage,
            column,
            block,
            value,
        };
        for (j, &x) in w.iter().enumerate() {
            if !x.is_finite() {
                return Err(PlanError::NonFinite {
                    field: format!("weights[{column}][{j}]"),
                    value: x,
                });
            }
        }
        let dist = w[feature::DIST_PRECEDING] + w[feature::DIST_ADJACENT];
        let diagonals = [
            (
                dist,
                w[feature::S_DELTA] / 2.0,
                "Q[s,s] = w9 + w10",
                "s-delta coupling w7 / 2 with Q[s,s] = 0",
            ),
            (
                w[feature::L_SQUARED] + dist,
                w[feature::L_DELTA] / 2.0,
                "Q[l,l] = w1 + w9 + w10",
                "l-delta coupling w5 / 2 with Q[l,l] = 0",
            ),
            (
                w[feature::PHI_SQUARED],
                w[feature::PHI_DELTA] / 2.0,
                "Q[phi,phi] = w3",
                "phi-delta coupling w6 / 2 with Q[phi,phi] = 0",
            ),
        ];
        let r = w[feature::DELTA_SQUARED];
        let scale = diagonals
            .iter()
            .flat_map(|&(d, c, _, _)| [d.abs(), c.abs()])
            .fold(r.abs(), f64::max);
        let tol = 1e-10 * scale;
        let mut schur = r;
        for &(d, c, diag_name, coupling_name) in &diagonals {
            if d < -tol {
                return Err(fail(diag_name, d));
            }
            if d <= tol {
                if c.abs() > tol {
                    return Err(fail(coupling_name, c));
                }
            } else {
                schur -= c * c / d;
            }
        }
        if r < -tol {
            return Err(fail("R[delta,delta] = w8", r));
        }
        if schur < -tol {
            return Err(fail(
                "Schur complement w8 - (w7²/4)/(w9+w10) - (w5²/4)/(w1+w9+w10) - (w6²/4)/w3",
                schur,
            ));
        }
    }
    Ok(())
}
