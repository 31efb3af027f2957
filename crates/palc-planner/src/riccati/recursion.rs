//! The time-varying Riccati recursion that solves one Newton system of the interior
//! point: the equality-constrained stage QP
//!
//! ```text
//! min Σ_{i<K} ½ [x_i; u_i]ᵀ H_i [x_i; u_i] + g_iᵀ [x_i; u_i] + ½ x_Kᵀ H_K x_K + g_Kᵀ x_K
//! s.t. x_0 = x̂_0,  x_{i+1} = A_i x_i + B_i u_i + f_i,  E x_K = e.
//! ```
//!
//! The terminal rows are dualized with a multiplier `ν` (at most 4 entries): the value
//! function is `V_i(x) = ½ xᵀ P_i x + xᵀ (p_i + Γ_i ν) + ½ νᵀ W_i ν + w_iᵀ ν`, with
//! `P_K = H_K`, `Γ_K = Eᵀ`, `W_K = 0`, `w_K = -e`, and per step (with
//! `R̄ = R + BᵀPB`, `S̄ = Sᵀ + BᵀPA`, `K = -R̄⁻¹S̄`)
//!
//! ```text
//! P_i = Q + AᵀPA + S̄ᵀK,            Γ_i = (A + BK)ᵀ Γ,     W_i = W - (BᵀΓ)ᵀ R̄⁻¹ (BᵀΓ),
//! p_i = q + Aᵀ(Pf + p) + Kᵀ r̄,     w_i = w + Γᵀf + (BᵀΓ)ᵀ k,   r̄ = r + Bᵀ(Pf + p), k = -R̄⁻¹ r̄.
//! ```
//!
//! `ν` maximizes the concave `V_0(x̂_0; ν)`: `-W_0 ν = Γ_0ᵀ x̂_0 + w_0`. The forward pass
//! gives `u_i = K_i x_i + k_i - R̄⁻¹ BᵀΓ_{i+1} ν` and the multipliers of the dynamics
//! rows `y_i = -(P_{i+1} x_{i+1} + p_{i+1} + Γ_{i+1} ν)` (rows written `x_{i+1} - A x - B u
//! = c`), of the initial rows `-(P_0 x̂_0 + p_0 + Γ_0 ν)` and of the terminal rows `ν`.
//!
//! Every block has a fixed size (4 x 4, 4 x 2, 2 x 2); all buffers are sized by
//! [`Riccati::resize`], so [`Riccati::factor`] and [`Riccati::solve`] never allocate.

use nalgebra::{Matrix2, Matrix2x4, Matrix4, Matrix6, SMatrix, SVector, Vector2, Vector4, Vector6};

use super::params::{
    CONTROL_REGULARIZATION, CONTROL_REGULARIZATION_RELATIVE, TERMINAL_FLOOR, TERMINAL_REFINEMENTS,
    TERMINAL_REGULARIZATION, TERMINAL_TOLERANCE,
};
use crate::dynamics::Dynamics;
use crate::qp::NX;

/// The terminal rows of every lane change: `v`, `l` and `φ` (Eq. 21; `s` only when
/// the problem fixes it): `Γ`'s products are specialized to three columns, a fifth
/// of the backward pass's arithmetic saved over four.
const TERMINAL_COLUMNS_USUAL: usize = 3;

/// Why a factorization failed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum FactorError {
    /// `R̄` of a step is not positive definite, even with every `P` projected onto the
    /// semidefinite cone (non-convex or non-finite data).
    ControlBlock(usize),
    /// The terminal Schur complement `-W_0` is not positive definite even after
    /// regularization (non-finite data).
    Terminal,
}

/// The right-hand side of one Newton system.
pub(crate) struct Rhs<'a> {
    /// `g_i` (`K + 1`).
    pub linear: &'a [Vector6<f64>],
    /// `f_i` (`K`).
    pub offsets: &'a [Vector4<f64>],
    /// `x̂_0`.
    pub initial: Vector4<f64>,
    /// `e` (entries `0..m`).
    pub terminal: Vector4<f64>,
}

