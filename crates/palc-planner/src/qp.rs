//! The lane-change QP in stage form, assembled once from the problem (Eqs. 9-23 and 34):
//!
//! ```text
//! min Σ_{i<K} ½ ux_iᵀ H_i ux_i + g_iᵀ ux_i + ½ x_Kᵀ H_K x_K + g_Kᵀ x_K + ρ Σ_j σ_j + c
//! s.t. x_0 = x̂_0 (Eq. 20),   x_{i+1} = A_i x_i + B_i u_i + c_i (Eqs. 11-14),
//!      E x_K = e (Eq. 21),   coef · ux_i[l] + coef_σ · σ_j <= h (Eqs. 22-23, slacks),
//! ```
//!
//! with `ux_i = [X_i; U_i]`: per step a 6 x 6 cost block (the quadratic features of
//! Eq. 34 weighted by column `i` of `w`, the acceleration penalty around the reference
//! profile's acceleration ([`Problem::reference_acceleration`]) and the tracking
//! term), the affine dynamics, the fixed `X_0`, the terminal rows, and inequality rows
//! that each touch one stage variable and at most one soft-bound slack `σ`.
//!
//! This is the one assembly: the Riccati backend reads it as it is, and the clarabel
//! backend's sparse matrices are derived from it (`sparse_qp.rs`), so both backends
//! solve the same numbers. The flat variable vector of both backends' results is
//! `x = [X_0, U_0, X_1, U_1, ..., X_K, σ]` ([`state_index`], [`control_index`],
//! [`StageQp::slack_column`]) and the rows are `X_0`, dynamics, terminal, inequalities.
//!
//! Longitudinal positions are assembled relative to the ego's initial position,
//! `s̃ = s - s_0` (the variable is `s̃`, [`StageQp::origin`] holds `s_0`): the squared
//! distances of Eq. 34 and the tracking term then expand around offsets of tens of
//! metres instead of absolute positions, whose squares (1e18 at 1e9 m) would cancel in
//! the objective. The feature `s δ` (w7) is kept exact as `w7 s̃ δ + w7 s_0 δ`, a linear
//! term in `δ`: it is the one feature that depends on where the plan starts (see
//! [`Problem`]).

use nalgebra::{Matrix4, Matrix6, Vector4, Vector6};

use crate::dynamics::{Dynamics, StepDynamics};
use crate::{LateralBoundsMode, PlannerConfig, Problem, feature};

/// States per step (`[s, v, l, φ]`, Eq. 9).
pub(crate) const NX: usize = 4;
/// Controls per step (`[a, δ]`, Eq. 10).
pub(crate) const NU: usize = 2;
/// Variables per stage (state and control).
pub(crate) const NZ: usize = NX + NU;
/// Most inequality rows one slack is in (above, below, `σ >= 0`).
pub(crate) const MAX_SLACK_ROWS: usize = 3;

/// Local indices of the stage variables in `ux_i = [s, v, l, φ, a, δ]`.
mod local {
    pub const S: usize = 0;
    pub const V: usize = 1;
    pub const L: usize = 2;
    pub const PHI: usize = 3;
    pub const A: usize = 4;
    pub const DELTA: usize = 5;
}

/// Offset of `X_i` in the flat variable vector.
pub(crate) fn state_index(step: usize) -> usize {
    NZ * step
}

/// Offset of `U_i` in the flat variable vector.
pub(crate) fn control_index(step: usize) -> usize {
    NZ * step + NX
}

/// What decides the sparsity pattern of the QP for a fixed configuration.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Pattern {
    /// Per step `0..=K`: (lower bound present, upper bound present).
    pub lateral: Vec<(bool, bool)>,
    /// Whether `s_K` is fixed.
    pub terminal_s: bool,
}

/// What an inequality row constrains, to read infeasibility certificates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum RowTag {
    Steering(usize),
    Lateral(usize),
    Slack,
}

/// The index of an absent variable in an [`Inequality`].
const ABSENT: u32 = u32::MAX;

/// One inequality row `coef · ux[core] + slack_coef · σ[slack] <= h`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Inequality {
    /// Index of the stage variable in the stage variables flattened
    /// (`NZ * stage + local`, [`flat`]), or [`ABSENT`]: the interior point reads every
    /// row several times per iteration, and a flat index costs one load where
    /// `Option<(stage, local)>` cost two bounds checks and a branch (32 bytes a row
    /// instead of 48).
    var: u32,
    /// Index of the slack variable, or [`ABSENT`].
    slack: u32,
    pub coef: f64,
    pub slack_coef: f64,
    pub h: f64,
}

