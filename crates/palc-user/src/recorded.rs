//! A lane-change shape recorded from a driver: noisy samples of the lateral
//! position, smoothed into the lane change the user will drive.
//!
//! Recorded trajectories (NGSIM, highD, a driving simulator) sample the lateral
//! position at 10–25 Hz with centimetre-to-decimetre noise. Differentiated
//! twice, that noise alone makes tens of m/s² of lateral acceleration, so the
//! sanity checks of a user cannot be applied to the samples themselves. The
//! recorded profile therefore drives a **fit** and is checked on the fit.
//!
//! # The fit
//! The lateral position over the normalized time `τ = t / T ∈ [0, 1]` (`T` the
//! last sample's time) is a Bernstein polynomial of degree [`DEGREE`],
//! `l(τ) = Σ c_k B_k(τ)`, with
//! - `c_0 = c_1 = c_2` and `c_{n−2} = c_{n−1} = c_n`: zero lateral speed and
//!   acceleration at both ends, as a lane change between two lane centres;
//! - `c_{k+1} ≥ c_k`: monotone towards the target lane (sufficient for a
//!   monotone `l`, Farouki 2012), so noise never becomes a back-and-forth;
//! - the smallest roughness `∫ l''(τ)² dτ` among such curves whose root mean
//!   square distance to the samples is the stated noise level `σ`
//!   (`noise_m`): Morozov's discrepancy principle. The weight of the roughness
//!   is found by bisection on its logarithm, each step a small convex QP
//!   solved by clarabel. Data closer to a monotone curve than `σ` is smoothed
//!   until it is `σ` away; data farther away is fitted as closely as the
//!   constraints allow, and the residual says so.
//!
//! The user's progress is `p(τ) = (l(τ) − c_0) / (c_n − c_0)`: a shape from 0 to
//! 1 that the user stretches over its lane-change duration and the scene's lane
//! width, as the analytic shapes. The fit reports its residual (root mean square
//! and the largest, with its sample); a sample farther than
//! [`OUTLIER_NOISE_FACTOR`] times `σ` from the fit is refused, naming the sample:
//! an outlier or a lane change that turns back is not a shape to learn.

use std::sync::OnceLock;

use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, SolverStatus, SupportedConeT};
use serde::{Deserialize, Serialize};

use crate::UserError;
use crate::point::ProfilePoint;

/// Degree of the Bernstein polynomial. Seventeen coefficients follow a gradual
/// onset and an asymmetric end; with the roughness weight chosen from the noise,
/// a short lane change of ten samples is not over-fitted.
pub const DEGREE: usize = 16;
/// Fewest samples of a recorded profile: fewer cannot tell a shape from noise.
pub const MIN_SAMPLES: usize = 5;
/// Most samples of a recorded profile: a minute at 100 Hz.
pub const MAX_SAMPLES: usize = 6_000;
/// Bounds of the stated noise level (m): from survey-grade tracking to the
/// decimetres of video-based trajectories such as NGSIM's.
pub const NOISE_BOUNDS_M: (f64, f64) = (0.001, 0.5);
/// The noise level when none is stated (m): the order of the lateral position
/// errors of video-extracted trajectories (Punzo et al., 2011, on NGSIM).
pub const DEFAULT_NOISE_M: f64 = 0.1;
/// Smallest lateral move of a recording (m): less is lane keeping, not a lane change.
pub const MIN_MOVE_M: f64 = 1.0;
/// A sample farther than this many noise levels from the fit is refused: for
/// Gaussian noise of the stated level, one in 1.7 million samples.
pub const OUTLIER_NOISE_FACTOR: f64 = 5.0;
/// Bisection range of the roughness weight's decimal logarithm: at the low end
/// the fit interpolates as closely as its degree allows, at the high end it is
/// the smoothest monotone curve between the two plateaus.
const LOG_WEIGHT_RANGE: (f64, f64) = (-12.0, 2.0);
/// Bisection steps: the weight to within a factor of 10^(14 / 2^40), far below
/// any visible change of the fit.
const BISECTION_STEPS: usize = 40;
/// Midpoints of the quadrature of the roughness integral.
const QUADRATURE_POINTS: usize = 200;

