//! Covariances, their pseudo-inverses and the fitted discriminants (Eqs. 2-8).
//!
//! # The inverse of a shared covariance
//!
//! Eq. (8) needs `Sigma^-1 (mu_1 - mu_0)`. The paper's features make `Sigma`
//! badly conditioned (dist = hypot(ds, dl) is almost `|ds|` while `|ds| >> |dl|`,
//! dl_p and dl_a are both `const - l`), and a feature can be constant in both
//! classes (dl_p when the ego never moves laterally), so `Sigma` can be
//! exactly singular. The rule, in four steps:
//!
//! 1. **Standardize**: `R = D^-1 Sigma D^-1` with `D` the per-feature within-class
//!    standard deviations, so the rule below is scale-free (NOTES.md,
//!    "Feature conditioning").
//! 2. **Drop zero-variance features**: a feature whose within-class variance is at
//!    most [`CONSTANT_FEATURE_RATIO`] of its total variance (or zero) is constant
//!    within the classes; its row and column are removed and it gets weight 0.
//! 3. **Pseudo-inverse**: the symmetric eigendecomposition `R + ridge I = U L U^T`
//!    of the kept block (faer); eigenvalues at most [`EIGEN_CUT`] times
//!    `d lambda_max` count as zero, which is the rank rule of numpy's `lstsq`
//!    and scikit-learn's `lsqr`/`svd` LDA solvers, and the inverse is
//!    `U L^+ U^T`. No direction that the data resolve is damped.
//! 4. **Refine**: the weights `w` are refined twice, `w += Sigma_reg^+ r` with the
//!    residual `r = (mu_1 - mu_0) - Sigma_reg w` accumulated in compensated
//!    (double-double) arithmetic against the unstandardized `Sigma_reg`. The
//!    eigenvalues of `R` carry an absolute error of about `eps lambda_max`, so
//!    one solve alone is only accurate to `cond(R) eps` (1e-4 at a condition
//!    number of 1e12); each refinement step multiplies that error by
//!    `cond(R) eps`.
//!
//! `ridge` (default 0) adds `ridge I` to `R` before step 3: with 0 the model is
//! the maximum-likelihood one (and exactly affine invariant); a positive ridge
//! is a deliberate shrinkage that damps every direction whose standardized
//! variance is not large against it, including those that separate the classes.
//!
//! The per-class covariances of [`crate::Discriminant::Quadratic`] use steps 1-3 and
//! the pseudo-determinant (the product of the kept eigenvalues times `D^2`), so
//! the Gaussian of a class lives on the subspace its samples span.

use faer::{Mat, Side};

use crate::{error::ZoneError, features::MAX_FEATURES};

/// A within-class variance at or below this fraction of the feature's total
/// variance counts as zero: the feature is constant within the classes (its
/// within-class standard deviation is a millionth of its spread).
const CONSTANT_FEATURE_RATIO: f64 = 1e-12;

/// Eigenvalues of the standardized covariance at or below
/// `EIGEN_CUT * d * lambda_max` are treated as zero. The eigenvalues of an
/// exactly singular `R` come out of a backward-stable solver at a few
/// `eps lambda_max`; `8 eps` per dimension covers them with margin while
/// keeping every direction of a condition number up to 1e12 / (8 d eps) > 1e13
/// at `d = 6`.
const EIGEN_CUT: f64 = 8.0 * f64::EPSILON;

/// Refinement steps of the linear weights (each multiplies the error by about
/// `cond(R) eps`, so two bring a condition number of 1e12 to rounding).
const REFINEMENT_STEPS: usize = 2;

/// The spectral form of a regularized covariance in standardized coordinates.
#[derive(Debug, Clone)]
struct Spectrum {
    /// Per-feature scales `D`.
    scales: Vec<f64>,
    /// The kept features (non-zero within-class variance), in order.
    kept: Vec<usize>,
    /// Eigenvectors of the kept block, column-major `kept x rank` (only the
    /// retained eigenvalues' columns).
    vectors: Vec<f64>,
    /// The retained eigenvalues of `R + ridge I` on the kept block.
    values: Vec<f64>,
    /// The ridge, which is the standardized variance of a dropped feature.
    ridge: f64,
}