impl Inequality {
    /// The row `coef · ux[core] + slack_coef · σ[slack] <= h`.
    pub fn new(
        core: Option<(usize, usize)>,
        coef: f64,
        slack: Option<usize>,
        slack_coef: f64,
        h: f64,
    ) -> Self {
        Self {
            var: core.map_or(ABSENT, |(i, l)| (NZ * i + l) as u32),
            coef,
            slack: slack.map_or(ABSENT, |k| k as u32),
            slack_coef,
            h,
        }
    }

    /// `(stage, local index in [X; U])` of the stage variable, if any.
    #[inline(always)]
    pub fn core(&self) -> Option<(usize, usize)> {
        let var = self.var as usize;
        (self.var != ABSENT).then_some((var / NZ, var % NZ))
    }

    /// Index of the slack variable, if any.
    #[inline(always)]
    pub fn slack(&self) -> Option<usize> {
        (self.slack != ABSENT).then_some(self.slack as usize)
    }

    /// The entry of the row's stage variable in `ux` (flattened, [`flat`]), if any.
    #[inline(always)]
    pub fn var_in<'a>(&self, ux: &'a mut [f64]) -> Option<&'a mut f64> {
        // `ABSENT` is past the end of any slice: one comparison says both that the
        // variable exists and that its index is in bounds.
        ux.get_mut(self.var as usize)
    }

    /// The entry of the row's slack in `sigma`, if any.
    #[inline(always)]
    pub fn slack_in<'a>(&self, sigma: &'a mut [f64]) -> Option<&'a mut f64> {
        sigma.get_mut(self.slack as usize)
    }

    /// `(G x)_j` of this row for the stage variables `ux` (flattened, [`flat`]) and
    /// the slacks `σ`.
    #[inline(always)]
    pub fn times(&self, ux: &[f64], sigma: &[f64]) -> f64 {
        // As in `var_in`: one comparison for presence and bounds.
        ux.get(self.var as usize).map_or(0.0, |x| self.coef * x)
            + sigma
                .get(self.slack as usize)
                .map_or(0.0, |x| self.slack_coef * x)
    }
}

/// The stage variables `[X_0; U_0], ..., [X_K; U_K]` as one slice, `NZ` entries a
/// stage: the layout the rows' variable indices refer to.
#[inline(always)]
pub(crate) fn flat(ux: &[Vector6<f64>]) -> &[f64] {
    bytemuck::cast_slice(ux)
}

/// [`flat`], mutable.
#[inline(always)]
pub(crate) fn flat_mut(ux: &mut [Vector6<f64>]) -> &mut [f64] {
    bytemuck::cast_slice_mut(ux)
}

/// The QP of one plan in stage form; buffers reused between plans.
#[derive(Debug, Default)]
pub(crate) struct StageQp {
    /// Horizon `K`.
    pub k: usize,
    /// Cost Hessian block of stage `i` over `[X_i; U_i]` (`K + 1` blocks; the last has
    /// only its state corner).
    pub hessian: Vec<Matrix6<f64>>,
    /// Linear cost of stage `i` (`K + 1`).
    pub linear: Vec<Vector6<f64>>,
    /// Dynamics of steps `0..K`.
    pub dynamics: Vec<Dynamics>,
    /// The fixed initial state (`s̃_0 = 0`).
    pub x0: Vector4<f64>,
    /// Number of terminal rows `m <= 4`.
    pub terminal_rows: usize,
    /// `E` (rows `0..m`).
    pub terminal: Matrix4<f64>,
    /// `e` (entries `0..m`).
    pub terminal_rhs: Vector4<f64>,
    /// Linear cost of each slack.
    pub slack_cost: Vec<f64>,
    /// The stage variable each slack is tied to by its rows.
    pub slack_core: Vec<Option<(usize, usize)>>,
    /// The inequality rows of each slack (at most [`MAX_SLACK_ROWS`], first; the unused
    /// entries `None`).
    pub slack_rows: Vec<[Option<usize>; MAX_SLACK_ROWS]>,
    /// Inequality rows: steering (Eq. 23) for every step, then the lateral bounds
    /// (Eq. 22) step by step, each bounded step's slack row after its bounds.
    pub inequalities: Vec<Inequality>,
    /// What each inequality row constrains.
    pub row_tags: Vec<RowTag>,
    /// The slack of each step `0..=K` (soft mode, bounded steps only).
    pub slack_of_step: Vec<Option<usize>>,
    /// Equality rows `m_eq = 4 + 4K + m`.
    pub m_eq: usize,
    /// The constant of the objective (squared-distance and tracking constants).
    pub constant: f64,
    /// `s_0`: the longitudinal variables are `s - s_0`.
    pub origin: f64,
}