/// The solution of one Newton system.
pub(crate) struct Step<'a> {
    /// `[x_i; u_i]` (`K + 1`, the last control zero).
    pub ux: &'a mut [Vector6<f64>],
    /// Multipliers of the dynamics rows (`K`).
    pub y_dynamics: &'a mut [Vector4<f64>],
    /// Multipliers of the initial rows.
    pub y_initial: &'a mut Vector4<f64>,
    /// Multipliers of the terminal rows (entries `0..m`).
    pub y_terminal: &'a mut Vector4<f64>,
    /// Whether to compute the multipliers of the dynamics and initial rows; without
    /// them (the predictor, which needs only the primal step) the forward pass does
    /// about half its work, and `y_dynamics`, `y_initial` keep stale values.
    pub multipliers: bool,
}

/// Factorization and solve buffers for a horizon `K`.
#[derive(Debug, Default)]
pub(crate) struct Riccati {
    k: usize,
    m: usize,
    p: Vec<Matrix4<f64>>,
    gain: Vec<Matrix2x4<f64>>,
    r_inv: Vec<Matrix2<f64>>,
    gamma: Vec<Matrix4<f64>>,
    bt_gamma: Vec<Matrix2x4<f64>>,
    neg_w0_inv: Matrix4<f64>,
    terminal: Matrix4<f64>,
    p_vec: Vec<Vector4<f64>>,
    k_vec: Vec<Vector2<f64>>,
}

impl Riccati {
    /// Sizes the buffers for horizon `k` (the only allocation).
    pub fn resize(&mut self, k: usize) {
        self.k = k;
        self.p.resize(k + 1, Matrix4::zeros());
        self.gain.resize(k, Matrix2x4::zeros());
        self.r_inv.resize(k, Matrix2::zeros());
        self.gamma.resize(k + 1, Matrix4::zeros());
        self.bt_gamma.resize(k, Matrix2x4::zeros());
        self.p_vec.resize(k + 1, Vector4::zeros());
        self.k_vec.resize(k, Vector2::zeros());
    }

    /// Backward pass over the Hessian blocks `h + diag(d)` (`K + 1`), dynamics and the
    /// `m` terminal rows `terminal` (rows `0..m` used).
    ///
    /// If a control block comes out not positive definite, the pass is repeated with
    /// every `P_i` projected onto the semidefinite cone (its negative eigenvalues set to
    /// zero), which it is in exact arithmetic: `P_i` is the Hessian of a convex
    /// cost-to-go. Why: once bounds are active with `W = λ / s` of 1e17-1e21 (on an
    /// infeasible problem, whose multipliers grow without bound), `AᵀPA` and
    /// `S̄ᵀR̄⁻¹S̄` are of that order and their difference, of order 1e8, keeps only
    /// about 1e5 of absolute accuracy: it can come out indefinite (issue 12, `P_17` of
    /// a hard-zone problem with a negative determinant), and the next control block
    /// negative. The projection changes the Newton step, not the residuals, which are
    /// always computed exactly; the usual pass is kept first because the projection
    /// (an eigendecomposition per step) is not needed otherwise.
    pub fn factor(
        &mut self,
        h: &[Matrix6<f64>],
        d: &[Vector6<f64>],
        dynamics: &[Dynamics],
        terminal: &Matrix4<f64>,
        m: usize,
    ) -> Result<(), FactorError> {
        let pass = |riccati: &mut Self, semidefinite_p| {
            if m <= TERMINAL_COLUMNS_USUAL {
                riccati.factor_with::<TERMINAL_COLUMNS_USUAL>(
                    h,
                    d,
                    dynamics,
                    terminal,
                    m,
                    semidefinite_p,
                )
            } else {
                riccati.factor_with::<NX>(h, d, dynamics, terminal, m, semidefinite_p)
            }
        };
        match pass(self, false) {
            Err(FactorError::ControlBlock(_)) => pass(self, true),
            result => result,
        }
    }

