//! The shared-covariance model against the maximum-likelihood LDA computed
//! differently: a Householder QR of the centred data matrix in the test, so
//! that `Sigma^-1 = N R^-1 R^-T` never forms `X^T X` (issue 12, item 1).

mod common;

use common::features_at;
use palc_zone_filter::{FeatureSet, Label, Sample, ZoneConfig, ZoneModel};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Posterior agreement required with the reference.
const TOLERANCE: f64 = 1e-6;

/// The maximum-likelihood shared-covariance LDA of `samples`, fitted by QR.
///
/// Columns that are constant within both classes are left out (their weight
/// is 0), as scikit-learn's `lsqr` and `svd` solvers do.
struct Reference {
    weights: Vec<f64>,
    midpoint: Vec<f64>,
    log_prior_ratio: f64,
    /// `cond(R)^2`, the condition number of the standardized covariance.
    condition: f64,
}

impl Reference {
    fn fit(samples: &[Sample]) -> Reference {
        let d = samples[0].x.len();
        let class_mean = |y: Label| -> (Vec<f64>, f64) {
            let members: Vec<&Sample> = samples.iter().filter(|s| s.y == y).collect();
            let n = members.len() as f64;
            let mean = (0..d)
                .map(|j| members.iter().map(|s| s.x[j]).sum::<f64>() / n)
                .collect();
            (mean, n)
        };
        let (mu1, n1) = class_mean(Label::Safe);
        let (mu0, n0) = class_mean(Label::Unsafe);
        let centred: Vec<Vec<f64>> = (0..d)
            .map(|j| {
                samples
                    .iter()
                    .map(|s| {
                        let mu = if s.y == Label::Safe { &mu1 } else { &mu0 };
                        s.x[j] - mu[j]
                    })
                    .collect()
            })
            .collect();
        let kept: Vec<usize> = (0..d)
            .filter(|&j| centred[j].iter().any(|v| *v != 0.0))
            .collect();
        // Standardize the kept columns so that the condition number is the
        // one of the correlation-like matrix the model works with.
        let norms: Vec<f64> = kept
            .iter()
            .map(|&j| centred[j].iter().map(|v| v * v).sum::<f64>().sqrt())
            .collect();
        let mut columns: Vec<Vec<f64>> = kept
            .iter()
            .zip(&norms)
            .map(|(&j, norm)| centred[j].iter().map(|v| v / norm).collect())
            .collect();
        let r = householder_r(&mut columns);
        let k = kept.len();
        let diagonal: Vec<f64> = (0..k).map(|i| r[i][i].abs()).collect();
        let condition = (diagonal.iter().cloned().fold(0.0, f64::max)
            / diagonal.iter().cloned().fold(f64::INFINITY, f64::min))
        .powi(2);
        let n = n1 + n0;
        // Standardized gap, then Sigma_std^-1 = N R^-1 R^-T.
        let gap: Vec<f64> = kept
            .iter()
            .zip(&norms)
            .map(|(&j, norm)| (mu1[j] - mu0[j]) / norm)
            .collect();
        let mut y = vec![0.0; k];
        for i in 0..k {
            let mut v = gap[i];
            for p in 0..i {
                v -= r[p][i] * y[p];
            }
            y[i] = v / r[i][i];
        }
        let mut z = vec![0.0; k];
        for i in (0..k).rev() {
            let mut v = y[i];
            for p in i + 1..k {
                v -= r[i][p] * z[p];
            }
            z[i] = v / r[i][i];
        }
        // Sigma = D_n R^T R D_n / N with D_n the column norms, so
        // w = N D_n^-1 R^-1 R^-T D_n^-1 (mu_1 - mu_0).
        let mut weights = vec![0.0; d];
        for (i, (&j, norm)) in kept.iter().zip(&norms).enumerate() {
            weights[j] = n * z[i] / norm;
        }
        Reference {
            weights,
            midpoint: (0..d).map(|j| 0.5 * (mu1[j] + mu0[j])).collect(),
            log_prior_ratio: (n1 / n0).ln(),
            condition,
        }
    }