/// A recorded lane change's lateral samples and the noise level they carry.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RecordedProfile {
    /// `(time since the start, lateral offset towards the target lane)` samples;
    /// times strictly increasing from 0, offsets in metres from any origin.
    pub samples: Vec<ProfilePoint>,
    /// Standard deviation of the samples' noise (m), in [`NOISE_BOUNDS_M`].
    #[serde(default = "RecordedProfile::default_noise_m")]
    pub noise_m: f64,
    #[serde(skip)]
    fit: OnceLock<Result<RecordedFit, InvalidField>>,
}

/// A field out of bound, its path relative to the profile's table (kept by the
/// cached fit, and named in full when it is reported).
#[derive(Debug, Clone, PartialEq)]
struct InvalidField {
    /// The path below the profile's table, e.g. `samples[3].offset_m`.
    field: String,
    value: f64,
    bound: String,
}

impl InvalidField {
    fn under(&self, table: &str) -> UserError {
        UserError::InvalidConfig {
            field: format!("{table}.{}", self.field),
            value: self.value,
            bound: self.bound.clone(),
        }
    }
}

/// The smoothed lane change and how far the samples are from it.
#[derive(Debug, Clone, PartialEq)]
pub struct RecordedFit {
    /// Bernstein coefficients of `l(τ)` (m).
    pub coefficients: Vec<f64>,
    /// Root mean square distance between the samples and the fit (m).
    pub rms_residual_m: f64,
    /// Largest distance between a sample and the fit (m).
    pub max_residual_m: f64,
    /// Index of that sample.
    pub max_residual_sample: usize,
}

impl RecordedProfile {
    fn default_noise_m() -> f64 {
        DEFAULT_NOISE_M
    }

    /// A recorded profile of `samples` with noise level `noise_m`; checked and
    /// fitted on first use ([`RecordedProfile::fit`]).
    pub fn new(samples: Vec<ProfilePoint>, noise_m: f64) -> Self {
        RecordedProfile {
            samples,
            noise_m,
            fit: OnceLock::new(),
        }
    }

    /// The fit, computed once; errors name the field under `table` that is out of bound.
    pub fn fit(&self, table: &str) -> Result<&RecordedFit, UserError> {
        self.fit
            .get_or_init(|| fit_samples(&self.samples, self.noise_m))
            .as_ref()
            .map_err(|error| error.under(table))
    }

    /// Normalized progress `p(τ) ∈ [0, 1]` of the fit; 0 throughout when the
    /// samples cannot be fitted (validation, [`RecordedProfile::fit`], says why;
    /// the user's sanity checks then refuse a lane change that never moves).
    pub fn progress(&self, tau: f64) -> f64 {
        let Ok(fit) = self
            .fit
            .get_or_init(|| fit_samples(&self.samples, self.noise_m))
        else {
            return 0.0;
        };
        let c = &fit.coefficients;
        let (first, last) = (c[0], c[c.len() - 1]);
        let span = last - first;
        if span <= 0.0 {
            return 0.0;
        }
        ((bernstein_value(c, tau.clamp(0.0, 1.0)) - first) / span).clamp(0.0, 1.0)
    }
}

impl Clone for RecordedProfile {
    fn clone(&self) -> Self {
        RecordedProfile {
            samples: self.samples.clone(),
            noise_m: self.noise_m,
            fit: self.fit.clone(),
        }
    }
}

impl PartialEq for RecordedProfile {
    fn eq(&self, other: &Self) -> bool {
        self.samples == other.samples && self.noise_m == other.noise_m
    }
}

impl std::fmt::Debug for RecordedProfile {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RecordedProfile")
            .field("samples", &self.samples.len())
            .field("noise_m", &self.noise_m)
            .finish()
    }
}