    /// The backward pass; `semidefinite_p` projects every `P_i` onto the semidefinite
    /// cone. `Γ`, `BᵀΓ` and `W` are computed on their first `M >= m` columns, the
    /// others being zero (`Γ_K = Eᵀ`).
    fn factor_with<const M: usize>(
        &mut self,
        h: &[Matrix6<f64>],
        d: &[Vector6<f64>],
        dynamics: &[Dynamics],
        terminal: &Matrix4<f64>,
        m: usize,
        semidefinite_p: bool,
    ) -> Result<(), FactorError> {
        let k = self.k;
        self.m = m;
        self.terminal = *terminal;
        self.p[k] = h[k].fixed_view::<4, 4>(0, 0).into_owned();
        for j in 0..NX {
            self.p[k][(j, j)] += d[k][j];
        }
        self.gamma[k] = terminal.transpose();
        let mut w = SMatrix::<f64, M, M>::zeros();
        for i in (0..k).rev() {
            let diag = &d[i];
            let d = &dynamics[i].sparse;
            let hi = &h[i];
            let p_next = &self.p[i + 1];
            let pa = d.right_a(p_next);
            // R̄ = R + BᵀPB, symmetric: B has one entry per column.
            let (bv, bphi) = (d.bv, d.bphi);
            let mut r00 = hi[(4, 4)] + bv * bv * p_next[(1, 1)] + diag[4];
            let r01 = hi[(4, 5)] + bv * bphi * p_next[(1, 3)];
            let mut r11 = hi[(5, 5)] + bphi * bphi * p_next[(3, 3)] + diag[5];
            // Each diagonal entry regularized relative to itself: an active steering
            // bound makes `r11` huge, and a regularization relative to it swamped `r00`.
            r00 += CONTROL_REGULARIZATION + CONTROL_REGULARIZATION_RELATIVE * r00.abs();
            r11 += CONTROL_REGULARIZATION + CONTROL_REGULARIZATION_RELATIVE * r11.abs();
            // Positive definite iff the leading entry and the determinant are positive;
            // then the closed-form 2 x 2 inverse.
            let det = r00 * r11 - r01 * r01;
            if !(r00 > 0.0 && det > 0.0) {
                return Err(FactorError::ControlBlock(i));
            }
            let inv_det = 1.0 / det;
            let r_inv = Matrix2::new(r11, -r01, -r01, r00) * inv_det;
            if !r_inv.iter().all(|x| x.is_finite()) {
                return Err(FactorError::ControlBlock(i));
            }
            // S̄ = Sᵀ + BᵀPA (rows a, δ).
            let s_bar = Matrix2x4::from_fn(|c, j| {
                hi[(j, 4 + c)]
                    + if c == 0 {
                        bv * pa[(1, j)]
                    } else {
                        bphi * pa[(3, j)]
                    }
            });
            let gain = mul_2x2(&-r_inv, &s_bar);
            // P = Q + AᵀPA + S̄ᵀK, symmetric in exact arithmetic: built from its upper
            // triangle.
            let apa = d.a_tr_left(&pa);
            let mut p = symmetric(|r, c| hi[(r, c)] + apa[(r, c)] + tr_dot(&s_bar, &gain, r, c));
            for j in 0..NX {
                p[(j, j)] += diag[j];
            }
            if semidefinite_p {
                p = semidefinite(p);
            }
            // Γ_i = (A + BK)ᵀ Γ = AᵀΓ + Kᵀ (BᵀΓ).
            let gamma_next = self.gamma[i + 1].fixed_columns::<M>(0).into_owned();
            let bt_gamma = d.b_tr_left(&gamma_next);
            let at_gamma = d.a_tr_left(&gamma_next);
            let gamma = SMatrix::<f64, NX, M>::from_fn(|r, c| {
                at_gamma[(r, c)] + tr_dot(&gain, &bt_gamma, r, c)
            });
            self.gamma[i].fixed_columns_mut::<M>(0).copy_from(&gamma);
            // W -= (BᵀΓ)ᵀ R̄⁻¹ (BᵀΓ).
            let r_bt_gamma = mul_2x2(&r_inv, &bt_gamma);
            w -= symmetric(|r, c| tr_dot(&bt_gamma, &r_bt_gamma, r, c));
            self.p[i] = p;
            self.gain[i] = gain;
            self.r_inv[i] = r_inv;
            self.bt_gamma[i]
                .fixed_columns_mut::<M>(0)
                .copy_from(&bt_gamma);
        }
        // -W_0 on the m terminal rows; the unused rows get an identity.
        let mut neg_w0 = Matrix4::zeros();
        neg_w0.fixed_view_mut::<M, M>(0, 0).copy_from(&-w);
        let scale = (0..m).fold(0.0_f64, |s, j| s.max(neg_w0[(j, j)].abs()));
        for j in 0..NX {
            if j < m {
                let row = neg_w0[(j, j)].abs().max(TERMINAL_FLOOR * scale);
                neg_w0[(j, j)] += TERMINAL_REGULARIZATION * row + f64::MIN_POSITIVE;
            } else {
                neg_w0[(j, j)] = 1.0;
            }
        }
        let neg_w0 = (neg_w0 + neg_w0.transpose()) * 0.5;
        self.neg_w0_inv = neg_w0
            .cholesky()
            .map(|c| c.inverse())
            .ok_or(FactorError::Terminal)?;
        Ok(())
    }