impl StageQp {
    /// Fills the QP of Eqs. (11)-(23) (+ extras) for a validated problem, reusing the
    /// buffers.
    pub fn assemble(&mut self, config: &PlannerConfig, problem: &Problem) {
        use local::{A, DELTA, L, PHI, S, V};
        let k = config.horizon;
        let dt = config.dt;
        let soft_weight = match config.lateral_bounds_mode {
            LateralBoundsMode::Soft { weight } => Some(weight),
            LateralBoundsMode::Hard => None,
        };
        self.k = k;
        reset(&mut self.hessian, k + 1, Matrix6::zeros());
        reset(&mut self.linear, k + 1, Vector6::zeros());
        self.dynamics.clear();
        self.inequalities.clear();
        self.row_tags.clear();
        self.slack_of_step.clear();
        self.slack_cost.clear();
        self.slack_core.clear();
        self.slack_rows.clear();
        self.constant = 0.0;
        let origin = problem.initial.s;
        self.origin = origin;
        for bound in &problem.lateral_bounds {
            let bounded = bound.is_some_and(|b| b.min.is_some() || b.max.is_some());
            match soft_weight.filter(|_| bounded) {
                Some(weight) => {
                    self.slack_of_step.push(Some(self.slack_cost.len()));
                    self.slack_cost.push(weight);
                }
                None => self.slack_of_step.push(None),
            }
        }

        // Eq. (15) with Eqs. (16)-(19) and (34): stage i uses X_{i-1}, U_{i-1} and
        // column i-1 of w.
        for (stage, w) in problem.weights.columns().iter().enumerate() {
            let (mut pre, mut adj) = (problem.preceding[stage], problem.adjacent[stage]);
            pre.s -= origin;
            adj.s -= origin;
            let (w9, w10) = (w[feature::DIST_PRECEDING], w[feature::DIST_ADJACENT]);
            let h = &mut self.hessian[stage];
            h[(S, S)] += 2.0 * (w9 + w10);
            h[(L, L)] += 2.0 * (w[feature::L_SQUARED] + w9 + w10);
            h[(PHI, PHI)] += 2.0 * w[feature::PHI_SQUARED];
            // ρ_a (a - a_ref)² = ρ_a a² - 2 ρ_a a_ref a + ρ_a a_ref².
            let a_ref = problem.reference_acceleration(stage, dt);
            h[(A, A)] += 2.0 * config.acceleration_penalty;
            h[(DELTA, DELTA)] += 2.0 * w[feature::DELTA_SQUARED];
            for (row, weight) in [
                (S, w[feature::S_DELTA]),
                (L, w[feature::L_DELTA]),
                (PHI, w[feature::PHI_DELTA]),
            ] {
                h[(row, DELTA)] += weight;
                h[(DELTA, row)] += weight;
            }
            let g = &mut self.linear[stage];
            g[S] += -2.0 * (w9 * pre.s + w10 * adj.s);
            g[L] += w[feature::L] - 2.0 * (w9 * pre.l + w10 * adj.l);
            g[PHI] += w[feature::PHI];
            g[DELTA] += w[feature::S_DELTA] * origin;
            g[A] += -2.0 * config.acceleration_penalty * a_ref;
            self.constant += config.acceleration_penalty * a_ref * a_ref
                + w9 * (pre.s * pre.s + pre.l * pre.l)
                + w10 * (adj.s * adj.s + adj.l * adj.l);
        }
        // Tracking (form of Eq. 25).
        if let Some(tracking) = &problem.tracking {
            for (step, reference) in tracking.reference.iter().enumerate().take(k + 1) {
                let Some(reference) = reference else { continue };
                let mut r = reference.to_array();
                r[S] -= origin;
                for c in 0..NX {
                    let weight = tracking.weights[c];
                    self.hessian[step][(c, c)] += 2.0 * weight;
                    self.linear[step][c] += -2.0 * weight * r[c];
                    self.constant += weight * r[c] * r[c];
                }
            }
        }

        // Equality rows: X_0 (Eq. 20), dynamics (Eqs. 11-14), terminal (Eq. 21).
        self.x0 = Vector4::from(problem.initial.to_array());
        self.x0[S] = 0.0;
        let steer_gain = dt / config.wheelbase;
        for i in 0..k {
            let v_ref = problem.reference_speed[i];
            self.dynamics.push(Dynamics {
                c: Vector4::new(0.0, 0.0, 0.0, -dt * v_ref * problem.curvature),
                sparse: StepDynamics {
                    ds: dt,                   // s' = v
                    dl: dt * v_ref,           // l' = v_ref φ
                    bv: dt,                   // v' = a
                    bphi: steer_gain * v_ref, // φ' = v_ref/l_fr δ - v_ref R
                },
            });
        }
        let t = &problem.terminal;
        let terminal = [
            (t.s.map(|s| s - origin), S),
            (Some(t.v), V),
            (Some(t.l), L),
            (Some(0.0), PHI),
        ];
        self.terminal = Matrix4::zeros();
        self.terminal_rhs = Vector4::zeros();
        self.terminal_rows = 0;
        for (value, c) in terminal {
            if let Some(value) = value {
                self.terminal[(self.terminal_rows, c)] = 1.0;
                self.terminal_rhs[self.terminal_rows] = value;
                self.terminal_rows += 1;
            }
        }
        self.m_eq = NX + NX * k + self.terminal_rows;

        // Inequality rows: steering (Eq. 23), lateral (Eq. 22), slacks.
        for i in 0..k {
            for (coef, h) in [(1.0, config.steering_max), (-1.0, -config.steering_min)] {
                self.inequalities
                    .push(Inequality::new(Some((i, DELTA)), coef, None, 0.0, h));
                self.row_tags.push(RowTag::Steering(i));
            }
        }
        for (step, bound) in problem.lateral_bounds.iter().enumerate() {
            let Some(bound) = bound else { continue };
            let slack = self.slack_of_step[step];
            let mut rows = [None; MAX_SLACK_ROWS];
            let mut add = |qp: &mut Self, row: Inequality, tag| {
                if let Some(free) = rows.iter_mut().find(|r| r.is_none()) {
                    *free = Some(qp.inequalities.len());
                }
                qp.inequalities.push(row);
                qp.row_tags.push(tag);
            };
            for (value, sign) in [(bound.max, 1.0), (bound.min, -1.0)] {
                if let Some(value) = value {
                    let slack_coef = if slack.is_some() { -1.0 } else { 0.0 };
                    let row =
                        Inequality::new(Some((step, L)), sign, slack, slack_coef, sign * value);
                    add(self, row, RowTag::Lateral(step));
                }
            }
            if slack.is_some() {
                let row = Inequality::new(None, 0.0, slack, -1.0, 0.0);
                add(self, row, RowTag::Slack);
                self.slack_core.push(Some((step, L)));
                self.slack_rows.push(rows);
            }
        }
    }

