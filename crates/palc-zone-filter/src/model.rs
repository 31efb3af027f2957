//! The online GDA model of the perceived safe zone (Eqs. 2-8).

use serde::{Deserialize, Serialize};

use crate::{
    config::{Discriminant, ZoneConfig},
    error::ZoneError,
    gaussian::{Fitted, linear_weights, logistic, regularized_precision},
    sample::{Label, Sample, check_point},
    statistics::ClassStatistics,
};

/// The version of the serialized model written by this build.
pub const MODEL_FORMAT_VERSION: u32 = 1;

/// A GDA model of the perceived safe zone that learns online.
///
/// It stores only sufficient statistics per class (count, mean, centred
/// scatter), so [`ZoneModel::update`] with one takeover's samples never
/// revisits old data and equals a batch fit on all data to rounding.
/// Parameters are the maximum-likelihood estimates of Eqs. (5)-(8) as
/// corrected in NOTES.md: `theta = N1 / N`, `mu_c` the class means and
/// `Sigma = (1/N) sum_i (x_i - mu_{y_i})(x_i - mu_{y_i})^T`, regularized as
/// described on [`ZoneConfig::ridge`].
///
/// Until both classes have samples the model is *not informative*: it has no
/// boundary, queries return [`ZoneError::NotInformative`] and
/// [`crate::lateral_bounds`] returns [`crate::StepBounds::Unconstrained`]
/// ("no information, no bound").
///
/// Serializes (serde) as `{format_version, config, safe, unsafe}` with the
/// statistics; the parameters are recomputed on load.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "StoredZoneModel", into = "StoredZoneModel")]
pub struct ZoneModel {
    config: ZoneConfig,
    safe: ClassStatistics,
    unsafe_: ClassStatistics,
    fitted: Option<Fitted>,
}

impl ZoneModel {
    /// An empty (not yet informative) model.
    ///
    /// # Errors
    /// [`ZoneError::InvalidConfig`] if the configuration is out of range.
    pub fn new(config: ZoneConfig) -> Result<Self, ZoneError> {
        config.validate()?;
        let d = config.feature_set.dimension();
        Ok(ZoneModel {
            config,
            safe: ClassStatistics::empty(d),
            unsafe_: ClassStatistics::empty(d),
            fitted: None,
        })
    }

    /// A model fitted in one batch on `samples`.
    ///
    /// # Errors
    /// As [`ZoneModel::new`] and [`ZoneModel::update`].
    pub fn fit(config: ZoneConfig, samples: &[Sample]) -> Result<Self, ZoneError> {
        let mut model = ZoneModel::new(config)?;
        model.update(samples)?;
        Ok(model)
    }

    /// Adds `samples` (e.g. one takeover's lesson) and refits.
    ///
    /// All samples are checked before anything changes; on error the model is
    /// left as it was. An empty slice is accepted and changes nothing.
    ///
    /// # Errors
    /// [`ZoneError::DimensionMismatch`] or [`ZoneError::NonFinite`] for a bad
    /// sample, [`ZoneError::StatisticsOverflow`] if finite samples overflow the
    /// mean or scatter, [`ZoneError::SingularCovariance`] if the eigendecomposition of
    /// a covariance fails (a singular covariance is not an error: its null
    /// directions get weight 0).
    pub fn update(&mut self, samples: &[Sample]) -> Result<(), ZoneError> {
        let d = self.dimension();
        for (i, sample) in samples.iter().enumerate() {
            check_point(&sample.x, d, || format!("sample {i}"))?;
        }
        let of_class = |label: Label| {
            samples
                .iter()
                .filter(move |s| s.y == label)
                .map(|s| s.x.as_slice())
        };
        let mut safe = self.safe.clone();
        let mut unsafe_ = self.unsafe_.clone();
        safe.merge(&ClassStatistics::from_points(d, of_class(Label::Safe)));
        unsafe_.merge(&ClassStatistics::from_points(d, of_class(Label::Unsafe)));
        for (class, statistics) in [("safe", &safe), ("unsafe", &unsafe_)] {
            let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
            if !(finite(&statistics.mean) && finite(&statistics.scatter)) {
                return Err(ZoneError::StatisticsOverflow { class });
            }
        }
        let fitted = fit_parameters(&self.config, &safe, &unsafe_)?;
        self.safe = safe;
        self.unsafe_ = unsafe_;
        self.fitted = fitted;
        Ok(())
    }

    /// The configuration.
    pub fn config(&self) -> &ZoneConfig {
        &self.config
    }

    /// The number of features per sample.
    pub fn dimension(&self) -> usize {
        self.config.feature_set.dimension()
    }

