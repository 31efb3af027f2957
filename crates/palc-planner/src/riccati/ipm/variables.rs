//! The primal-dual iterate of the interior point and the Newton direction.
//!
//! The QP of [`StageQp`](crate::qp::StageQp) in the interior point's
//! notation (clarabel's, with the stage structure kept):
//!
//! ```text
//! min ½ xᵀPx + qᵀx   s.t.   A x = b   (X_0, dynamics, terminal; multipliers y),
//!                           G x + s = h,   s >= 0   (inequalities; multipliers λ >= 0),
//! ```
//!
//! where the primal `x = (ux_0, ..., ux_K, σ)` holds the stage variables
//! `ux_i = [X_i; U_i]` of Eqs. (9)-(10) (the last control unused) and the soft-bound
//! slacks `σ`, and the multipliers `y = (y_initial, y_dynamics, y_terminal)` are those
//! of Eq. (20), of Eqs. (11)-(14) and of Eq. (21). The letter `z` is not used: the
//! backends' common result calls the multipliers `z` (clarabel's name).

use nalgebra::{Vector4, Vector6};

use crate::qp::{flat, flat_mut};

/// One primal-dual iterate `(x, s, y, λ)`.
#[derive(Debug, Default, Clone)]
pub(crate) struct Variables {
    /// Stage variables `[X_i; U_i]`, `i = 0..=K` (the last control zero).
    pub ux: Vec<Vector6<f64>>,
    /// Soft-bound slacks `σ` (one per softly bounded step).
    pub sigma: Vec<f64>,
    /// Multipliers of the initial rows `X_0 = x̂_0` (Eq. 20).
    pub y_initial: Vector4<f64>,
    /// Multipliers of the dynamics rows of steps `0..K` (Eqs. 11-14).
    pub y_dynamics: Vec<Vector4<f64>>,
    /// Multipliers of the terminal rows (Eq. 21; entries `0..m`).
    pub y_terminal: Vector4<f64>,
    /// Slacks `s >= 0` of the inequality rows (Eqs. 22-23).
    pub s: Vec<f64>,
    /// Multipliers `λ >= 0` of the inequality rows.
    pub lambda: Vec<f64>,
}

impl Variables {
    /// Whether the buffers have the sizes of a horizon `k` with `n_slack` slacks and
    /// `m_in` inequality rows.
    pub fn sized(&self, k: usize, n_slack: usize, m_in: usize) -> bool {
        self.ux.len() == k + 1
            && self.y_dynamics.len() == k
            && self.sigma.len() == n_slack
            && self.s.len() == m_in
            && self.lambda.len() == m_in
    }

    /// Sizes the buffers (allocating only when a size changes; see [`resize_keep`]).
    pub fn resize(&mut self, k: usize, n_slack: usize, m_in: usize) {
        resize_keep(&mut self.ux, k + 1, Vector6::zeros());
        resize_keep(&mut self.y_dynamics, k, Vector4::zeros());
        resize_keep(&mut self.sigma, n_slack, 0.0);
        resize_keep(&mut self.s, m_in, 0.0);
        resize_keep(&mut self.lambda, m_in, 0.0);
    }

    /// Sets every entry to zero.
    pub fn zero(&mut self) {
        self.ux.fill(Vector6::zeros());
        self.y_dynamics.fill(Vector4::zeros());
        self.sigma.fill(0.0);
        self.s.fill(0.0);
        self.lambda.fill(0.0);
        self.y_initial = Vector4::zeros();
        self.y_terminal = Vector4::zeros();
    }

    /// Copies `other` into `self` (the same sizes; no allocation).
    pub fn copy_from(&mut self, other: &Self) {
        self.ux.copy_from_slice(&other.ux);
        self.sigma.copy_from_slice(&other.sigma);
        self.y_initial = other.y_initial;
        self.y_dynamics.copy_from_slice(&other.y_dynamics);
        self.y_terminal = other.y_terminal;
        self.s.copy_from_slice(&other.s);
        self.lambda.copy_from_slice(&other.lambda);
    }