impl Spectrum {
    /// Steps 1-3 of the module doc for `covariance` (row-major `d x d`).
    fn new(
        covariance: &[f64],
        total_variance: &[f64],
        ridge: f64,
        which: &'static str,
    ) -> Result<Spectrum, ZoneError> {
        let d = total_variance.len();
        let mut scales = Vec::with_capacity(d);
        let mut kept = Vec::with_capacity(d);
        for j in 0..d {
            let within = covariance[j * d + j];
            let total = total_variance[j];
            if within > 0.0 && within > CONSTANT_FEATURE_RATIO * total {
                scales.push(within.sqrt());
                kept.push(j);
            } else if total > 0.0 {
                scales.push(total.sqrt());
            } else {
                scales.push(1.0);
            }
        }
        let k = kept.len();
        let block = Mat::from_fn(k, k, |r, c| {
            let (i, j) = (kept[r], kept[c]);
            let value = covariance[i * d + j] / (scales[i] * scales[j]);
            if r == c { value + ridge } else { value }
        });
        let mut vectors = Vec::with_capacity(k * k);
        let mut values = Vec::with_capacity(k);
        if k > 0 {
            let eigen = block
                .self_adjoint_eigen(Side::Lower)
                .map_err(|_| ZoneError::SingularCovariance { which, ridge })?;
            let (u, s) = (eigen.U(), eigen.S().column_vector());
            let largest = (0..k).map(|i| s[i]).fold(0.0_f64, f64::max);
            let cut = EIGEN_CUT * k as f64 * largest;
            for i in 0..k {
                if s[i] > cut {
                    values.push(s[i]);
                    vectors.extend((0..k).map(|r| u[(r, i)]));
                }
            }
        }
        let spectrum = Spectrum {
            scales,
            kept,
            vectors,
            values,
            ridge,
        };
        if spectrum
            .values
            .iter()
            .chain(&spectrum.vectors)
            .any(|v| !v.is_finite())
        {
            return Err(ZoneError::SingularCovariance { which, ridge });
        }
        Ok(spectrum)
    }

    /// `out = Sigma_reg^+ rhs` (no allocation beyond a stack buffer).
    fn solve(&self, rhs: &[f64], out: &mut [f64]) {
        let d = self.scales.len();
        let k = self.kept.len();
        let mut kept_mask = [false; MAX_FEATURES];
        for &j in &self.kept {
            kept_mask[j] = true;
        }
        for j in 0..d {
            out[j] = if !kept_mask[j] && self.ridge > 0.0 {
                rhs[j] / (self.ridge * self.scales[j] * self.scales[j])
            } else {
                0.0
            };
        }
        // Standardized right-hand side of the kept block.
        let mut z = [0.0; MAX_FEATURES];
        for (r, &j) in self.kept.iter().enumerate() {
            z[r] = rhs[j] / self.scales[j];
        }
        for (i, &lambda) in self.values.iter().enumerate() {
            let u = &self.vectors[i * k..(i + 1) * k];
            let coefficient: f64 = u.iter().zip(&z[..k]).map(|(a, b)| a * b).sum::<f64>() / lambda;
            for (r, &j) in self.kept.iter().enumerate() {
                out[j] += coefficient * u[r] / self.scales[j];
            }
        }
    }

    /// The row-major pseudo-inverse and pseudo-log-determinant of `Sigma_reg`.
    fn precision(&self) -> Precision {
        let d = self.scales.len();
        let mut matrix = vec![0.0; d * d];
        let mut unit = [0.0; MAX_FEATURES];
        let mut column = [0.0; MAX_FEATURES];
        for c in 0..d {
            unit[c] = 1.0;
            self.solve(&unit[..d], &mut column[..d]);
            unit[c] = 0.0;
            for r in 0..d {
                matrix[r * d + c] = column[r];
            }
        }
        // Symmetrize the rounding of the column-by-column build.
        for r in 0..d {
            for c in 0..r {
                let mean = 0.5 * (matrix[r * d + c] + matrix[c * d + r]);
                matrix[r * d + c] = mean;
                matrix[c * d + r] = mean;
            }
        }
        let mut log_det: f64 = self.values.iter().map(|v| v.ln()).sum();
        for j in 0..d {
            if self.kept.contains(&j) {
                log_det += 2.0 * self.scales[j].ln();
            } else if self.ridge > 0.0 {
                log_det += self.ridge.ln() + 2.0 * self.scales[j].ln();
            }
        }
        Precision { matrix, log_det }
    }