    /// Statistics of the samples labelled y = 1.
    pub fn safe_statistics(&self) -> &ClassStatistics {
        &self.safe
    }

    /// Statistics of the samples labelled y = 0.
    pub fn unsafe_statistics(&self) -> &ClassStatistics {
        &self.unsafe_
    }

    /// Whether both classes have samples, i.e. the model has a boundary.
    pub fn is_informative(&self) -> bool {
        self.fitted.is_some()
    }

    /// The ML prior `theta = N1 / N` (Eq. 5), if there is any sample.
    pub fn theta(&self) -> Option<f64> {
        let n = self.safe.count + self.unsafe_.count;
        (n > 0).then(|| self.safe.count as f64 / n as f64)
    }

    pub(crate) fn fitted(&self) -> Result<&Fitted, ZoneError> {
        self.fitted.as_ref().ok_or(ZoneError::NotInformative {
            safe: self.safe.count,
            unsafe_count: self.unsafe_.count,
        })
    }

    /// `ln p(y=1|x) - ln p(y=0|x)`: positive inside the perceived safe zone.
    /// For [`Discriminant::Linear`] it is affine in `x`.
    ///
    /// # Errors
    /// [`ZoneError::NotInformative`], [`ZoneError::DimensionMismatch`],
    /// [`ZoneError::NonFinite`], [`ZoneError::Overflow`].
    pub fn log_odds_safe(&self, x: &[f64]) -> Result<f64, ZoneError> {
        let fitted = self.fitted()?;
        check_point(x, self.dimension(), || "point".to_owned())?;
        let a = fitted.log_odds(x);
        if a.is_nan() {
            return Err(ZoneError::Overflow {
                what: "point".to_owned(),
            });
        }
        Ok(a)
    }

    /// `p(y=1|x)`, computed from the log-odds so that it neither overflows nor
    /// loses the tail far from both means (Eq. 2). `p(y=0|x) = 1 - p(y=1|x)`.
    ///
    /// # Errors
    /// As [`ZoneModel::log_odds_safe`].
    pub fn posterior_safe(&self, x: &[f64]) -> Result<f64, ZoneError> {
        self.log_odds_safe(x).map(logistic)
    }

    /// `p(y=0|x)`, as `logistic(-a)` so that it keeps its precision near 0.
    ///
    /// # Errors
    /// As [`ZoneModel::log_odds_safe`].
    pub fn posterior_unsafe(&self, x: &[f64]) -> Result<f64, ZoneError> {
        self.log_odds_safe(x).map(|a| logistic(-a))
    }

    /// The class of `x` (Eq. 2): safe when `p(y=1|x) > p(y=0|x)`, unsafe on a tie.
    ///
    /// # Errors
    /// As [`ZoneModel::log_odds_safe`].
    pub fn classify(&self, x: &[f64]) -> Result<Label, ZoneError> {
        self.log_odds_safe(x)
            .map(|a| if a > 0.0 { Label::Safe } else { Label::Unsafe })
    }

    /// `p(y=1|x)` for many points: `rows` holds `out.len()` points of
    /// [`ZoneModel::dimension`] features each, row-major. Allocates nothing.
    ///
    /// # Errors
    /// [`ZoneError::LengthMismatch`] if the lengths disagree, otherwise as
    /// [`ZoneModel::log_odds_safe`], naming the point's index.
    pub fn posteriors_safe_into(&self, rows: &[f64], out: &mut [f64]) -> Result<(), ZoneError> {
        let fitted = self.fitted()?;
        let d = self.dimension();
        if rows.len() != out.len() * d {
            return Err(ZoneError::LengthMismatch {
                what: "feature rows",
                expected: out.len() * d,
                found: rows.len(),
            });
        }
        for (i, (x, p)) in rows.chunks_exact(d).zip(out.iter_mut()).enumerate() {
            check_point(x, d, || format!("point {i}"))?;
            let a = fitted.log_odds(x);
            if a.is_nan() {
                return Err(ZoneError::Overflow {
                    what: format!("point {i}"),
                });
            }
            *p = logistic(a);
        }
        Ok(())
    }
}

