//! The one error type of the aggregator.

use std::path::PathBuf;

use palc_planner::PlanError;
use palc_zone_filter::ZoneError;

/// Everything that can go wrong when learning from a lesson or storing experience.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum AggregatorError {
    /// The planner refused a plan (the new plan or an inner solve of a correction rule).
    #[error("planner: {0}")]
    Plan(#[from] PlanError),
    /// The zone filter refused an update or a projection.
    #[error("zone filter: {0}")]
    Zone(#[from] ZoneError),
    /// The expert problem could not be planned (infeasible, or the solver failed); the
    /// experience was left unchanged.
    #[error("expert trajectory ({expert}) could not be planned: {source}")]
    ExpertFailed {
        /// Which generator (`zone_centre` or `lesson`).
        expert: &'static str,
        /// The planner's refusal.
        source: PlanError,
    },
    /// An option lies outside its allowed range.
    #[error("option `{field}` = {value:?} is out of range: must be {bound}")]
    InvalidOption {
        /// The option, e.g. `incremental.step_size`.
        field: &'static str,
        /// Its value.
        value: f64,
        /// The allowed range, in words.
        bound: &'static str,
    },
    /// Two options cannot be used together.
    #[error("options conflict: {reason}")]
    ConflictingOptions {
        /// What conflicts and how to fix it.
        reason: &'static str,
    },
    /// A lesson input has the wrong length or an index out of range.
    #[error("lesson field `{field}` has length {found}, expected {expected}")]
    LessonMismatch {
        /// The field, e.g. `executed`.
        field: &'static str,
        /// Required length.
        expected: usize,
        /// Given length.
        found: usize,
    },
    /// A number (weight, feature, state) is NaN or infinite.
    #[error("`{field}` is {value:?}, expected a finite number")]
    NonFinite {
        /// The input with its index, e.g. `weights[3][8]`.
        field: String,
        /// The value.
        value: f64,
    },
    /// A stored value lies outside its bound.
    #[error("`{field}` is {value:?}, expected {bound}")]
    OutOfRange {
        /// The field with its index, e.g. `demonstration[12]`.
        field: String,
        /// The value.
        value: f64,
        /// The bound, in words.
        bound: String,
    },
    /// A weight matrix cannot be resampled to the requested horizon or step.
    #[error("cannot resample weights: {reason}")]
    Resample {
        /// What is wrong, naming the value and the bound.
        reason: String,
    },
    /// Reading or writing an experience file failed.
    #[error("experience file {}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// An experience file is not valid (corrupt or truncated); nothing was changed.
    #[error("experience file {} is corrupt or truncated: {reason}", path.display())]
    Corrupt {
        /// The file.
        path: PathBuf,
        /// What the parser reported (with line and column).
        reason: String,
    },
    /// An experience file was written by a newer format version.
    #[error(
        "experience file {} has format version {found}; this build reads versions up to {supported}",
        path.display()
    )]
    UnsupportedVersion {
        /// The file.
        path: PathBuf,
        /// The version in the file.
        found: u32,
        /// The newest version this build reads and writes.
        supported: u32,
    },
    /// The experience could not be serialized (e.g. a non-finite number in it).
    #[error("experience cannot be serialized: {reason}")]
    Serialize {
        /// What the serializer reported.
        reason: String,
    },
}
