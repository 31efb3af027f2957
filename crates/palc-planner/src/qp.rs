//! Assembly of the sparse QP `min ½ zᵀPz + qᵀz + c  s.t.  A z + s = b, s ∈ {0}^{m_eq} × R_+^{m_in}`.
//!
//! Variables are interleaved by step, `z = [X_0, U_0, X_1, U_1, ..., X_K, σ]`, so that the
//! KKT matrix is banded and a Riccati backend can reuse the layout. `σ` holds one slack
//! per bounded step in soft mode. Every entry of the sparsity pattern is always written
//! (zeros included), so the pattern depends only on `K`, the bound pattern, the mode and
//! whether `s_K` is fixed.
//!
//! Longitudinal positions are assembled relative to the ego's initial position,
//! `s̃ = s - s_0` (the variable of `z` is `s̃`, [`QpData::origin`] holds `s_0`): the
//! squared distances of Eq. 34 and the tracking term then expand around offsets of
//! tens of metres instead of absolute positions, whose squares (1e18 at 1e9 m) would
//! cancel in the objective. The feature `s δ` (w7) is kept exact as
//! `w7 s̃ δ + w7 s_0 δ`, a linear term in `δ`: it is the one feature that depends on
//! where the plan starts (see [`Problem`]).

use crate::{LateralBoundsMode, PlannerConfig, Problem, feature};

/// Offset of `X_i` in `z`.
pub(crate) fn state_index(step: usize) -> usize {
    6 * step
}

/// Offset of `U_i` in `z`.
pub(crate) fn control_index(step: usize) -> usize {
    6 * step + 4
}

/// What decides the sparsity pattern of P and A for a fixed configuration.
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

/// Triplets in a fixed order plus the vectors; rebuilt for each plan (cheap), then
/// scattered into a cached CSC pattern.
#[derive(Debug, Default)]
pub(crate) struct QpData {
    pub n: usize,
    pub m_eq: usize,
    pub m_in: usize,
    pub p_rows: Vec<usize>,
    pub p_cols: Vec<usize>,
    pub p_vals: Vec<f64>,
    pub a_rows: Vec<usize>,
    pub a_cols: Vec<usize>,
    pub a_vals: Vec<f64>,
    pub q: Vec<f64>,
    pub b: Vec<f64>,
    /// Constant dropped from the quadratic form (squared-distance and tracking constants).
    pub constant: f64,
    /// `s_0`: the longitudinal variables of `z` are `s - s_0`.
    pub origin: f64,
    /// Tag of each inequality row (index `row - m_eq`).
    pub row_tags: Vec<RowTag>,
    /// Slack variable of each step in soft mode.
    pub slack_of_step: Vec<Option<usize>>,
}

impl QpData {
    fn p(&mut self, r: usize, c: usize, v: f64) {
        debug_assert!(r <= c);
        self.p_rows.push(r);
        self.p_cols.push(c);
        self.p_vals.push(v);
    }

    fn a(&mut self, r: usize, c: usize, v: f64) {
        self.a_rows.push(r);
        self.a_cols.push(c);
        self.a_vals.push(v);
    }