/// Checks the samples and fits them; see the module documentation.
fn fit_samples(samples: &[ProfilePoint], noise_m: f64) -> Result<RecordedFit, InvalidField> {
    check_samples(samples, noise_m)?;
    let duration = samples[samples.len() - 1].time_s;
    let taus: Vec<f64> = samples.iter().map(|p| p.time_s / duration).collect();
    let offsets: Vec<f64> = samples.iter().map(|p| p.offset_m).collect();
    let problem = FitProblem::new(&taus, &offsets);
    let rms_at = |log_weight: f64| -> Result<(Vec<f64>, f64), InvalidField> {
        let c = problem.solve(10f64.powf(log_weight))?;
        let rms = problem.rms_residual(&c);
        Ok((c, rms))
    };
    let (low, high) = LOG_WEIGHT_RANGE;
    let (mut best, rms_low) = rms_at(low)?;
    if rms_low < noise_m {
        // The residual grows with the weight: find where it reaches the noise level.
        let (mut lo, mut hi) = (low, high);
        for _ in 0..BISECTION_STEPS {
            let mid = 0.5 * (lo + hi);
            let (c, rms) = rms_at(mid)?;
            if rms <= noise_m {
                best = c;
                lo = mid;
            } else {
                hi = mid;
            }
        }
    }
    let residuals: Vec<f64> = taus
        .iter()
        .zip(&offsets)
        .map(|(&tau, &y)| (y - bernstein_value(&best, tau)).abs())
        .collect();
    let (max_residual_sample, max_residual_m) = residuals
        .iter()
        .copied()
        .enumerate()
        .fold((0, 0.0), |m, (i, r)| if r > m.1 { (i, r) } else { m });
    let bound = OUTLIER_NOISE_FACTOR * noise_m;
    if max_residual_m > bound {
        let fitted = bernstein_value(&best, taus[max_residual_sample]);
        return Err(InvalidField {
            field: format!("samples[{max_residual_sample}].offset_m"),
            value: offsets[max_residual_sample],
            bound: format!(
                "within {OUTLIER_NOISE_FACTOR} × noise_m = {bound:.3} m of the smoothed monotone \
                 lane change ({fitted:.3} m at t = {:.2} s): an outlier, or a lane change that \
                 turns back",
                samples[max_residual_sample].time_s
            ),
        });
    }
    Ok(RecordedFit {
        rms_residual_m: problem.rms_residual(&best),
        coefficients: best,
        max_residual_m,
        max_residual_sample,
    })
}

/// The structural checks: count, finite values, times from 0 and increasing, a
/// move of at least [`MIN_MOVE_M`] towards the target, the noise level in bounds.
fn check_samples(samples: &[ProfilePoint], noise_m: f64) -> Result<(), InvalidField> {
    let invalid = |field: String, value: f64, bound: String| InvalidField {
        field,
        value,
        bound,
    };
    let (low, high) = NOISE_BOUNDS_M;
    if !(noise_m.is_finite() && (low..=high).contains(&noise_m)) {
        return Err(invalid(
            "noise_m".to_owned(),
            noise_m,
            format!("a value in [{low}, {high}] m"),
        ));
    }
    if !(MIN_SAMPLES..=MAX_SAMPLES).contains(&samples.len()) {
        return Err(invalid(
            "samples".to_owned(),
            samples.len() as f64,
            format!("between {MIN_SAMPLES} and {MAX_SAMPLES} samples"),
        ));
    }
    for (i, point) in samples.iter().enumerate() {
        if !point.offset_m.is_finite() {
            return Err(invalid(
                format!("samples[{i}].offset_m"),
                point.offset_m,
                "finite".to_owned(),
            ));
        }
        let time_ok = match i {
            0 => point.time_s == 0.0,
            _ => point.time_s.is_finite() && point.time_s > samples[i - 1].time_s,
        };
        if !time_ok {
            let bound = match i {
                0 => "0 (the samples start at the start of the lane change)".to_owned(),
                _ => format!(
                    "finite and greater than the previous sample's {} s",
                    samples[i - 1].time_s
                ),
            };
            return Err(invalid(format!("samples[{i}].time_s"), point.time_s, bound));
        }
    }
    let last = samples.len() - 1;
    let moved = samples[last].offset_m - samples[0].offset_m;
    if moved < MIN_MOVE_M {
        return Err(invalid(
            format!("samples[{last}].offset_m"),
            samples[last].offset_m,
            format!(
                "at least {MIN_MOVE_M} m beyond the first sample's {:.3} m (a lane change moves \
                 towards the target lane)",
                samples[0].offset_m
            ),
        ));
    }
    Ok(())
}

