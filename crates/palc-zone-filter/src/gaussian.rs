//! Regularized covariances and the fitted discriminants (Eqs. 2-8).

use faer::{Mat, Side, linalg::solvers::DenseSolveCore};

use crate::{error::ZoneError, features::MAX_FEATURES};

/// A variance below this fraction of the feature's total variance counts as
/// zero: the feature is constant within the classes.
const CONSTANT_FEATURE_RATIO: f64 = 1e-12;

/// The inverse and log-determinant of a regularized covariance.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Precision {
    /// Row-major `d x d` inverse of `Sigma_reg`.
    pub matrix: Vec<f64>,
    /// `ln |Sigma_reg|`.
    pub log_det: f64,
}

/// Inverts `Sigma_reg = D (R + ridge I) D` with `R = D^-1 Sigma D^-1`.
///
/// `D` holds per-feature scales: the square root of the feature's variance in
/// `covariance`, or, for a feature constant within the classes, the square
/// root of its total variance `total_variance` (1 if that is zero too).
/// Standardizing first makes the ridge scale-free and keeps metres next to
/// tenths of metres well conditioned (NOTES.md, "Feature conditioning").
pub(crate) fn regularized_precision(
    covariance: &[f64],
    total_variance: &[f64],
    ridge: f64,
    which: &'static str,
) -> Result<Precision, ZoneError> {
    let d = total_variance.len();
    let scales: Vec<f64> = (0..d)
        .map(|j| {
            let within = covariance[j * d + j];
            let total = total_variance[j];
            if within > 0.0 && within > CONSTANT_FEATURE_RATIO * total {
                within.sqrt()
            } else if total > 0.0 {
                total.sqrt()
            } else {
                1.0
            }
        })
        .collect();
    let standardized = Mat::from_fn(d, d, |r, c| {
        let value = covariance[r * d + c] / (scales[r] * scales[c]);
        if r == c { value + ridge } else { value }
    });
    let singular = || ZoneError::SingularCovariance { which, ridge };
    let llt = standardized.llt(Side::Lower).map_err(|_| singular())?;
    let factor = llt.L();
    let mut log_det = 0.0;
    for j in 0..d {
        let pivot = factor[(j, j)];
        if !(pivot.is_finite() && pivot > 0.0) {
            return Err(singular());
        }
        log_det += 2.0 * pivot.ln() + 2.0 * scales[j].ln();
    }
    let inverse = llt.inverse();
    let mut matrix = vec![0.0; d * d];
    for r in 0..d {
        for c in 0..d {
            matrix[r * d + c] = inverse[(r, c)] / (scales[r] * scales[c]);
        }
    }
    if matrix.iter().any(|v| !v.is_finite()) || !log_det.is_finite() {
        return Err(singular());
    }
    Ok(Precision { matrix, log_det })
}

/// A fitted discriminant: what the log-odds `ln p(y=1|x) - ln p(y=0|x)` needs.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Fitted {
    /// Shared covariance (Eq. 8): `a(x) = w . (x - m) + ln(theta / (1 - theta))`,
    /// with `w = Sigma^-1 (mu_1 - mu_0)` and `m = (mu_0 + mu_1) / 2`.
    Linear {
        weights: Vec<f64>,
        midpoint: Vec<f64>,
        log_prior_ratio: f64,
    },
    /// Per-class covariance: the difference of the two Gaussian log-densities (Eq. 3)
    /// plus the log prior ratio (Eq. 4).
    Quadratic {
        safe_mean: Vec<f64>,
        safe: Precision,
        unsafe_mean: Vec<f64>,
        unsafe_: Precision,
        log_prior_ratio: f64,
    },
}

impl Fitted {
    /// The log-odds of the safe class at `x` (no checks; `x.len() == d`).
    #[inline]
    pub(crate) fn log_odds(&self, x: &[f64]) -> f64 {
        match self {
            Fitted::Linear {
                weights,
                midpoint,
                log_prior_ratio,
            } => {
                let mut a = *log_prior_ratio;
                for j in 0..x.len() {
                    a += weights[j] * (x[j] - midpoint[j]);
                }
                a
            }
            Fitted::Quadratic {
                safe_mean,
                safe,
                unsafe_mean,
                unsafe_,
                log_prior_ratio,
            } => {
                let q_safe = mahalanobis(x, safe_mean, &safe.matrix);
                let q_unsafe = mahalanobis(x, unsafe_mean, &unsafe_.matrix);
                log_prior_ratio - 0.5 * (safe.log_det - unsafe_.log_det) - 0.5 * (q_safe - q_unsafe)
            }
        }
    }
}

/// `(x - mu)^T P (x - mu)` for a row-major symmetric `P`.
#[inline]
fn mahalanobis(x: &[f64], mean: &[f64], precision: &[f64]) -> f64 {
    let d = x.len();
    let mut delta = [0.0; MAX_FEATURES];
    for j in 0..d {
        delta[j] = x[j] - mean[j];
    }
    let mut q = 0.0;
    for r in 0..d {
        let mut row = 0.0;
        for c in 0..d {
            row += precision[r * d + c] * delta[c];
        }
        q += delta[r] * row;
    }
    q
}

/// `p(y=1|x)` from the log-odds, without overflow for any `a` (Eq. 2).
#[inline]
pub(crate) fn logistic(a: f64) -> f64 {
    if a >= 0.0 {
        1.0 / (1.0 + (-a).exp())
    } else {
        let e = a.exp();
        e / (1.0 + e)
    }
}
