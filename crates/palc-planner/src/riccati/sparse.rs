//! Products with the dynamics matrices, exploiting the kinematic bicycle's pattern.
//!
//! Eqs. 11-14 give `A_i = I + N_i` with two entries in `N_i` (`s ← v` and `l ← φ`) and
//! two in `B_i` (`v ← a` and `φ ← δ`): the dense 4 x 4 products of the Riccati recursion
//! spend most of their work on zeros. [`StepDynamics::new`] recognises that pattern
//! (fixed positions, so the values stay in registers) and falls back to dense products
//! for any other `A`, `B`; a property test holds both paths to the same numbers.

use nalgebra::{Matrix4, Matrix4x2, SMatrix, Vector2, Vector4};

/// The dynamics matrices of one step, in the cheapest exact form.
#[derive(Debug, Clone, Copy)]
pub(crate) enum StepDynamics {
    /// `A = I + ds e_s e_vᵀ + dl e_l e_φᵀ`, `B = bv e_v e_aᵀ + bphi e_φ e_δᵀ`.
    Bicycle {
        ds: f64,
        dl: f64,
        bv: f64,
        bphi: f64,
    },
    /// Any other `A`, `B`.
    Dense { a: Matrix4<f64>, b: Matrix4x2<f64> },
}

impl Default for StepDynamics {
    fn default() -> Self {
        Self::Bicycle {
            ds: 0.0,
            dl: 0.0,
            bv: 0.0,
            bphi: 0.0,
        }
    }
}

impl StepDynamics {
    /// The bicycle form when `a` and `b` have its pattern exactly, else the dense form.
    pub fn new(a: &Matrix4<f64>, b: &Matrix4x2<f64>) -> Self {
        let (ds, dl, bv, bphi) = (a[(0, 1)], a[(2, 3)], b[(1, 0)], b[(3, 1)]);
        let bicycle = Self::Bicycle { ds, dl, bv, bphi };
        if bicycle.dense() == (*a, *b) {
            bicycle
        } else {
            Self::Dense { a: *a, b: *b }
        }
    }

    /// `(A, B)` as dense matrices.
    pub fn dense(&self) -> (Matrix4<f64>, Matrix4x2<f64>) {
        match *self {
            Self::Bicycle { ds, dl, bv, bphi } => {
                let mut a = Matrix4::identity();
                a[(0, 1)] = ds;
                a[(2, 3)] = dl;
                let mut b = Matrix4x2::zeros();
                b[(1, 0)] = bv;
                b[(3, 1)] = bphi;
                (a, b)
            }
            Self::Dense { a, b } => (a, b),
        }
    }

    /// `A x`.
    #[inline(always)]
    pub fn a_mul(&self, x: &Vector4<f64>) -> Vector4<f64> {
        match self {
            Self::Bicycle { ds, dl, .. } => {
                Vector4::new(x[0] + ds * x[1], x[1], x[2] + dl * x[3], x[3])
            }
            Self::Dense { a, .. } => a * x,
        }
    }

    /// `B u`.
    #[inline(always)]
    pub fn b_mul(&self, u: &Vector2<f64>) -> Vector4<f64> {
        match self {
            Self::Bicycle { bv, bphi, .. } => Vector4::new(0.0, bv * u[0], 0.0, bphi * u[1]),
            Self::Dense { b, .. } => b * u,
        }
    }

    /// `Aᵀ y`.
    #[inline(always)]
    pub fn a_tr_mul(&self, y: &Vector4<f64>) -> Vector4<f64> {
        match self {
            Self::Bicycle { ds, dl, .. } => {
                Vector4::new(y[0], y[1] + ds * y[0], y[2], y[3] + dl * y[2])
            }
            Self::Dense { a, .. } => a.tr_mul(y),
        }
    }

    /// `Bᵀ y`.
    #[inline(always)]
    pub fn b_tr_mul(&self, y: &Vector4<f64>) -> Vector2<f64> {
        match self {
            Self::Bicycle { bv, bphi, .. } => Vector2::new(bv * y[1], bphi * y[3]),
            Self::Dense { b, .. } => b.tr_mul(y),
        }
    }

    /// `X A`.
    #[inline(always)]
    pub fn right_a(&self, x: &Matrix4<f64>) -> Matrix4<f64> {
        match self {
            Self::Bicycle { ds, dl, .. } => {
                let mut out = *x;
                out.set_column(1, &(x.column(1) + x.column(0) * *ds));
                out.set_column(3, &(x.column(3) + x.column(2) * *dl));
                out
            }
            Self::Dense { a, .. } => x * a,
        }
    }

