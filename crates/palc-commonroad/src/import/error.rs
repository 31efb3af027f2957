//! The importer's errors: a scenario that cannot be read ([`ImportError`]) and a file of
//! recorded lane changes that does not validate ([`ReadError`]).
//!
//! Vehicles with gaps in their time steps or non-finite numbers are not errors: they are
//! counted and skipped (see [`SkipReason`](super::SkipReason)), because one bad track in a
//! recording of hundreds should not lose the others.

use std::path::PathBuf;

/// A CommonRoad scenario could not be imported.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ImportError {
    /// The file could not be read.
    #[error("cannot read {}: {error}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        error: std::io::Error,
    },
    /// The XML is malformed or does not have the structure of a 2020a scenario.
    #[error("{source_name}:{line}:{column}: not a readable CommonRoad 2020a scenario: {message}")]
    Xml {
        /// The file (or the name the caller gave the text).
        source_name: String,
        /// Line of the error (from 1), as far as quick-xml locates it.
        line: usize,
        /// Column of the error (from 1).
        column: usize,
        /// quick-xml's message.
        message: String,
    },
    /// The root element is not `commonRoad`.
    #[error(
        "{source_name}: the root element is `{root}`, not `commonRoad`: not a CommonRoad scenario"
    )]
    NotCommonRoad {
        /// The file.
        source_name: String,
        /// The root element found.
        root: String,
    },
    /// The scenario's `commonRoadVersion` is not 2020a.
    #[error(
        "{source_name}: commonRoadVersion is `{version}`, only `2020a` is read; convert the file with commonroad-io: \
         `CommonRoadFileReader(path).open()`, then `CommonRoadFileWriter(scenario, planning_problems).write_to_file(...)`"
    )]
    UnsupportedVersion {
        /// The file.
        source_name: String,
        /// The version found (`(none)` when the attribute is missing).
        version: String,
    },
    /// The `timeStepSize` is not a positive finite number.
    #[error("{source_name}: timeStepSize is {value}, must be positive and finite")]
    InvalidTimeStep {
        /// The file.
        source_name: String,
        /// The value found.
        value: f64,
    },
    /// A lanelet cannot be used as a lane (too few points, non-finite coordinates, a
    /// duplicate id).
    #[error("{source_name}: lanelet {id}: {reason}")]
    InvalidLanelet {
        /// The file.
        source_name: String,
        /// The lanelet's id.
        id: i64,
        /// What is wrong with it.
        reason: String,
    },
}

/// A file of recorded lane changes could not be read or does not validate.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReadError {
    /// The file could not be read.
    #[error("cannot read {}: {error}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        error: std::io::Error,
    },
    /// The JSON is malformed or has unknown or missing fields.
    #[error("{}:{line}:{column}: {message}", path.display())]
    Json {
        /// The file.
        path: PathBuf,
        /// Line of the error (from 1).
        line: usize,
        /// Column of the error (from 1).
        column: usize,
        /// serde_json's message.
        message: String,
    },
    /// A field's value is out of its bounds.
    #[error("{}: {field} is {value}, must be {bound}", path.display())]
    Invalid {
        /// The file.
        path: PathBuf,
        /// The field, as a path (`lane_changes[3].trace[5].time_s`).
        field: String,
        /// The value found.
        value: String,
        /// What it must be.
        bound: String,
    },
}