    /// Number of variables of the flat vector `[X_0, U_0, ..., X_K, σ]`.
    pub fn n(&self) -> usize {
        NZ * self.k + NX + self.slack_cost.len()
    }

    /// Column of slack `j` in the flat variable vector.
    pub fn slack_column(&self, j: usize) -> usize {
        NZ * self.k + NX + j
    }

    /// `½ xᵀPx + qᵀx + c` of a flat variable vector `x` (length [`n`](Self::n)).
    pub fn objective(&self, x: &[f64]) -> f64 {
        let mut value = self.constant;
        for i in 0..=self.k {
            let size = if i < self.k { NZ } else { NX };
            let start = state_index(i);
            let mut ux = Vector6::zeros();
            for (c, &v) in x[start..start + size].iter().enumerate() {
                ux[c] = v;
            }
            value += 0.5 * ux.dot(&hessian_mul(&self.hessian[i], &ux)) + self.linear[i].dot(&ux);
        }
        let sigma = &x[self.slack_column(0)..];
        value
            + self
                .slack_cost
                .iter()
                .zip(sigma)
                .map(|(c, s)| c * s)
                .sum::<f64>()
    }
}

/// `H x` for a cost block of [`StageQp::assemble`], which writes only the diagonal and
/// the `δ` row and column (`s δ`, `l δ`, `φ δ`: w7, w5, w6 of Eq. 34): 12 entries of 36,
/// read at their fixed positions.
#[inline(always)]
pub(crate) fn hessian_mul(h: &Matrix6<f64>, x: &Vector6<f64>) -> Vector6<f64> {
    use local::{DELTA, L, PHI, S};
    let (hs, hl, hphi) = (h[(S, DELTA)], h[(L, DELTA)], h[(PHI, DELTA)]);
    let delta = x[DELTA];
    Vector6::new(
        h[(0, 0)] * x[0] + hs * delta,
        h[(1, 1)] * x[1],
        h[(2, 2)] * x[2] + hl * delta,
        h[(3, 3)] * x[3] + hphi * delta,
        h[(4, 4)] * x[4],
        h[(5, 5)] * delta + hs * x[S] + hl * x[L] + hphi * x[PHI],
    )
}