    /// `Sigma_reg` itself, row-major: the covariance with `ridge D^2` on the
    /// diagonal and the rows and columns of dropped features replaced by
    /// `ridge D^2` on the diagonal alone.
    fn regularized(&self, covariance: &[f64]) -> Vec<f64> {
        let d = self.scales.len();
        let mut kept_mask = [false; MAX_FEATURES];
        for &j in &self.kept {
            kept_mask[j] = true;
        }
        let mut out = vec![0.0; d * d];
        for r in 0..d {
            for c in 0..d {
                if kept_mask[r] && kept_mask[c] {
                    out[r * d + c] = covariance[r * d + c];
                }
            }
            out[r * d + r] += self.ridge * self.scales[r] * self.scales[r];
        }
        out
    }
}

/// The pseudo-inverse and pseudo-log-determinant of a regularized covariance.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Precision {
    /// Row-major `d x d` pseudo-inverse of `Sigma_reg`.
    pub matrix: Vec<f64>,
    /// `ln` of the pseudo-determinant of `Sigma_reg`.
    pub log_det: f64,
}

/// The pseudo-inverse of `Sigma_reg` (steps 1-3 of the module doc), for the
/// per-class covariances of the quadratic discriminant.
///
/// `total_variance` holds each feature's variance over both classes; it scales
/// a feature that is constant within the classes.
///
/// # Errors
/// [`ZoneError::SingularCovariance`] if the eigendecomposition does not
/// converge or gives non-finite values.
pub(crate) fn regularized_precision(
    covariance: &[f64],
    total_variance: &[f64],
    ridge: f64,
    which: &'static str,
) -> Result<Precision, ZoneError> {
    Ok(Spectrum::new(covariance, total_variance, ridge, which)?.precision())
}

/// The weights `w = Sigma_reg^+ (mu_1 - mu_0)` of the shared-covariance
/// discriminant (Eq. 8), by all four steps of the module doc.
///
/// # Errors
/// As [`regularized_precision`].
pub(crate) fn linear_weights(
    covariance: &[f64],
    total_variance: &[f64],
    mean_gap: &[f64],
    ridge: f64,
) -> Result<Vec<f64>, ZoneError> {
    let d = mean_gap.len();
    let spectrum = Spectrum::new(covariance, total_variance, ridge, "shared")?;
    let regularized = spectrum.regularized(covariance);
    let mut weights = vec![0.0; d];
    spectrum.solve(mean_gap, &mut weights);
    let mut residual = [0.0; MAX_FEATURES];
    let mut correction = [0.0; MAX_FEATURES];
    for _ in 0..REFINEMENT_STEPS {
        for r in 0..d {
            residual[r] =
                compensated_residual(mean_gap[r], &regularized[r * d..(r + 1) * d], &weights);
        }
        spectrum.solve(&residual[..d], &mut correction[..d]);
        for (w, c) in weights.iter_mut().zip(&correction) {
            *w += c;
        }
    }
    if weights.iter().any(|w| !w.is_finite()) {
        return Err(ZoneError::SingularCovariance {
            which: "shared",
            ridge,
        });
    }
    Ok(weights)
}

/// `b - a . w` in compensated arithmetic (Ogita, Rump and Oishi's `Dot2`):
/// as accurate as if computed in twice the working precision, then rounded.
fn compensated_residual(b: f64, a: &[f64], w: &[f64]) -> f64 {
    let (mut sum, mut error) = (b, 0.0);
    for (&x, &y) in a.iter().zip(w) {
        let product = x * y;
        let product_error = x.mul_add(y, -product);
        // Two-sum of `sum` and `-product`.
        let t = sum - product;
        let z = t - sum;
        error += (sum - (t - z)) + (-product - z) - product_error;
        sum = t;
    }
    sum + error
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
