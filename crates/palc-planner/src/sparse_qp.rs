//! The clarabel backend's form of the QP, derived from the stage form of
//! [`StageQp`]: `min ½ xᵀPx + qᵀx  s.t.  A x + s = b, s ∈ {0}^{m_eq} × R_+^{m_in}`
//! as triplets in the flat variable order `x = [X_0, U_0, ..., X_K, σ]` and the row
//! order `X_0`, dynamics, terminal, inequalities, scattered into a compressed-sparse-
//! column pattern built once per sparsity pattern.
//!
//! Every entry of the pattern is always written (zeros included): per stage the six
//! diagonal entries of `P` and the couplings of `δ` with `s`, `l` and `φ` (the state
//! diagonal only at stage `K`), the identity and the kinematic bicycle's four entries
//! of each dynamics step (Eqs. 11-14), so that the pattern depends only on `K`, the
//! bound pattern, the mode and whether `s_K` is fixed.

use crate::dynamics::StepDynamics;
use crate::qp::{NX, StageQp, control_index, state_index};

/// The triplets and vectors of one plan's QP; rebuilt for each plan (cheap), then
/// scattered into a cached CSC pattern.
#[derive(Debug, Default)]
pub(crate) struct SparseQp {
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
}

impl SparseQp {
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

    /// Derives the triplets of `qp`, reusing the buffers.
    pub fn fill(&mut self, qp: &StageQp) {
        let k = qp.k;
        self.n = qp.n();
        self.m_eq = qp.m_eq;
        self.m_in = qp.inequalities.len();
        for v in [
            &mut self.p_rows,
            &mut self.p_cols,
            &mut self.a_rows,
            &mut self.a_cols,
        ] {
            v.clear();
        }
        for v in [&mut self.p_vals, &mut self.a_vals, &mut self.q, &mut self.b] {
            v.clear();
        }

        // Cost: the upper triangle of each stage block, and the linear terms.
        for i in 0..=k {
            let (x, h, g) = (state_index(i), &qp.hessian[i], &qp.linear[i]);
            let size = if i < k { 6 } else { NX };
            for c in 0..size {
                self.p(x + c, x + c, h[(c, c)]);
            }
            if i < k {
                let delta = control_index(i) + 1;
                for c in [0, 2, 3] {
                    self.p(x + c, delta, h[(c, 5)]);
                }
            }
            self.q.extend(g.iter().take(size));
        }
        self.q.extend(&qp.slack_cost);

        // Equality rows: X_0 (Eq. 20), dynamics (Eqs. 11-14), terminal (Eq. 21).
        for c in 0..NX {
            self.a(c, c, 1.0);
            self.b.push(qp.x0[c]);
        }
        for (i, d) in qp.dynamics.iter().enumerate() {
            let r = NX + NX * i;
            let (x, u, next) = (state_index(i), control_index(i), state_index(i + 1));
            let StepDynamics { ds, dl, bv, bphi } = d.sparse;
            for c in 0..NX {
                self.a(r + c, next + c, 1.0);
                self.a(r + c, x + c, -1.0);
            }
            self.a(r, x + 1, -ds); // s' = v
            self.a(r + 1, u, -bv); // v' = a
            self.a(r + 2, x + 3, -dl); // l' = v_ref φ
            self.a(r + 3, u + 1, -bphi); // φ' = v_ref/l_fr δ - v_ref R
            self.b.extend(d.c.iter());
        }
        let first_terminal = NX + NX * k;
        for row in 0..qp.terminal_rows {
            for c in 0..NX {
                if qp.terminal[(row, c)] != 0.0 {
                    self.a(
                        first_terminal + row,
                        state_index(k) + c,
                        qp.terminal[(row, c)],
                    );
                }
            }
            self.b.push(qp.terminal_rhs[row]);
        }

        // Inequality rows: steering (Eq. 23), lateral (Eq. 22), slacks.
        for (j, row) in qp.inequalities.iter().enumerate() {
            let r = qp.m_eq + j;
            if let Some((i, l)) = row.core() {
                self.a(r, state_index(i) + l, row.coef);
            }
            if let Some(slack) = row.slack() {
                self.a(r, qp.slack_column(slack), row.slack_coef);
            }
            self.b.push(row.h);
        }
        debug_assert_eq!(self.q.len(), self.n);
        debug_assert_eq!(self.b.len(), self.m_eq + self.m_in);
    }
}

/// A compressed-sparse-column pattern built once from triplets, with the position of
/// each triplet in `nzval` (duplicates share a position and are summed); only the
/// clarabel backend reads the QP in this form.
#[derive(Debug, Clone)]
pub(crate) struct CscPattern {
    pub m: usize,
    pub n: usize,
    pub colptr: Vec<usize>,
    pub rowval: Vec<usize>,
    pub slot_of_triplet: Vec<usize>,
}

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