/// The QP of one roughness weight: `min (1/N) |A c − y|² + w cᵀ R c` subject to
/// the flat ends and monotone coefficients.
struct FitProblem {
    /// `(2/N) AᵀA`, dense.
    data_hessian: Vec<Vec<f64>>,
    /// `2 R`, dense.
    roughness_hessian: Vec<Vec<f64>>,
    /// `−(2/N) Aᵀ y`.
    linear: Vec<f64>,
    /// The basis at each sample, `A`.
    basis: Vec<Vec<f64>>,
    offsets: Vec<f64>,
}

impl FitProblem {
    fn new(taus: &[f64], offsets: &[f64]) -> Self {
        let m = DEGREE + 1;
        let n = taus.len() as f64;
        let basis: Vec<Vec<f64>> = taus.iter().map(|&tau| bernstein_basis(tau)).collect();
        let mut data_hessian = vec![vec![0.0; m]; m];
        let mut linear = vec![0.0; m];
        for (row, &y) in basis.iter().zip(offsets) {
            for i in 0..m {
                linear[i] -= 2.0 / n * row[i] * y;
                for j in 0..m {
                    data_hessian[i][j] += 2.0 / n * row[i] * row[j];
                }
            }
        }
        let mut roughness_hessian = vec![vec![0.0; m]; m];
        let h = 1.0 / QUADRATURE_POINTS as f64;
        for q in 0..QUADRATURE_POINTS {
            let g = second_derivative_basis((q as f64 + 0.5) * h);
            for i in 0..m {
                for j in 0..m {
                    roughness_hessian[i][j] += 2.0 * h * g[i] * g[j];
                }
            }
        }
        FitProblem {
            data_hessian,
            roughness_hessian,
            linear,
            basis,
            offsets: offsets.to_vec(),
        }
    }

    fn rms_residual(&self, c: &[f64]) -> f64 {
        let sum: f64 = self
            .basis
            .iter()
            .zip(&self.offsets)
            .map(|(row, y)| {
                let value: f64 = row.iter().zip(c).map(|(b, c)| b * c).sum();
                (value - y).powi(2)
            })
            .sum();
        (sum / self.offsets.len() as f64).sqrt()
    }

    /// The coefficients at roughness weight `weight`.
    fn solve(&self, weight: f64) -> Result<Vec<f64>, InvalidField> {
        let m = DEGREE + 1;
        let hessian: Vec<Vec<f64>> = (0..m)
            .map(|i| {
                (0..m)
                    .map(|j| {
                        let v = self.data_hessian[i][j] + weight * self.roughness_hessian[i][j];
                        if j >= i { v } else { 0.0 }
                    })
                    .collect()
            })
            .collect();
        let p = CscMatrix::from(hessian.iter().map(|r| r.iter()));
        // Equalities (zero cone, A x = b): c0 = c1 = c2 and c_{n−2} = c_{n−1} = c_n.
        // Inequalities (nonnegative cone, b − A x ≥ 0): c_k − c_{k+1} ≤ 0.
        let mut rows: Vec<Vec<f64>> = Vec::new();
        for (a, b) in [(0, 1), (1, 2), (m - 3, m - 2), (m - 2, m - 1)] {
            let mut row = vec![0.0; m];
            row[a] = 1.0;
            row[b] = -1.0;
            rows.push(row);
        }
        for k in 0..m - 1 {
            let mut row = vec![0.0; m];
            row[k] = 1.0;
            row[k + 1] = -1.0;
            rows.push(row);
        }
        let a = CscMatrix::from(rows.iter().map(|r| r.iter()));
        let b = vec![0.0; rows.len()];
        let cones = [
            SupportedConeT::ZeroConeT(4),
            SupportedConeT::NonnegativeConeT(m - 1),
        ];
        let settings = DefaultSettings {
            verbose: false,
            max_threads: 1,
            ..DefaultSettings::default()
        };
        let failed = || InvalidField {
            field: "samples".to_owned(),
            value: f64::NAN,
            bound: "samples the smoothing QP can fit (clarabel found no solution)".to_owned(),
        };
        let mut solver =
            DefaultSolver::new(&p, &self.linear, &a, &b, &cones, settings).map_err(|_| failed())?;
        solver.solve();
        match solver.solution.status {
            SolverStatus::Solved | SolverStatus::AlmostSolved => Ok(solver.solution.x.clone()),
            _ => Err(failed()),
        }
    }
}

