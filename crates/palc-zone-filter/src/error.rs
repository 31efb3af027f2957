//! The one error type of the zone filter.

/// Everything that can go wrong when building, updating, querying or
/// projecting a zone model.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ZoneError {
    /// A feature vector does not have the length of the model's feature set.
    #[error("{what}: expected {expected} features, got {found}")]
    DimensionMismatch {
        /// Which input was wrong (e.g. `sample 3`, `point 7`).
        what: String,
        /// The feature set's dimension.
        expected: usize,
        /// The length that was given.
        found: usize,
    },
    /// An input number is NaN or infinite.
    #[error("{field} = {value} is not finite")]
    NonFinite {
        /// Which input was wrong (e.g. `sample 3 feature dl_p`).
        field: String,
        /// The offending value.
        value: f64,
    },
    /// Time-based features divide by the ego speed, which must be positive.
    #[error("{field} = {value:?} m/s must be positive for the time-gap feature set")]
    NonPositiveSpeed {
        /// Which input was wrong.
        field: String,
        /// The offending speed.
        value: f64,
    },
    /// A configuration value is outside its allowed range.
    #[error("config field `{field}` = {value} is out of range: must be {bound}")]
    InvalidConfig {
        /// The configuration field.
        field: &'static str,
        /// The offending value.
        value: f64,
        /// The allowed range, in words.
        bound: &'static str,
    },
    /// The model has not seen both classes yet, so it carries no boundary.
    #[error("the model has {safe} safe and {unsafe_count} unsafe samples; both classes are needed")]
    NotInformative {
        /// Samples labelled y = 1.
        safe: u64,
        /// Samples labelled y = 0.
        unsafe_count: u64,
    },
    /// The eigendecomposition of a covariance did not converge or gave
    /// non-finite values (a singular covariance is not an error).
    #[error(
        "the eigendecomposition of the {which} covariance failed with ridge = {ridge:e}; its entries are too large or too small"
    )]
    SingularCovariance {
        /// Which covariance (`shared`, `safe class`, `unsafe class`).
        which: &'static str,
        /// The ridge in use.
        ridge: f64,
    },
    /// Finite features so large that the log-odds overflowed to NaN.
    #[error("the log-odds of {what} overflowed; its features are too large (|x| > 1e150?)")]
    Overflow {
        /// Which point overflowed.
        what: String,
    },
    /// Finite samples whose mean or scatter overflowed (e.g. features near 1e308).
    #[error(
        "the statistics of the {class} samples overflowed (a mean or scatter entry is not finite); features must stay below about 1e150 in magnitude"
    )]
    StatisticsOverflow {
        /// `safe` or `unsafe`.
        class: &'static str,
    },
    /// A stored model was written by an unsupported format version.
    #[error("model format version {found} is not supported; this build reads version {expected}")]
    UnsupportedVersion {
        /// The version in the file.
        found: u32,
        /// The version this build reads and writes.
        expected: u32,
    },
    /// Stored statistics are inconsistent with each other or with the feature set.
    #[error("stored statistics are invalid: {reason}")]
    InvalidStatistics {
        /// What is inconsistent.
        reason: String,
    },
    /// Two buffers that must match in length do not.
    #[error("{what}: length {found} does not match the expected {expected}")]
    LengthMismatch {
        /// Which buffer.
        what: &'static str,
        /// The expected length.
        expected: usize,
        /// The given length.
        found: usize,
    },
}

/// Checks that `value` is finite, naming it in the error.
pub(crate) fn check_finite(value: f64, field: impl FnOnce() -> String) -> Result<(), ZoneError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(ZoneError::NonFinite {
            field: field(),
            value,
        })
    }
}
