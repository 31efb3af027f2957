//! The dynamics of one step of the stage QP (Eqs. 11-14), and products with its
//! matrices that exploit the kinematic bicycle's pattern.
//!
//! Eqs. 11-14 give `A_i = I + N_i` with two entries in `N_i` (`s ← v` and `l ← φ`) and
//! two in `B_i` (`v ← a` and `φ ← δ`): the dense 4 x 4 products of the Riccati recursion
//! would spend most of their work on zeros. The assembly ([`StageQp`](crate::qp::StageQp))
//! builds every step in this pattern, so a step is stored as its four entries (32 bytes
//! instead of the 192 of dense `A`, `B`: one step's dynamics with its offset fills one
//! cache line), and every product below works on them with fixed positions; a property
//! test holds each product to the dense one.
//!
//! The types live below both the assembly (`qp.rs`) and the Riccati backend
//! (`riccati/`), which read them; neither imports the other's for them.

use nalgebra::{Matrix4, Matrix4x2, SMatrix, Vector2, Vector4};

/// `X_{i+1} = A X_i + B U_i + c` (Eqs. 11-14); `sparse` holds `A` and `B` in the
/// cheapest exact form for the products of the recursion.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Dynamics {
    pub c: Vector4<f64>,
    pub sparse: StepDynamics,
}

/// The dynamics matrices of one step,
/// `A = I + ds e_s e_vᵀ + dl e_l e_φᵀ`, `B = bv e_v e_aᵀ + bphi e_φ e_δᵀ`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct StepDynamics {
    /// `A[s, v]`: `dt`.
    pub ds: f64,
    /// `A[l, φ]`: `dt v_ref`.
    pub dl: f64,
    /// `B[v, a]`: `dt`.
    pub bv: f64,
    /// `B[φ, δ]`: `dt v_ref / l_fr`.
    pub bphi: f64,
}

impl StepDynamics {
    /// `(A, B)` as dense matrices.
    pub fn dense(&self) -> (Matrix4<f64>, Matrix4x2<f64>) {
        let mut a = Matrix4::identity();
        a[(0, 1)] = self.ds;
        a[(2, 3)] = self.dl;
        let mut b = Matrix4x2::zeros();
        b[(1, 0)] = self.bv;
        b[(3, 1)] = self.bphi;
        (a, b)
    }

    /// `A x`.
    #[inline(always)]
    pub fn a_mul(&self, x: &Vector4<f64>) -> Vector4<f64> {
        Vector4::new(x[0] + self.ds * x[1], x[1], x[2] + self.dl * x[3], x[3])
    }

    /// `B u`.
    #[inline(always)]
    pub fn b_mul(&self, u: &Vector2<f64>) -> Vector4<f64> {
        Vector4::new(0.0, self.bv * u[0], 0.0, self.bphi * u[1])
    }

    /// `Aᵀ y`.
    #[inline(always)]
    pub fn a_tr_mul(&self, y: &Vector4<f64>) -> Vector4<f64> {
        Vector4::new(y[0], y[1] + self.ds * y[0], y[2], y[3] + self.dl * y[2])
    }

    /// `Bᵀ y`.
    #[inline(always)]
    pub fn b_tr_mul(&self, y: &Vector4<f64>) -> Vector2<f64> {
        Vector2::new(self.bv * y[1], self.bphi * y[3])
    }

    /// `X A`.
    #[inline(always)]
    pub fn right_a(&self, x: &Matrix4<f64>) -> Matrix4<f64> {
        let mut out = *x;
        out.set_column(1, &(x.column(1) + x.column(0) * self.ds));
        out.set_column(3, &(x.column(3) + x.column(2) * self.dl));
        out
    }

    /// `Aᵀ X`.
    #[inline(always)]
    pub fn a_tr_left<const C: usize>(&self, x: &SMatrix<f64, 4, C>) -> SMatrix<f64, 4, C> {
        let mut out = *x;
        out.set_row(1, &(x.row(1) + x.row(0) * self.ds));
        out.set_row(3, &(x.row(3) + x.row(2) * self.dl));
        out
    }

    /// `Bᵀ X`.
    #[inline(always)]
    pub fn b_tr_left<const C: usize>(&self, x: &SMatrix<f64, 4, C>) -> SMatrix<f64, 2, C> {
        SMatrix::<f64, 2, C>::from_rows(&[x.row(1) * self.bv, x.row(3) * self.bphi])
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
        /// Every product agrees with the dense product of the same matrices.
        #[test]
        fn bicycle_products_match_dense_products(
            (ds, dl, bv, bphi) in (-1.0..1.0f64, -3.0..3.0f64, -1.0..1.0f64, -2.0..2.0f64),
            x in prop::collection::vec(-10.0..10.0f64, 16),
            y in prop::collection::vec(-10.0..10.0f64, 4),
            u in prop::collection::vec(-10.0..10.0f64, 2),
        ) {
            let s = StepDynamics { ds, dl, bv, bphi };
            let (a, b) = s.dense();
            let (xm, ym, um) = (matrix::<4, 4>(&x), matrix::<4, 1>(&y), matrix::<2, 1>(&u));
            let close = |p: &[f64], q: &[f64]| p.iter().zip(q).all(|(p, q)| (p - q).abs() <= 1e-12 * (1.0 + q.abs()));
            prop_assert!(close(s.a_mul(&ym).as_slice(), (a * ym).as_slice()));
            prop_assert!(close(s.b_mul(&um).as_slice(), (b * um).as_slice()));
            prop_assert!(close(s.a_tr_mul(&ym).as_slice(), a.tr_mul(&ym).as_slice()));
            prop_assert!(close(s.b_tr_mul(&ym).as_slice(), b.tr_mul(&ym).as_slice()));
            prop_assert!(close(s.right_a(&xm).as_slice(), (xm * a).as_slice()));
            prop_assert!(close(s.a_tr_left(&xm).as_slice(), a.tr_mul(&xm).as_slice()));
            prop_assert!(close(s.b_tr_left(&xm).as_slice(), b.tr_mul(&xm).as_slice()));
        }
    }
}