/// Binomial coefficient `C(n, k)` as a float (exact for the degrees used here):
/// [`DEGREE_BINOMIALS`] for degree [`DEGREE`], computed otherwise.
fn binomial(n: usize, k: usize) -> f64 {
    if n == DEGREE {
        DEGREE_BINOMIALS[k]
    } else {
        binomial_product(n, k)
    }
}

/// `C(n, k) = Π_{i<k} (n − i) / (i + 1)`, multiplied and divided in that order.
const fn binomial_product(n: usize, k: usize) -> f64 {
    let mut acc = 1.0;
    let mut i = 0;
    while i < k {
        acc = acc * (n - i) as f64 / (i + 1) as f64;
        i += 1;
    }
    acc
}

/// `C(DEGREE, k)` for every `k`, computed once at compile time by
/// [`binomial_product`]: a profile is read at every step, and the coefficients'
/// 136 dependent multiplications and divisions per reading cost more than the
/// basis itself. Compile-time floating-point arithmetic is IEEE's, so the table
/// holds the bits the product gives at run time.
const DEGREE_BINOMIALS: [f64; DEGREE + 1] = {
    let mut row = [0.0; DEGREE + 1];
    let mut k = 0;
    while k <= DEGREE {
        row[k] = binomial_product(DEGREE, k);
        k += 1;
    }
    row
};

/// The Bernstein polynomial `B_k^n(τ) = C(n, k) τ^k (1 − τ)^(n−k)`.
fn bernstein_term(n: usize, k: usize, tau: f64) -> f64 {
    binomial(n, k) * tau.powi(k as i32) * (1.0 - tau).powi((n - k) as i32)
}

/// The Bernstein basis of degree `n` at `τ`.
fn bernstein_basis_of(n: usize, tau: f64) -> Vec<f64> {
    (0..=n).map(|k| bernstein_term(n, k, tau)).collect()
}

/// The Bernstein basis of degree [`DEGREE`] at `τ`.
fn bernstein_basis(tau: f64) -> Vec<f64> {
    bernstein_basis_of(DEGREE, tau)
}

/// `∂ l''(τ) / ∂ c_k` for every `k`: `l'' = n(n−1) Σ Δ²c_k B_k^{n−2}`.
fn second_derivative_basis(tau: f64) -> Vec<f64> {
    let n = DEGREE;
    let lower = bernstein_basis_of(n - 2, tau);
    let scale = (n * (n - 1)) as f64;
    let mut g = vec![0.0; n + 1];
    for (k, b) in lower.iter().enumerate() {
        g[k] += scale * b;
        g[k + 1] -= 2.0 * scale * b;
        g[k + 2] += scale * b;
    }
    g
}