    /// `X B`.
    #[inline(always)]
    pub fn right_b(&self, x: &Matrix4<f64>) -> Matrix4x2<f64> {
        match self {
            Self::Bicycle { bv, bphi, .. } => {
                Matrix4x2::from_columns(&[x.column(1) * *bv, x.column(3) * *bphi])
            }
            Self::Dense { b, .. } => x * b,
        }
    }

    /// `Aᵀ X`.
    #[inline(always)]
    pub fn a_tr_left<const C: usize>(&self, x: &SMatrix<f64, 4, C>) -> SMatrix<f64, 4, C> {
        match self {
            Self::Bicycle { ds, dl, .. } => {
                let mut out = *x;
                out.set_row(1, &(x.row(1) + x.row(0) * *ds));
                out.set_row(3, &(x.row(3) + x.row(2) * *dl));
                out
            }
            Self::Dense { a, .. } => a.tr_mul(x),
        }
    }

    /// `Bᵀ X`.
    #[inline(always)]
    pub fn b_tr_left<const C: usize>(&self, x: &SMatrix<f64, 4, C>) -> SMatrix<f64, 2, C> {
        match self {
            Self::Bicycle { bv, bphi, .. } => {
                SMatrix::<f64, 2, C>::from_rows(&[x.row(1) * *bv, x.row(3) * *bphi])
            }
            Self::Dense { b, .. } => b.tr_mul(x),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn matrix<const R: usize, const C: usize>(v: &[f64]) -> SMatrix<f64, R, C> {
        SMatrix::<f64, R, C>::from_iterator(v.iter().copied())
    }

    proptest! {
        /// The bicycle products agree with dense products of the same matrices, and a
        /// perturbed pattern falls back to the dense form.
        #[test]
        fn bicycle_products_match_dense_products(
            (ds, dl, bv, bphi) in (-1.0..1.0f64, -3.0..3.0f64, -1.0..1.0f64, -2.0..2.0f64),
            x in prop::collection::vec(-10.0..10.0f64, 16),
            y in prop::collection::vec(-10.0..10.0f64, 4),
            u in prop::collection::vec(-10.0..10.0f64, 2),
            extra in 0usize..16,
        ) {
            let bicycle = StepDynamics::Bicycle { ds, dl, bv, bphi };
            let (a, b) = bicycle.dense();
            let recognised = matches!(StepDynamics::new(&a, &b), StepDynamics::Bicycle { .. });
            prop_assert!(recognised);
            let dense = StepDynamics::Dense { a, b };
            let (xm, ym, um) = (matrix::<4, 4>(&x), matrix::<4, 1>(&y), matrix::<2, 1>(&u));
            let close = |p: &[f64], q: &[f64]| p.iter().zip(q).all(|(p, q)| (p - q).abs() <= 1e-12 * (1.0 + q.abs()));
            for s in [&bicycle, &dense] {
                prop_assert!(close(s.a_mul(&ym).as_slice(), (a * ym).as_slice()));
                prop_assert!(close(s.b_mul(&um).as_slice(), (b * um).as_slice()));
                prop_assert!(close(s.a_tr_mul(&ym).as_slice(), a.tr_mul(&ym).as_slice()));
                prop_assert!(close(s.b_tr_mul(&ym).as_slice(), b.tr_mul(&ym).as_slice()));
                prop_assert!(close(s.right_a(&xm).as_slice(), (xm * a).as_slice()));
                prop_assert!(close(s.right_b(&xm).as_slice(), (xm * b).as_slice()));
                prop_assert!(close(s.a_tr_left(&xm).as_slice(), a.tr_mul(&xm).as_slice()));
                prop_assert!(close(s.b_tr_left(&xm).as_slice(), b.tr_mul(&xm).as_slice()));
            }
            // An entry outside the pattern (not (0, 1), (2, 3) or an identity entry moved
            // back to 1) forces the dense form.
            let (r, c) = (extra / 4, extra % 4);
            prop_assume!((r, c) != (0, 1) && (r, c) != (2, 3));
            let mut other = a;
            other[(r, c)] += 0.5;
            let dense_fallback = matches!(StepDynamics::new(&other, &b), StepDynamics::Dense { .. });
            prop_assert!(dense_fallback);
        }
    }
}
