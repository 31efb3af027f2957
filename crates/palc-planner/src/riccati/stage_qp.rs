//! The assembled QP read back in stage form: per step a 6 x 6 cost block over
//! `[X_i; U_i]`, the affine dynamics `X_{i+1} = A_i X_i + B_i U_i + c_i`, the fixed
//! `X_0`, the terminal rows `E X_K = e`, and inequality rows that each touch one
//! stage variable and at most one soft-bound slack.
//!
//! The stage form is read from [`QpData`] (the one assembly of Eqs. 11-23), never
//! built a second time from the [`Problem`](crate::Problem), so both backends solve
//! the same numbers.

use nalgebra::{Matrix4, Matrix4x2, Matrix6, Vector4, Vector6};

use super::sparse::StepDynamics;
use crate::LayoutError;
use crate::qp::QpData;

/// Most inequality rows one slack may appear in (soft mode uses 3: above, below, `σ >= 0`).
pub(crate) const MAX_SLACK_ROWS: usize = 4;

/// States per step.
pub(crate) const NX: usize = 4;
/// Variables per stage (state and control).
pub(crate) const NZ: usize = 6;

/// `X_{i+1} = A X_i + B U_i + c` (Eqs. 11-14); `sparse` holds `A` and `B` in the
/// cheapest exact form for the products of the recursion.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Dynamics {
    pub c: Vector4<f64>,
    pub sparse: StepDynamics,
}

/// One inequality row `coef · z[core] + slack_coef · σ[slack] <= h`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Inequality {
    /// `(stage, local index in [X; U])` of the stage variable, if any.
    pub core: Option<(usize, usize)>,
    pub coef: f64,
    /// Index of the slack variable, if any.
    pub slack: Option<usize>,
    pub slack_coef: f64,
    pub h: f64,
}

impl Inequality {
    /// `(G x)_j` of this row for the stage variables `ux` and the slacks `σ`.
    #[inline(always)]
    pub fn times(&self, ux: &[Vector6<f64>], sigma: &[f64]) -> f64 {
        self.core.map_or(0.0, |(i, l)| self.coef * ux[i][l])
            + self.slack.map_or(0.0, |k| self.slack_coef * sigma[k])
    }
}

/// The QP of [`QpData`] in stage form.
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
    /// `(A_i, B_i)` accumulated from the triplets while loading.
    dense_dynamics: Vec<(Matrix4<f64>, Matrix4x2<f64>)>,
    /// The fixed initial state.
    pub x0: Vector4<f64>,
    /// Number of terminal rows `m <= 4`.
    pub terminal_rows: usize,
    /// `E` (rows `0..m`).
    pub terminal: Matrix4<f64>,
    /// `e` (entries `0..m`).
    pub terminal_rhs: Vector4<f64>,
    /// Linear cost of each slack.
    pub slack_cost: Vec<f64>,
    /// The stage variable each slack is tied to by its rows, if any.
    pub slack_core: Vec<Option<(usize, usize)>>,
    /// The inequality rows of each slack (at most [`MAX_SLACK_ROWS`], first; the unused
    /// entries `None`).
    pub slack_rows: Vec<[Option<usize>; MAX_SLACK_ROWS]>,
    /// Inequality rows in the order of the QP's rows.
    pub inequalities: Vec<Inequality>,
    /// Equality rows `m_eq = 4 + 4K + m`.
    pub m_eq: usize,
    /// Per stage variable (`NZ * stage + local`): whether a slack is tied to it.
    softly_bounded: Vec<bool>,
    /// The constant of the objective (squared-distance and tracking constants).
    pub constant: f64,
}

/// Where a QP variable lives.
enum Var {
    Core(usize, usize),
    Slack(usize),
}