/// `l(τ) = Σ c_k B_k(τ)`.
///
/// The terms of [`bernstein_basis_of`], each times its coefficient, summed in
/// order without collecting the basis (a profile is read at every step).
fn bernstein_value(c: &[f64], tau: f64) -> f64 {
    let n = c.len() - 1;
    (c.iter().enumerate())
        .map(|(k, c)| bernstein_term(n, k, tau) * c)
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::profile::quintic;

    #[test]
    fn the_degrees_binomials_are_the_products_bits_and_exact() {
        let mut exact = 1u64;
        for (k, &table) in DEGREE_BINOMIALS.iter().enumerate() {
            // `std::hint::black_box` keeps the product a run-time computation.
            let product = binomial_product(std::hint::black_box(DEGREE), k);
            assert_eq!(table.to_bits(), product.to_bits(), "C({DEGREE}, {k})");
            assert_eq!(table, exact as f64, "C({DEGREE}, {k})");
            exact = exact * (DEGREE - k) as u64 / (k + 1) as u64;
        }
    }

    /// A deterministic noise of roughly unit variance (a hash, not a generator,
    /// so that the tests need no seed plumbing).
    fn noise(i: usize) -> f64 {
        let x = ((i as f64 + 1.0) * 12.9898).sin() * 43_758.545_3;
        (x - x.floor() - 0.5) * 12f64.sqrt()
    }

    fn quintic_samples(duration: f64, width: f64, rate_hz: f64, sigma: f64) -> Vec<ProfilePoint> {
        let n = (duration * rate_hz).round() as usize;
        (0..=n)
            .map(|i| {
                let t = i as f64 / rate_hz;
                ProfilePoint {
                    time_s: t,
                    offset_m: width * quintic(t / duration) + sigma * noise(i),
                }
            })
            .collect()
    }

    #[test]
    fn a_noisy_quintic_is_smoothed_to_within_its_noise() {
        let samples = quintic_samples(3.0, 3.7, 10.0, 0.05);
        let profile = RecordedProfile::new(samples, 0.05);
        let fit = profile.fit("user.family.profile").unwrap();
        assert!((fit.rms_residual_m - 0.05).abs() < 0.005, "{fit:?}");
        for i in 0..=100 {
            let tau = i as f64 / 100.0;
            let error = profile.progress(tau) - quintic(tau);
            assert!(error.abs() < 0.05, "τ = {tau}: {error}");
        }
    }

    #[test]
    fn the_fit_is_monotone_and_flat_at_both_ends() {
        let profile = RecordedProfile::new(quintic_samples(2.0, 3.5, 25.0, 0.1), 0.1);
        profile.fit("p").unwrap();
        let path: Vec<f64> = (0..=1000)
            .map(|i| profile.progress(i as f64 / 1000.0))
            .collect();
        assert!(path.windows(2).all(|w| w[1] >= w[0] - 1e-9));
        assert!(path[0].abs() < 1e-9 && (path[1000] - 1.0).abs() < 1e-9);
        let h = 1e-3;
        let speed_at_start = (profile.progress(h) - profile.progress(0.0)) / h;
        assert!(speed_at_start.abs() < 1e-3, "{speed_at_start}");
    }

    #[test]
    fn an_outlier_is_refused_naming_its_sample() {
        let mut samples = quintic_samples(3.0, 3.5, 10.0, 0.02);
        samples[12].offset_m += 2.0;
        let error = RecordedProfile::new(samples, 0.05)
            .fit("users.family.profile")
            .unwrap_err()
            .to_string();
        assert!(
            error.contains("users.family.profile.samples[12].offset_m"),
            "{error}"
        );
    }

    #[test]
    fn bad_samples_name_the_field() {
        let point = |time_s, offset_m| ProfilePoint { time_s, offset_m };
        let good = quintic_samples(2.0, 3.5, 10.0, 0.0);
        let mut late_start = good.clone();
        late_start[0].time_s = 0.1;
        let mut nan = good.clone();
        nan[3].offset_m = f64::NAN;
        let mut backwards = good.clone();
        backwards[5].time_s = backwards[4].time_s;
        let flat: Vec<ProfilePoint> = (0..10).map(|i| point(i as f64 * 0.1, 0.0)).collect();
        let cases = [
            (good[..3].to_vec(), 0.1, "p.samples"),
            (late_start, 0.1, "p.samples[0].time_s"),
            (nan, 0.1, "p.samples[3].offset_m"),
            (backwards, 0.1, "p.samples[5].time_s"),
            (flat, 0.1, "p.samples[9].offset_m"),
            (good, 0.0, "p.noise_m"),
        ];
        for (samples, noise, field) in cases {
            let error = RecordedProfile::new(samples, noise)
                .fit("p")
                .unwrap_err()
                .to_string();
            assert!(error.contains(field), "{field}: {error}");
        }
    }
}
