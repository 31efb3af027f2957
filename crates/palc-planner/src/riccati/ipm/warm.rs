//! The warm start of a closed-loop re-plan: the previous solution shifted by one step.
//!
//! In closed loop the next problem is the last one a step `dt` later: the stage `i` of
//! the new problem is the stage `i + 1` of the old one (the same bound pattern, the
//! same weights). The shifted iterate takes, for each new stage, the old stage after
//! it: stage variables `[X_{i+1}; U_{i+1}]` (longitudinal positions relative to the old
//! `X_1`, as the new problem's are relative to its own initial state), the
//! multipliers of the dynamics rows of Eqs. (11)-(14) (the old `y_0` becomes the
//! multiplier of the new initial rows, Eq. 20: both are the incoming multiplier of the
//! same state), and the `σ` and `λ` of the same bound one step later. The last stage
//! repeats the old last control and propagates the dynamics, so that every equality
//! row but the changed initial state holds. The new stage `K - 1` (the old stage `K`)
//! has a stage cost the old one had not; the multipliers of the last dynamics rows and
//! of the terminal rows are set from the stationarity of the last two stages' states,
//! which leaves the dual residual on the last controls only (without it, the shifted
//! multipliers left a dual residual of 4e-2 there and the re-plan took one more
//! iteration). The inequality slacks are then
//! `s = h - G x` (zero inequality residual), and each pair `(s_j, λ_j)` is moved off
//! the boundary to `s_j λ_j >= μ` with `m μ` a small fraction of the objective
//! ([`WARM_GAP`]): the interior point needs a central iterate, and an exact
//! solution, with `s_j λ_j` at the tolerance, is not one.

use nalgebra::Vector6;

use super::super::params::WARM_GAP;
use super::Ipm;
use crate::qp::{Inequality, NX, StageQp, flat};

/// Kinds of inequality rows told apart when shifting: `(local index, sign, kind)`,
/// kind 0 a row on a stage variable only, 1 a row with its soft-bound slack, 2 a row on
/// the slack alone.
const ROW_KINDS: usize = 6 * 2 * 3;

/// The stage of row `row` and the kind of row it is, if it has a stage.
fn stage_and_kind(
    row: &Inequality,
    slack_core: &[Option<(usize, usize)>],
) -> Option<(usize, usize)> {
    let (core, kind, coef) = match (row.core(), row.slack()) {
        (Some(core), None) => (core, 0, row.coef),
        (Some(core), Some(_)) => (core, 1, row.coef),
        (None, Some(j)) => (slack_core.get(j).copied().flatten()?, 2, row.slack_coef),
        (None, None) => return None,
    };
    let (stage, local) = core;
    let sign = usize::from(coef > 0.0);
    Some((stage, (local * 2 + sign) * 3 + kind))
}