/// The ML parameters from the two classes' statistics, or `None` while a
/// class is empty.
fn fit_parameters(
    config: &ZoneConfig,
    safe: &ClassStatistics,
    unsafe_: &ClassStatistics,
) -> Result<Option<Fitted>, ZoneError> {
    if safe.count == 0 || unsafe_.count == 0 {
        return Ok(None);
    }
    let d = safe.dimension();
    let (n1, n0) = (safe.count as f64, unsafe_.count as f64);
    let n = n1 + n0;
    // Eq. (8), corrected: the within-class scatter over all samples, divided by N.
    let shared: Vec<f64> = safe
        .scatter
        .iter()
        .zip(&unsafe_.scatter)
        .map(|(a, b)| (a + b) / n)
        .collect();
    let mean_gap: Vec<f64> = safe
        .mean
        .iter()
        .zip(&unsafe_.mean)
        .map(|(a, b)| a - b)
        .collect();
    let total_variance: Vec<f64> = (0..d)
        .map(|j| shared[j * d + j] + n1 * n0 / (n * n) * mean_gap[j] * mean_gap[j])
        .collect();
    // Eq. (5): theta = N1 / N, so ln(theta / (1 - theta)) = ln(N1 / N0).
    let log_prior_ratio = (n1 / n0).ln();
    let fitted = match config.discriminant {
        Discriminant::Linear => {
            let weights = linear_weights(&shared, &total_variance, &mean_gap, config.ridge)?;
            let midpoint = safe
                .mean
                .iter()
                .zip(&unsafe_.mean)
                .map(|(a, b)| 0.5 * (a + b))
                .collect();
            Fitted::Linear {
                weights,
                midpoint,
                log_prior_ratio,
            }
        }
        Discriminant::Quadratic => {
            let alpha = config.quadratic_pooling;
            let class_covariance = |stats: &ClassStatistics| -> Vec<f64> {
                let nc = stats.count as f64;
                stats
                    .scatter
                    .iter()
                    .zip(&shared)
                    .map(|(s, p)| (1.0 - alpha) * s / nc + alpha * p)
                    .collect()
            };
            let safe_precision = regularized_precision(
                &class_covariance(safe),
                &total_variance,
                config.ridge,
                "safe class",
            )?;
            let unsafe_precision = regularized_precision(
                &class_covariance(unsafe_),
                &total_variance,
                config.ridge,
                "unsafe class",
            )?;
            Fitted::Quadratic {
                safe_mean: safe.mean.clone(),
                safe: safe_precision,
                unsafe_mean: unsafe_.mean.clone(),
                unsafe_: unsafe_precision,
                log_prior_ratio,
            }
        }
    };
    Ok(Some(fitted))
}

/// The serialized form of a [`ZoneModel`]: version, config and statistics.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct StoredZoneModel {
    format_version: u32,
    config: ZoneConfig,
    safe: ClassStatistics,
    #[serde(rename = "unsafe")]
    unsafe_: ClassStatistics,
}

impl From<ZoneModel> for StoredZoneModel {
    fn from(model: ZoneModel) -> Self {
        StoredZoneModel {
            format_version: MODEL_FORMAT_VERSION,
            config: model.config,
            safe: model.safe,
            unsafe_: model.unsafe_,
        }
    }
}

impl TryFrom<StoredZoneModel> for ZoneModel {
    type Error = ZoneError;

    fn try_from(stored: StoredZoneModel) -> Result<Self, ZoneError> {
        if stored.format_version != MODEL_FORMAT_VERSION {
            return Err(ZoneError::UnsupportedVersion {
                found: stored.format_version,
                expected: MODEL_FORMAT_VERSION,
            });
        }
        stored.config.validate()?;
        let d = stored.config.feature_set.dimension();
        for (name, stats) in [("safe", &stored.safe), ("unsafe", &stored.unsafe_)] {
            check_statistics(name, stats, d)?;
        }
        let fitted = fit_parameters(&stored.config, &stored.safe, &stored.unsafe_)?;
        Ok(ZoneModel {
            config: stored.config,
            safe: stored.safe,
            unsafe_: stored.unsafe_,
            fitted,
        })
    }
}

fn check_statistics(name: &str, stats: &ClassStatistics, d: usize) -> Result<(), ZoneError> {
    let invalid = |reason: String| Err(ZoneError::InvalidStatistics { reason });
    if stats.mean.len() != d || stats.scatter.len() != d * d {
        return invalid(format!(
            "{name}: mean has {} and scatter {} entries; the feature set needs {d} and {}",
            stats.mean.len(),
            stats.scatter.len(),
            d * d
        ));
    }
    if let Some(v) = stats
        .mean
        .iter()
        .chain(&stats.scatter)
        .find(|v| !v.is_finite())
    {
        return invalid(format!("{name}: entry {v} is not finite"));
    }
    for j in 0..d {
        if stats.scatter[j * d + j] < 0.0 {
            return invalid(format!("{name}: scatter diagonal {j} is negative"));
        }
    }
    if stats.count == 0 && stats.mean.iter().chain(&stats.scatter).any(|&v| v != 0.0) {
        return invalid(format!("{name}: no samples but non-zero mean or scatter"));
    }
    Ok(())
}