/// `v` with `n` entries, all `value` (allocates only when `n` grows past the capacity).
fn reset<T: Copy>(v: &mut Vec<T>, n: usize, value: T) {
    v.clear();
    v.resize(n, value);
}

/// The sparsity-deciding part of a problem.
pub(crate) fn pattern_of(problem: &Problem) -> Pattern {
    Pattern {
        lateral: problem
            .lateral_bounds
            .iter()
            .map(|b| b.map_or((false, false), |b| (b.min.is_some(), b.max.is_some())))
            .collect(),
        terminal_s: problem.terminal.s.is_some(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{LateralBound, Position, State, Terminal, Tracking, Weights};
    use proptest::prelude::*;

    proptest! {
        /// A row's flat index names the stage variable it was built with, and its
        /// product `(G x)_j` on the flattened stage variables equals the product on
        /// the stage vectors, with and without a variable or a slack.
        #[test]
        fn a_row_reads_its_variable_through_the_flat_index(
            stage in 0..40usize,
            local in 0..NZ,
            has_var in any::<bool>(),
            slack in prop::option::of(0..5usize),
            coef in -10.0..10.0f64,
            slack_coef in -10.0..10.0f64,
            values in prop::collection::vec(-100.0..100.0f64, 40 * NZ),
            sigma in prop::collection::vec(-100.0..100.0f64, 5),
        ) {
            let core = has_var.then_some((stage, local));
            let row = Inequality::new(core, coef, slack, slack_coef, 1.0);
            prop_assert_eq!(row.core(), core);
            prop_assert_eq!(row.slack(), slack);
            let ux: Vec<Vector6<f64>> =
                values.chunks(NZ).map(Vector6::from_column_slice).collect();
            let expected = core.map_or(0.0, |(i, l)| coef * ux[i][l])
                + slack.map_or(0.0, |k| slack_coef * sigma[k]);
            prop_assert_eq!(row.times(flat(&ux), &sigma), expected);
            let mut flat_ux = values.clone();
            match row.var_in(&mut flat_ux) {
                Some(x) => {
                    prop_assert!(has_var);
                    *x += 1.0;
                    prop_assert_eq!(flat_ux[NZ * stage + local], values[NZ * stage + local] + 1.0);
                }
                None => prop_assert!(!has_var),
            }
        }

        /// Every assembled cost block is zero outside the pattern [`hessian_mul`] reads,
        /// and the product equals the dense one.
        #[test]
        fn assembled_cost_blocks_have_the_pattern_hessian_mul_reads(
            column in prop::array::uniform10(-10.0..10.0f64),
            tracking in prop::array::uniform4(0.0..10.0f64),
            x in prop::array::uniform6(-50.0..50.0f64),
            speed in 1.0..30.0f64,
        ) {
            let config = PlannerConfig { horizon: 8, ..PlannerConfig::default() };
            let k = config.horizon;
            let state = State { s: 100.0, v: speed, l: 0.5, phi: 0.01 };
            let problem = Problem {
                initial: state,
                reference_speed: vec![speed; k],
                curvature: 0.0,
                weights: Weights::constant(k, column),
                preceding: vec![Position { s: 130.0, l: 0.0 }; k],
                adjacent: vec![Position { s: 90.0, l: 3.5 }; k],
                terminal: Terminal { s: None, v: speed, l: 3.5 },
                lateral_bounds: vec![Some(LateralBound::new(-1.75, 5.25)); k + 1],
                tracking: Some(Tracking { weights: tracking, reference: vec![Some(state); k + 1] }),
            };
            let mut qp = StageQp::default();
            qp.assemble(&config, &problem);
            let x = Vector6::from(x);
            for h in &qp.hessian {
                for r in 0..NZ {
                    for c in 0..NZ {
                        let in_pattern = r == c || r == local::DELTA || c == local::DELTA;
                        prop_assert!(in_pattern || h[(r, c)] == 0.0, "entry ({r}, {c}) = {}", h[(r, c)]);
                    }
                }
                let (fast, dense) = (hessian_mul(h, &x), h * x);
                for r in 0..NZ {
                    prop_assert!((fast[r] - dense[r]).abs() <= 1e-12 * (1.0 + dense[r].abs()));
                }
            }
        }
    }
}
