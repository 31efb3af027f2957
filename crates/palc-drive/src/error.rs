//! The errors of a driving study: its protocol, its record and its server.

use std::path::PathBuf;

/// An error of `palc drive`.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum DriveError {
    /// The protocol file does not parse or breaks a rule.
    #[error("protocol {path}: {message}")]
    Protocol {
        /// The protocol file.
        path: PathBuf,
        /// What is wrong, naming the field, the value and the bound.
        message: String,
    },
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The session record cannot be resumed.
    #[error("record {path}, line {line}: {message}")]
    Record {
        /// The record file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// The loop refused a scene or failed.
    #[error(transparent)]
    Harness(#[from] palc_harness::HarnessError),
    /// An output file could not be written.
    #[error(transparent)]
    Output(#[from] palc_aggregator::output::OutputError),
    /// The experience could not be saved.
    #[error(transparent)]
    Aggregator(#[from] palc_aggregator::AggregatorError),
}
