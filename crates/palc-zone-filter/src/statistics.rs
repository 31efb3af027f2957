//! Sufficient statistics of one class, mergeable without revisiting old data.

use serde::{Deserialize, Serialize};

/// Count, mean and centred scatter of the samples of one class.
///
/// Two sets of statistics merge exactly as if the data had been pooled
/// (Chan, Golub and LeVeque's pairwise update), so an online model equals a
/// batch fit to rounding. The centred form avoids the cancellation of raw
/// sums of `x x^T`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClassStatistics {
    /// Number of samples.
    pub count: u64,
    /// Mean of the samples (zeros when `count == 0`).
    pub mean: Vec<f64>,
    /// Centred scatter `sum_i (x_i - mean)(x_i - mean)^T`, row-major `d x d`.
    pub scatter: Vec<f64>,
}

impl ClassStatistics {
    /// Statistics of no samples in dimension `d`.
    pub fn empty(d: usize) -> Self {
        ClassStatistics {
            count: 0,
            mean: vec![0.0; d],
            scatter: vec![0.0; d * d],
        }
    }

    /// The dimension of the feature vectors.
    pub fn dimension(&self) -> usize {
        self.mean.len()
    }

    /// Statistics of a batch (two passes: mean, then centred scatter).
    pub(crate) fn from_points<'a>(
        d: usize,
        points: impl Iterator<Item = &'a [f64]> + Clone,
    ) -> Self {
        let mut stats = ClassStatistics::empty(d);
        for x in points.clone() {
            stats.count += 1;
            for (m, v) in stats.mean.iter_mut().zip(x) {
                *m += v;
            }
        }
        if stats.count == 0 {
            return stats;
        }
        let n = stats.count as f64;
        stats.mean.iter_mut().for_each(|m| *m /= n);
        let mut centred = vec![0.0; d];
        for x in points {
            for j in 0..d {
                centred[j] = x[j] - stats.mean[j];
            }
            for r in 0..d {
                for c in r..d {
                    stats.scatter[r * d + c] += centred[r] * centred[c];
                }
            }
        }
        for r in 0..d {
            for c in 0..r {
                stats.scatter[r * d + c] = stats.scatter[c * d + r];
            }
        }
        stats
    }

    /// Adds `other`'s samples to `self` (pairwise update; exact up to rounding).
    pub(crate) fn merge(&mut self, other: &ClassStatistics) {
        if other.count == 0 {
            return;
        }
        if self.count == 0 {
            *self = other.clone();
            return;
        }
        let d = self.dimension();
        let (na, nb) = (self.count as f64, other.count as f64);
        let n = na + nb;
        let delta: Vec<f64> = other
            .mean
            .iter()
            .zip(&self.mean)
            .map(|(b, a)| b - a)
            .collect();
        let weight = na * nb / n;
        for r in 0..d {
            for c in 0..d {
                self.scatter[r * d + c] += other.scatter[r * d + c] + weight * delta[r] * delta[c];
            }
        }
        for (m, dm) in self.mean.iter_mut().zip(&delta) {
            *m += dm * nb / n;
        }
        self.count += other.count;
    }
}