impl Ipm {
    /// Builds the warm start for `qp` from the last result, which must be the solution
    /// of the problem one step before `qp` with the same layout; returns `false` (cold
    /// start) when the last run did not solve or had other sizes.
    pub fn prepare_warm_start(&mut self, qp: &StageQp) -> bool {
        let (k, n_slack, m_in) = (qp.k, qp.slack_cost.len(), qp.inequalities.len());
        let Some(objective) = self.solved_objective else {
            return false;
        };
        if k == 0 || m_in == 0 || !self.v.sized(k, n_slack, m_in) {
            return false;
        }
        let (old, w) = (&self.v, &mut self.shifted);
        // Every entry is written below.
        w.resize(k, n_slack, m_in);

        // Stage variables: stage i from old stage i + 1, positions relative to old X_1.
        let origin = old.ux[1][0];
        for i in 0..k {
            w.ux[i] = old.ux[i + 1];
            w.ux[i][0] -= origin;
        }
        w.ux[k - 1][4] = old.ux[k - 1][4];
        w.ux[k - 1][5] = old.ux[k - 1][5];
        w.ux[0].fixed_rows_mut::<NX>(0).copy_from(&qp.x0);
        let last = &qp.dynamics[k - 1];
        let x = w.ux[k - 1].fixed_rows::<NX>(0).into_owned();
        let u = w.ux[k - 1].fixed_rows::<2>(NX).into_owned();
        let x = last.sparse.a_mul(&x) + last.sparse.b_mul(&u) + last.c;
        w.ux[k] = Vector6::new(x[0], x[1], x[2], x[3], 0.0, 0.0);

        // Multipliers of the equality rows.
        w.y_initial = old.y_dynamics[0];
        w.y_dynamics[..k - 1].copy_from_slice(&old.y_dynamics[1..]);
        w.y_dynamics[k - 1] = old.y_dynamics[k - 1];
        w.y_terminal = old.y_terminal;

        // Soft-bound slacks: the slack of the same variable one stage later.
        for j in 0..n_slack {
            let next = match (
                qp.slack_core[j],
                qp.slack_core.get(j + 1).copied().flatten(),
            ) {
                (Some((i, l)), Some(after)) if after == (i + 1, l) => j + 1,
                _ => j,
            };
            w.sigma[j] = old.sigma[next];
        }

        // Inequality multipliers: the row of the same kind one stage later, found by a
        // backward scan (rows of one kind are in stage order).
        let mut following = [None::<(usize, usize)>; ROW_KINDS];
        for j in (0..m_in).rev() {
            let row = &qp.inequalities[j];
            let mut source = j;
            if let Some((stage, kind)) = stage_and_kind(row, &qp.slack_core) {
                if let Some((next_stage, next_row)) = following[kind] {
                    if next_stage == stage + 1 {
                        source = next_row;
                    }
                }
                following[kind] = Some((stage, j));
            }
            w.lambda[j] = old.lambda[source];
        }

        // Slacks with zero inequality residual, then off the boundary.
        let mu = WARM_GAP * (1.0 + objective.abs()) / m_in as f64;
        let floor = mu.sqrt();
        for (j, row) in qp.inequalities.iter().enumerate() {
            let mut s = (row.h - row.times(flat(&w.ux), &w.sigma)).max(0.0);
            let mut l = w.lambda[j].max(0.0);
            if s >= l {
                s = s.max(floor);
                l = l.max(mu / s);
            } else {
                l = l.max(floor);
                s = s.max(mu / l);
            }
            w.s[j] = s;
            w.lambda[j] = l;
        }
        // The last stage: the old stage K becomes stage K - 1 and gains the stage cost
        // the old one did not have. Its state rows of the stationarity condition fix the
        // multiplier of the last dynamics rows, `A_{K-1}ᵀ y_{K-1} = y_{K-2} + ∇_x ℓ_{K-1}
        // + (Gᵀλ)_{K-1}`, and stage K's then fix the terminal multiplier
        // `Eᵀν = -(y_{K-1} + ∇_x ℓ_K + (Gᵀλ)_K)`: the dual residual is left on the
        // controls of stage K - 1 and on the rows of X_K that no terminal row fixes.
        let mut gl = [Vector6::zeros(); 2];
        for (row, &l) in qp.inequalities.iter().zip(&w.lambda) {
            if let Some((i, c)) = row.core() {
                if i + 1 >= k {
                    gl[i + 1 - k][c] += row.coef * l;
                }
            }
        }
        let state_rows = |i: usize, g: &Vector6<f64>| {
            (qp.hessian[i] * w.ux[i] + qp.linear[i] + g)
                .fixed_rows::<NX>(0)
                .into_owned()
        };
        let incoming = if k >= 2 {
            w.y_dynamics[k - 2]
        } else {
            w.y_initial
        };
        let (a, _) = qp.dynamics[k - 1].sparse.dense();
        if let Some(y) = a
            .transpose()
            .try_inverse()
            .map(|inv| inv * (incoming + state_rows(k - 1, &gl[0])))
        {
            w.y_dynamics[k - 1] = y;
            let rest = -(y + state_rows(k, &gl[1]));
            for j in 0..qp.terminal_rows {
                if let Some(c) = (0..NX).find(|&c| qp.terminal[(j, c)] != 0.0) {
                    w.y_terminal[j] = rest[c] / qp.terminal[(j, c)];
                }
            }
        }
        // A non-finite previous solution (it would have failed its own stopping rule)
        // is never a start.
        w.ux.iter().all(|x| x.iter().all(|v| v.is_finite()))
            && w.s
                .iter()
                .chain(&w.lambda)
                .chain(&w.sigma)
                .all(|v| v.is_finite())
    }
}