    /// `(x, s, λ) += α (Δx, Δs, Δλ)` and `y += α (y⁺ - y)`.
    pub fn take_step(&mut self, d: &Direction, alpha: f64) {
        // On the flattened entries: one loop the compiler vectorizes instead of one
        // small-vector operation per stage (a third of this step's instructions).
        let axpy = |x: &mut [f64], dx: &[f64]| {
            for (x, dx) in x.iter_mut().zip(dx) {
                *x += alpha * dx;
            }
        };
        axpy(flat_mut(&mut self.ux), flat(&d.ux));
        axpy(&mut self.sigma, &d.sigma);
        axpy(&mut self.s, &d.s);
        axpy(&mut self.lambda, &d.lambda);
        self.y_initial += alpha * (d.y_initial - self.y_initial);
        let y_new: &[f64] = bytemuck::cast_slice(&d.y_dynamics);
        for (y, y_new) in bytemuck::cast_slice_mut::<_, f64>(&mut self.y_dynamics)
            .iter_mut()
            .zip(y_new)
        {
            *y += alpha * (y_new - *y);
        }
        self.y_terminal += alpha * (d.y_terminal - self.y_terminal);
    }

    /// `(s + α Δs)ᵀ(λ + α Δλ) / m` after a step `α` along `d`.
    pub fn mean_complementarity_after(&self, d: &Direction, alpha: f64) -> f64 {
        let n = self.s.len();
        let (s, lambda, ds, d_lambda) =
            (&self.s[..n], &self.lambda[..n], &d.s[..n], &d.lambda[..n]);
        let mut sum = 0.0;
        for j in 0..n {
            sum += (s[j] + alpha * ds[j]) * (lambda[j] + alpha * d_lambda[j]);
        }
        sum / n as f64
    }
}

/// The solution of one Newton system: the primal and inequality steps
/// `(Δx, Δs, Δλ)`, and the equality multipliers `y⁺` themselves (the Riccati solve
/// returns the multipliers of the linearized problem, not their change).
#[derive(Debug, Default, Clone)]
pub(crate) struct Direction {
    /// `Δux_i`, `i = 0..=K`.
    pub ux: Vec<Vector6<f64>>,
    /// `Δσ`.
    pub sigma: Vec<f64>,
    /// `Δs`.
    pub s: Vec<f64>,
    /// `Δλ`.
    pub lambda: Vec<f64>,
    /// `y⁺` of the initial rows.
    pub y_initial: Vector4<f64>,
    /// `y⁺` of the dynamics rows.
    pub y_dynamics: Vec<Vector4<f64>>,
    /// `y⁺` of the terminal rows.
    pub y_terminal: Vector4<f64>,
}

impl Direction {
    /// Sizes the buffers like [`Variables::resize`].
    pub fn resize(&mut self, k: usize, n_slack: usize, m_in: usize) {
        resize_keep(&mut self.ux, k + 1, Vector6::zeros());
        resize_keep(&mut self.y_dynamics, k, Vector4::zeros());
        resize_keep(&mut self.sigma, n_slack, 0.0);
        resize_keep(&mut self.s, m_in, 0.0);
        resize_keep(&mut self.lambda, m_in, 0.0);
    }
}

/// `v` with `n` entries: left as they are when it has `n` already, else all `value`
/// (allocates only when `n` grows past the capacity).
///
/// Within a solve, every buffer of the interior point is written before it is read
/// (the iterate of a cold start is zeroed by [`Variables::zero`]; the constant zero
/// offsets of the refinement are never written), so the entries a reused planner
/// keeps from its last solve are never used. Zeroing them anyway cost 6 % of the
/// instructions of a warm re-plan (K = 120) and 3 % of a cold plan; the plans are
/// bit for bit the same without it (`palc-eval/tests/golden.rs`, `tests/replan.rs`).
pub(super) fn resize_keep<T: Copy>(v: &mut Vec<T>, n: usize, value: T) {
    if v.len() != n {
        v.clear();
        v.resize(n, value);
    }
}