    /// Fills the QP of Eqs. (11)-(23) (+ extras) for a validated problem.
    pub fn assemble(&mut self, config: &PlannerConfig, problem: &Problem) {
        let k = config.horizon;
        let dt = config.dt;
        let pattern = pattern_of(problem);
        let soft_weight = match config.lateral_bounds_mode {
            LateralBoundsMode::Soft { weight } => Some(weight),
            LateralBoundsMode::Hard => None,
        };
        self.p_rows.clear();
        self.p_cols.clear();
        self.p_vals.clear();
        self.a_rows.clear();
        self.a_cols.clear();
        self.a_vals.clear();
        self.row_tags.clear();
        self.slack_of_step.clear();
        let n_core = 6 * k + 4;
        let mut n = n_core;
        for &(lo, hi) in &pattern.lateral {
            if soft_weight.is_some() && (lo || hi) {
                self.slack_of_step.push(Some(n));
                n += 1;
            } else {
                self.slack_of_step.push(None);
            }
        }
        self.n = n;
        self.q.clear();
        self.q.resize(n, 0.0);
        self.constant = 0.0;
        let origin = problem.initial.s;
        self.origin = origin;

        // Eq. (15) with Eqs. (16)-(19), stage i uses X_{i-1}, U_{i-1} and column i-1.
        for (stage0, w) in problem.weights.columns().iter().enumerate() {
            let x = state_index(stage0);
            let u = control_index(stage0);
            let (mut pre, mut adj) = (problem.preceding[stage0], problem.adjacent[stage0]);
            pre.s -= origin;
            adj.s -= origin;
            let (w9, w10) = (w[feature::DIST_PRECEDING], w[feature::DIST_ADJACENT]);
            self.p(x, x, 2.0 * (w9 + w10));
            self.p(x + 2, x + 2, 2.0 * (w[feature::L_SQUARED] + w9 + w10));
            self.p(x + 3, x + 3, 2.0 * w[feature::PHI_SQUARED]);
            self.p(u, u, 2.0 * config.acceleration_penalty);
            self.p(u + 1, u + 1, 2.0 * w[feature::DELTA_SQUARED]);
            self.p(x, u + 1, w[feature::S_DELTA]);
            self.p(x + 2, u + 1, w[feature::L_DELTA]);
            self.p(x + 3, u + 1, w[feature::PHI_DELTA]);
            self.q[x] += -2.0 * (w9 * pre.s + w10 * adj.s);
            self.q[x + 2] += w[feature::L] - 2.0 * (w9 * pre.l + w10 * adj.l);
            self.q[x + 3] += w[feature::PHI];
            self.q[u + 1] += w[feature::S_DELTA] * origin;
            self.constant +=
                w9 * (pre.s * pre.s + pre.l * pre.l) + w10 * (adj.s * adj.s + adj.l * adj.l);
        }
        // Tracking (form of Eq. 25); the diagonal of every state is always in the pattern.
        for step in 0..=k {
            let x = state_index(step);
            let reference = problem
                .tracking
                .as_ref()
                .and_then(|t| t.reference[step].map(|r| (t.weights, r.to_array())))
                .map(|(q, mut r)| {
                    r[0] -= origin;
                    (q, r)
                });
            for c in 0..4 {
                let (weight, r) = reference.map_or((0.0, 0.0), |(q, r)| (q[c], r[c]));
                self.p(x + c, x + c, 2.0 * weight);
                self.q[x + c] += -2.0 * weight * r;
                self.constant += weight * r * r;
            }
        }
        if let Some(weight) = soft_weight {
            for &slack in self.slack_of_step.iter().flatten() {
                self.q[slack] = weight;
            }
        }

        // Equality rows: X_0 (Eq. 20), dynamics (Eqs. 11-14), terminal (Eq. 21).
        self.b.clear();
        let mut x0 = problem.initial.to_array();
        x0[0] = 0.0;
        for c in 0..4 {
            self.a(c, c, 1.0);
            self.b.push(x0[c]);
        }
        let steer_gain = dt / config.wheelbase;
        for i in 0..k {
            let r = 4 + 4 * i;
            let (x, u, next) = (state_index(i), control_index(i), state_index(i + 1));
            let v_ref = problem.reference_speed[i];
            for c in 0..4 {
                self.a(r + c, next + c, 1.0);
                self.a(r + c, x + c, -1.0);
            }
            self.a(r, x + 1, -dt); // s' = v
            self.a(r + 1, u, -dt); // v' = a
            self.a(r + 2, x + 3, -dt * v_ref); // l' = v_ref φ
            self.a(r + 3, u + 1, -steer_gain * v_ref); // φ' = v_ref/l_fr δ - v_ref R
            self.b
                .extend_from_slice(&[0.0, 0.0, 0.0, -dt * v_ref * problem.curvature]);
        }
        let mut r = 4 + 4 * k;
        let xk = state_index(k);
        let t = &problem.terminal;
        let terminal = [
            (t.s.map(|s| s - origin), 0),
            (Some(t.v), 1),
            (Some(t.l), 2),
            (Some(0.0), 3),
        ];
        for (value, c) in terminal {
            if let Some(value) = value {
                self.a(r, xk + c, 1.0);
                self.b.push(value);
                r += 1;
            }
        }
        self.m_eq = r;

        // Inequality rows A z <= b: steering (Eq. 23), lateral (Eq. 22), slacks.
        for i in 0..k {
            let d = control_index(i) + 1;
            self.a(r, d, 1.0);
            self.b.push(config.steering_max);
            self.a(r + 1, d, -1.0);
            self.b.push(-config.steering_min);
            self.row_tags
                .extend([RowTag::Steering(i), RowTag::Steering(i)]);
            r += 2;
        }
        for (step, bound) in problem.lateral_bounds.iter().enumerate() {
            let Some(bound) = bound else { continue };
            let l = state_index(step) + 2;
            let slack = self.slack_of_step[step];
            for (value, sign) in [(bound.max, 1.0), (bound.min, -1.0)] {
                if let Some(value) = value {
                    self.a(r, l, sign);
                    if let Some(slack) = slack {
                        self.a(r, slack, -1.0);
                    }
                    self.b.push(sign * value);
                    self.row_tags.push(RowTag::Lateral(step));
                    r += 1;
                }
            }
            if let Some(slack) = slack {
                self.a(r, slack, -1.0);
                self.b.push(0.0);
                self.row_tags.push(RowTag::Slack);
                r += 1;
            }
        }
        self.m_in = r - self.m_eq;
    }