    fn posterior_safe(&self, x: &[f64]) -> f64 {
        let a: f64 = self.log_prior_ratio
            + x.iter()
                .zip(&self.weights)
                .zip(&self.midpoint)
                .map(|((x, w), m)| w * (x - m))
                .sum::<f64>();
        1.0 / (1.0 + (-a).exp())
    }
}

/// The `R` factor (row-major `k x k`, rows as `Vec`) of the Householder QR of
/// `columns` (each of length `n`); `columns` is overwritten.
fn householder_r(columns: &mut [Vec<f64>]) -> Vec<Vec<f64>> {
    let k = columns.len();
    for c in 0..k {
        let norm = columns[c][c..].iter().map(|v| v * v).sum::<f64>().sqrt();
        let alpha = if columns[c][c] > 0.0 { -norm } else { norm };
        let mut v: Vec<f64> = columns[c][c..].to_vec();
        v[0] -= alpha;
        let vv: f64 = v.iter().map(|x| x * x).sum();
        for other in c..k {
            if vv == 0.0 {
                break;
            }
            let dot: f64 = v.iter().zip(&columns[other][c..]).map(|(a, b)| a * b).sum();
            let f = 2.0 * dot / vv;
            for (i, vi) in v.iter().enumerate() {
                columns[other][c + i] -= f * vi;
            }
        }
    }
    (0..k)
        .map(|i| {
            (0..k)
                .map(|c| if c >= i { columns[c][i] } else { 0.0 })
                .collect()
        })
        .collect()
}

/// The largest posterior difference between the model and the reference.
fn worst_posterior_gap(model: &ZoneModel, reference: &Reference, points: &[Vec<f64>]) -> f64 {
    points
        .iter()
        .map(|x| (model.posterior_safe(x).unwrap() - reference.posterior_safe(x)).abs())
        .fold(0.0, f64::max)
}

/// Four features in which `b = a + delta t` is almost collinear with `a`, and
/// the classes differ in `t` by about its spread, so the near-null direction
/// separates them. Every sample is a class mean plus or minus a small-integer
/// pattern, so means and scatters are exact in binary floating point and the
/// comparison measures the solve, not the rounding of the statistics.
fn collinear_classes(delta: f64, seed: u64) -> Vec<Sample> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut samples = Vec::new();
    for (y, mean) in [
        (Label::Safe, [0.0, 0.0, 0.0, 0.0]),
        (Label::Unsafe, [2.0, 2.0 + 2.0 * delta, 1.0, 0.5]),
    ] {
        for _ in 0..32 {
            let a = rng.random_range(-8..=8) as f64;
            let t = rng.random_range(-4..=4) as f64;
            let c = rng.random_range(-8..=8) as f64;
            let e = rng.random_range(-8..=8) as f64;
            let v = [a, a + delta * t, c, e];
            for sign in [1.0, -1.0] {
                let x = (0..4).map(|j| mean[j] + sign * v[j]).collect();
                samples.push(Sample::new(x, y));
            }
        }
    }
    samples
}

fn no_distance() -> ZoneConfig {
    ZoneConfig {
        feature_set: FeatureSet::NoDistance,
        ..ZoneConfig::default()
    }
}

#[test]
fn the_default_model_is_the_ml_lda_up_to_condition_numbers_of_1e12() {
    for (exponent, seed) in [(8, 1), (12, 2), (16, 3), (19, 4)] {
        let delta = (2.0_f64).powi(-exponent);
        let samples = collinear_classes(delta, seed);
        let reference = Reference::fit(&samples);
        let model = ZoneModel::fit(no_distance(), &samples).unwrap();
        let points: Vec<Vec<f64>> = samples.iter().map(|s| s.x.clone()).collect();
        let gap = worst_posterior_gap(&model, &reference, &points);
        eprintln!(
            "delta = 2^-{exponent}: condition {:e}, worst posterior gap {gap:e}",
            reference.condition
        );
        assert!(
            gap <= TOLERANCE,
            "condition {:e}: posteriors differ by {gap:e}",
            reference.condition
        );
    }
}