    /// Solves the Newton system of the last [`factor`](Self::factor) for `rhs`.
    pub fn solve(&mut self, dynamics: &[Dynamics], rhs: &Rhs<'_>, out: Step<'_>) {
        if self.m <= TERMINAL_COLUMNS_USUAL {
            self.solve_with::<TERMINAL_COLUMNS_USUAL>(dynamics, rhs, out);
        } else {
            self.solve_with::<NX>(dynamics, rhs, out);
        }
    }

    /// [`solve`](Self::solve) with `Γ` on its first `M >= m` columns.
    fn solve_with<const M: usize>(
        &mut self,
        dynamics: &[Dynamics],
        rhs: &Rhs<'_>,
        mut out: Step<'_>,
    ) {
        let k = self.k;
        let mut p_next = rhs.linear[k].fixed_rows::<4>(0).into_owned();
        self.p_vec[k] = p_next;
        let mut w: SVector<f64, M> = -rhs.terminal.fixed_rows::<M>(0);
        // Slices of length `K`, bound once: no bounds checks in the loop (`p`, `gamma`
        // start at step 1, the cost-to-go after the step).
        let (p, gamma) = (&self.p[1..=k], &self.gamma[1..=k]);
        let (r_inv, gain, bt_gamma) = (&self.r_inv[..k], &self.gain[..k], &self.bt_gamma[..k]);
        let (dynamics, offsets, linear) = (&dynamics[..k], &rhs.offsets[..k], &rhs.linear[..k]);
        let (p_vec, k_vec) = (&mut self.p_vec[..k], &mut self.k_vec[..k]);
        for i in (0..k).rev() {
            let d = &dynamics[i].sparse;
            let f = &offsets[i];
            let pf = p[i] * f + p_next;
            let r_bar = linear[i].fixed_rows::<2>(4) + d.b_tr_mul(&pf);
            let kv = -(r_inv[i] * r_bar);
            p_next = linear[i].fixed_rows::<4>(0) + d.a_tr_mul(&pf) + gain[i].tr_mul(&r_bar);
            p_vec[i] = p_next;
            w += gamma[i].fixed_columns::<M>(0).tr_mul(f)
                + bt_gamma[i].fixed_columns::<M>(0).tr_mul(&kv);
            k_vec[i] = kv;
        }
        let mut gradient = Vector4::zeros();
        gradient
            .fixed_rows_mut::<M>(0)
            .copy_from(&(self.gamma[0].fixed_columns::<M>(0).tr_mul(&rhs.initial) + w));
        let mut nu = self.neg_w0_inv * gradient;
        for j in self.m..NX {
            nu[j] = 0.0;
        }
        // The terminal residual `E x_K - e` is the gradient `Γ_0ᵀx̂_0 + W_0 ν + w_0` of the
        // dual function in `ν`: once the active bounds make `-W_0` ill-conditioned, a
        // Newton step on it (forward pass only) restores the terminal rows, which the
        // interior point cannot otherwise correct.
        for _ in 0..=TERMINAL_REFINEMENTS {
            if out.multipliers {
                self.forward::<M, true>(dynamics, rhs, &nu, &mut out);
            } else {
                self.forward::<M, false>(dynamics, rhs, &nu, &mut out);
            }
            let x_k = out.ux[self.k].fixed_rows::<4>(0).into_owned();
            let scale = 1.0 + x_k.amax() + rhs.terminal.amax();
            let mut residual = self.terminal * x_k - rhs.terminal;
            for j in self.m..NX {
                residual[j] = 0.0;
            }
            if residual.amax() <= TERMINAL_TOLERANCE * scale {
                break;
            }
            nu += self.neg_w0_inv * residual;
        }
    }