impl StageQp {
    /// Reads `data` (assembled for horizon `k`) into stage form, reusing the buffers.
    /// Fails with the [`LayoutError`] where the data departs from the planner's layout.
    pub fn load(&mut self, data: &QpData, k: usize) -> Result<(), LayoutError> {
        let n_core = NZ * k + NX;
        if data.n < n_core || data.m_eq < NX + NX * k || data.m_eq > 2 * NX + NX * k {
            return Err(LayoutError::Size {
                n: data.n,
                m_eq: data.m_eq,
                horizon: k,
            });
        }
        let n_slack = data.n - n_core;
        let var = |col: usize| {
            if col < n_core {
                Var::Core(col / NZ, col % NZ)
            } else {
                Var::Slack(col - n_core)
            }
        };
        self.k = k;
        self.hessian.clear();
        self.hessian.resize(k + 1, Matrix6::zeros());
        self.linear.clear();
        self.linear.resize(k + 1, Vector6::zeros());
        self.dynamics.clear();
        self.dynamics.resize(k, Dynamics::default());
        self.dense_dynamics.clear();
        self.dense_dynamics
            .resize(k, (Matrix4::zeros(), Matrix4x2::zeros()));
        self.slack_cost.clear();
        self.slack_cost.extend_from_slice(&data.q[n_core..]);
        self.slack_core.clear();
        self.slack_core.resize(n_slack, None);
        self.inequalities.clear();
        self.x0 = Vector4::zeros();
        self.terminal = Matrix4::zeros();
        self.terminal_rhs = Vector4::zeros();
        self.m_eq = data.m_eq;
        self.constant = data.constant;
        self.terminal_rows = data.m_eq - NX - NX * k;

        for ((&r, &c), &v) in data.p_rows.iter().zip(&data.p_cols).zip(&data.p_vals) {
            match (var(r), var(c)) {
                (Var::Core(i, a), Var::Core(j, b)) if i == j => {
                    self.hessian[i][(a, b)] += v;
                    if a != b {
                        self.hessian[i][(b, a)] += v;
                    }
                }
                _ => return Err(LayoutError::CoupledHessian { row: r, col: c }),
            }
        }
        for (col, &v) in data.q[..n_core].iter().enumerate() {
            self.linear[col / NZ][col % NZ] = v;
        }

        let first_terminal = NX + NX * k;
        for ((&r, &c), &v) in data.a_rows.iter().zip(&data.a_cols).zip(&data.a_vals) {
            let Var::Core(stage, local) = var(c) else {
                if r < data.m_eq {
                    return Err(LayoutError::SlackInEquality { row: r });
                }
                continue;
            };
            if r < NX {
                if (stage, local) != (0, r) || v != 1.0 {
                    return Err(LayoutError::InitialRow { row: r });
                }
            } else if r < first_terminal {
                let (step, comp) = ((r - NX) / NX, (r - NX) % NX);
                if stage == step + 1 {
                    if local != comp || v != 1.0 {
                        return Err(LayoutError::DynamicsRow { row: r });
                    }
                } else if stage == step && local < NX {
                    self.dense_dynamics[step].0[(comp, local)] -= v;
                } else if stage == step {
                    self.dense_dynamics[step].1[(comp, local - NX)] -= v;
                } else {
                    return Err(LayoutError::DynamicsRow { row: r });
                }
            } else if r < data.m_eq {
                if stage != k || local >= NX {
                    return Err(LayoutError::TerminalRow { row: r, stage });
                }
                self.terminal[(r - first_terminal, local)] += v;
            }
        }
        for r in 0..NX {
            self.x0[r] = data.b[r];
        }
        for step in 0..k {
            let d = &mut self.dynamics[step];
            for comp in 0..NX {
                d.c[comp] = data.b[NX + NX * step + comp];
            }
            let (a, b) = &self.dense_dynamics[step];
            d.sparse = StepDynamics::new(a, b);
        }
        for j in 0..self.terminal_rows {
            self.terminal_rhs[j] = data.b[first_terminal + j];
        }

        let m_in = data.b.len() - data.m_eq;
        self.inequalities.resize(
            m_in,
            Inequality {
                core: None,
                coef: 0.0,
                slack: None,
                slack_coef: 0.0,
                h: 0.0,
            },
        );
        for (row, h) in data.b[data.m_eq..].iter().enumerate() {
            self.inequalities[row].h = *h;
        }
        for ((&r, &c), &v) in data.a_rows.iter().zip(&data.a_cols).zip(&data.a_vals) {
            if r < data.m_eq {
                continue;
            }
            let row = &mut self.inequalities[r - data.m_eq];
            match var(c) {
                Var::Core(stage, local) if row.core.is_none() => {
                    row.core = Some((stage, local));
                    row.coef = v;
                }
                Var::Slack(j) if row.slack.is_none() => {
                    row.slack = Some(j);
                    row.slack_coef = v;
                }
                _ => {
                    return Err(LayoutError::InequalityRow { row: r - data.m_eq });
                }
            }
        }
        self.slack_rows.clear();
        self.slack_rows.resize(n_slack, [None; MAX_SLACK_ROWS]);
        for (row, ineq) in self.inequalities.iter().enumerate() {
            let Some(j) = ineq.slack else { continue };
            let Some(free) = self.slack_rows[j].iter_mut().find(|r| r.is_none()) else {
                return Err(LayoutError::Slack { slack: j });
            };
            *free = Some(row);
            if let Some(core) = ineq.core {
                match self.slack_core[j] {
                    None => self.slack_core[j] = Some(core),
                    Some(other) if other == core => {}
                    Some(_) => {
                        return Err(LayoutError::Slack { slack: j });
                    }
                }
            }
        }
        if let Some(j) = self.slack_rows.iter().position(|r| r[0].is_none()) {
            return Err(LayoutError::Slack { slack: j });
        }
        self.softly_bounded.clear();
        self.softly_bounded.resize(NZ * (k + 1), false);
        for &(i, l) in self.slack_core.iter().flatten() {
            self.softly_bounded[NZ * i + l] = true;
        }
        for (row, ineq) in self.inequalities.iter().enumerate() {
            if let (Some((i, l)), None) = (ineq.core, ineq.slack) {
                if self.softly_bounded[NZ * i + l] {
                    return Err(LayoutError::HardRowOnSoftVariable { row });
                }
            }
        }
        Ok(())
    }
}