#[test]
fn the_default_model_is_the_ml_lda_on_a_lane_change_with_paper_features() {
    // dist = hypot(ds, dl) with |ds| >> |dl|: distance features nearly
    // collinear with the longitudinal offsets, as during a lane change.
    let mut rng = ChaCha8Rng::seed_from_u64(12);
    let mut samples = Vec::new();
    for k in 0..200 {
        let s = 0.04 * k as f64 + rng.random_range(-0.02..0.02);
        let l = 0.005 * k as f64 + rng.random_range(-0.2..0.2);
        samples.push(Sample::new(
            features_at(FeatureSet::Paper, s, l),
            Label::Safe,
        ));
        let l = l + 0.6 + rng.random_range(-0.2..0.2);
        samples.push(Sample::new(
            features_at(FeatureSet::Paper, s, l),
            Label::Unsafe,
        ));
    }
    // In one scene ds_a = ds_p - 20 and dl_a = dl_p + 3.5 repeat the preceding
    // vehicle's offsets: the reference leaves them out, and the posterior on
    // points that keep the repetition is unique.
    let mut reduced = samples.clone();
    for s in &mut reduced {
        s.x[3] = 0.0;
        s.x[4] = 0.0;
    }
    let reference = Reference::fit(&reduced);
    let model = ZoneModel::fit(ZoneConfig::default(), &samples).unwrap();
    let gap = samples
        .iter()
        .zip(&reduced)
        .map(|(s, r)| (model.posterior_safe(&s.x).unwrap() - reference.posterior_safe(&r.x)).abs())
        .fold(0.0, f64::max);
    eprintln!(
        "paper features: condition {:e}, worst posterior gap {gap:e}",
        reference.condition
    );
    assert!(gap <= TOLERANCE, "posteriors differ by {gap:e}");
}

#[test]
fn a_feature_constant_in_both_classes_fits_and_gets_weight_zero() {
    // dl_p when the ego never moves laterally in the samples: the fourth
    // feature is the same constant in both classes.
    let mut samples = collinear_classes(2.0_f64.powi(-10), 5);
    for s in &mut samples {
        s.x[3] = 0.25;
    }
    let reference = Reference::fit(&samples);
    let model = ZoneModel::fit(no_distance(), &samples).unwrap();
    let points: Vec<Vec<f64>> = samples.iter().map(|s| s.x.clone()).collect();
    let gap = worst_posterior_gap(&model, &reference, &points);
    assert!(gap <= TOLERANCE, "posteriors differ by {gap:e}");
    // Weight 0: the constant feature's value does not move the log-odds.
    for x in &points {
        let mut moved = x.clone();
        moved[3] = 1e3;
        let (a, b) = (
            model.log_odds_safe(x).unwrap(),
            model.log_odds_safe(&moved).unwrap(),
        );
        assert_eq!(a, b);
    }
}

#[test]
fn exactly_collinear_features_fit_as_the_minimum_norm_model() {
    // The second feature repeats the first: the covariance is singular; the
    // posterior on points that respect the repetition is unique.
    let mut samples = collinear_classes(2.0_f64.powi(-10), 6);
    for s in &mut samples {
        s.x[1] = s.x[0];
    }
    let mut reduced = samples.clone();
    for s in &mut reduced {
        s.x[1] = 0.0;
    }
    let reference = Reference::fit(&reduced);
    let model = ZoneModel::fit(no_distance(), &samples).unwrap();
    let gap = samples
        .iter()
        .zip(&reduced)
        .map(|(s, r)| (model.posterior_safe(&s.x).unwrap() - reference.posterior_safe(&r.x)).abs())
        .fold(0.0, f64::max);
    assert!(gap <= TOLERANCE, "posteriors differ by {gap:e}");
}