    /// The forward pass for a given `ν`: controls, states and, with `MULTIPLIERS`, the
    /// multipliers.
    fn forward<const M: usize, const MULTIPLIERS: bool>(
        &self,
        dynamics: &[Dynamics],
        rhs: &Rhs<'_>,
        nu: &Vector4<f64>,
        out: &mut Step<'_>,
    ) {
        let k = self.k;
        let mut x = rhs.initial;
        let nu_m = nu.fixed_rows::<M>(0).into_owned();
        if MULTIPLIERS {
            *out.y_initial =
                -(self.p[0] * x + self.p_vec[0] + self.gamma[0].fixed_columns::<M>(0) * nu_m);
        }
        // Slices of length `K`, bound once (`p`, `p_vec`, `gamma` from step 1).
        let (p, p_vec, gamma) = (&self.p[1..=k], &self.p_vec[1..=k], &self.gamma[1..=k]);
        let (gain, k_vec) = (&self.gain[..k], &self.k_vec[..k]);
        let (r_inv, bt_gamma) = (&self.r_inv[..k], &self.bt_gamma[..k]);
        let (dynamics, offsets) = (&dynamics[..k], &rhs.offsets[..k]);
        let (ux, y_dynamics) = (&mut out.ux[..k], &mut out.y_dynamics[..k]);
        for i in 0..k {
            let d = &dynamics[i].sparse;
            let u = gain[i] * x + k_vec[i] - r_inv[i] * (bt_gamma[i].fixed_columns::<M>(0) * nu_m);
            ux[i] = Vector6::new(x[0], x[1], x[2], x[3], u[0], u[1]);
            x = d.a_mul(&x) + d.b_mul(&u) + offsets[i];
            if MULTIPLIERS {
                y_dynamics[i] = -(p[i] * x + p_vec[i] + gamma[i].fixed_columns::<M>(0) * nu_m);
            }
        }
        out.ux[k] = Vector6::new(x[0], x[1], x[2], x[3], 0.0, 0.0);
        *out.y_terminal = *nu;
    }
}

// The products of the backward pass, written out for its fixed sizes: with nalgebra's
// general products and the symmetrization `(P + Pᵀ) / 2` the pass took a fifth more
// instructions (157.6 M against 128.0 M over 300 benchmark plans, callgrind).

/// `(Mᵀ N)[r, c]` for two blocks of two rows.
#[inline(always)]
fn tr_dot<const A: usize, const B: usize>(
    m: &SMatrix<f64, 2, A>,
    n: &SMatrix<f64, 2, B>,
    r: usize,
    c: usize,
) -> f64 {
    m[(0, r)] * n[(0, c)] + m[(1, r)] * n[(1, c)]
}

/// `M N` for a 2 x 2 block and a block of two rows.
#[inline(always)]
fn mul_2x2<const C: usize>(m: &Matrix2<f64>, n: &SMatrix<f64, 2, C>) -> SMatrix<f64, 2, C> {
    SMatrix::<f64, 2, C>::from_fn(|r, c| m[(r, 0)] * n[(0, c)] + m[(r, 1)] * n[(1, c)])
}