    /// `½ zᵀPz + qᵀz + c` from the assembled (unscaled) data.
    pub fn objective(&self, z: &[f64]) -> f64 {
        let mut value = self.constant;
        for ((&r, &c), &v) in self.p_rows.iter().zip(&self.p_cols).zip(&self.p_vals) {
            value += if r == c {
                0.5 * v * z[r] * z[r]
            } else {
                v * z[r] * z[c]
            };
        }
        value + self.q.iter().zip(z).map(|(a, b)| a * b).sum::<f64>()
    }
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

/// A compressed-sparse-column pattern built once from triplets, with the position of
/// each triplet in `nzval` (duplicates share a position and are summed); only the
/// clarabel backend reads the QP in this form.
#[cfg(feature = "clarabel")]
#[derive(Debug, Clone)]
pub(crate) struct CscPattern {
    pub m: usize,
    pub n: usize,
    pub colptr: Vec<usize>,
    pub rowval: Vec<usize>,
    pub slot_of_triplet: Vec<usize>,
}

#[cfg(feature = "clarabel")]
impl CscPattern {
    pub fn new(m: usize, n: usize, rows: &[usize], cols: &[usize]) -> Self {
        let mut order: Vec<usize> = (0..rows.len()).collect();
        order.sort_unstable_by_key(|&t| (cols[t], rows[t]));
        let mut colptr = vec![0; n + 1];
        let mut rowval = Vec::with_capacity(rows.len());
        let mut slot_of_triplet = vec![0; rows.len()];
        let mut last: Option<(usize, usize)> = None;
        for &t in &order {
            let key = (cols[t], rows[t]);
            if last != Some(key) {
                rowval.push(rows[t]);
                colptr[cols[t] + 1] += 1;
                last = Some(key);
            }
            slot_of_triplet[t] = rowval.len() - 1;
        }
        for c in 0..n {
            colptr[c + 1] += colptr[c];
        }
        Self {
            m,
            n,
            colptr,
            rowval,
            slot_of_triplet,
        }
    }

    /// Scatters triplet values into `nzval` (summing duplicates).
    pub fn scatter(&self, values: &[f64], nzval: &mut Vec<f64>) {
        nzval.clear();
        nzval.resize(self.rowval.len(), 0.0);
        for (&slot, &v) in self.slot_of_triplet.iter().zip(values) {
            nzval[slot] += v;
        }
    }
}