/// The symmetric `N x N` matrix whose upper triangle is `entry(r, c)`, `r <= c`.
#[inline(always)]
fn symmetric<const N: usize>(entry: impl Fn(usize, usize) -> f64) -> SMatrix<f64, N, N> {
    let mut m = SMatrix::<f64, N, N>::zeros();
    for r in 0..N {
        for c in r..N {
            let value = entry(r, c);
            m[(r, c)] = value;
            m[(c, r)] = value;
        }
    }
    m
}

/// The positive semidefinite matrix nearest to the symmetric `p` in the Frobenius norm:
/// its eigendecomposition with the negative eigenvalues set to zero. Kept out of line:
/// only the repeated pass after a breakdown calls it.
#[cold]
#[inline(never)]
fn semidefinite(p: Matrix4<f64>) -> Matrix4<f64> {
    let eigen = p.symmetric_eigen();
    if eigen.eigenvalues.iter().all(|&e| e >= 0.0) {
        return p;
    }
    let v = eigen.eigenvectors;
    let p = v * Matrix4::from_diagonal(&eigen.eigenvalues.map(|e| e.max(0.0))) * v.transpose();
    (p + p.transpose()) * 0.5
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::StepDynamics;

    /// One step, no terminal rows: the acceleration's row of the Newton system is
    /// solved to rounding however large the steering's diagonal (an active steering
    /// bound, `W = λ / s` of 1e20 near the end of a warm re-plan). A regularization
    /// relative to the larger diagonal entry moved the acceleration by 1e7 / 2 of its
    /// own size, and a warm re-plan stalled 6e-6 above the optimum
    /// (`tests/replan.proptest-regressions`, K = 22 with a fixed `s_K`).
    #[test]
    fn a_huge_steering_diagonal_leaves_the_acceleration_row_exact() {
        for steering_diagonal in [0.0, 1e8, 1e14, 1e20] {
            let mut riccati = Riccati::default();
            riccati.resize(1);
            let h = [
                Matrix6::from_diagonal(&Vector6::new(1.0, 1.0, 1.0, 1.0, 2.0, 2.0)),
                Matrix6::from_diagonal(&Vector6::new(1.0, 1.0, 1.0, 1.0, 0.0, 0.0)),
            ];
            let d = [
                Vector6::new(0.0, 0.0, 0.0, 0.0, 0.0, steering_diagonal),
                Vector6::zeros(),
            ];
            let dynamics = [Dynamics {
                c: Vector4::zeros(),
                sparse: StepDynamics {
                    ds: 0.1,
                    dl: 2.0,
                    bv: 0.1,
                    bphi: 0.8,
                },
            }];
            riccati
                .factor(&h, &d, &dynamics, &Matrix4::zeros(), 0)
                .unwrap();
            let linear = [
                Vector6::new(0.0, 0.0, 0.0, 0.0, -1.5, 0.0),
                Vector6::zeros(),
            ];
            let (mut ux, mut y_dynamics) = ([Vector6::zeros(); 2], [Vector4::zeros()]);
            let (mut y_initial, mut y_terminal) = (Vector4::zeros(), Vector4::zeros());
            riccati.solve(
                &dynamics,
                &Rhs {
                    linear: &linear,
                    offsets: &[Vector4::zeros()],
                    initial: Vector4::zeros(),
                    terminal: Vector4::zeros(),
                },
                Step {
                    ux: &mut ux,
                    y_dynamics: &mut y_dynamics,
                    y_initial: &mut y_initial,
                    y_terminal: &mut y_terminal,
                    multipliers: true,
                },
            );
            // Stationarity in a: (2 + bv² P_1[v, v]) a = 1.5 with P_1 = I.
            let expected = 1.5 / (2.0 + 0.1 * 0.1);
            let a = ux[0][4];
            assert!(
                (a - expected).abs() <= 1e-9 * expected,
                "steering diagonal {steering_diagonal:e}: a = {a}, expected {expected}"
            );
        }
    }
}
