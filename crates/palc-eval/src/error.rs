//! Errors of the evaluation.

use std::path::PathBuf;

use thiserror::Error;

/// What can go wrong while reading an evaluation config, running it or writing
/// its outputs.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum EvalError {
    /// A file could not be read or written.
    #[error("cannot {action} {}: {source}", path.display())]
    Io {
        /// `read`, `write` or `create`.
        action: &'static str,
        /// The file or directory.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// An output file could not be written; the previous one is unchanged.
    #[error(transparent)]
    Output(#[from] palc_aggregator::output::OutputError),
    /// An error inside a config file, with the file's path.
    #[error("in {}: {source}", path.display())]
    InFile {
        /// The config file.
        path: PathBuf,
        /// The error.
        source: Box<EvalError>,
    },
    /// The TOML text does not parse or does not match the schema (unknown field, missing
    /// field, wrong type); the message names the field path, the line and the column.
    #[error("cannot parse the config: {}{error}", at_field(path))]
    Toml {
        /// Dotted path of the field where the error is (e.g.
        /// `planning.standard_alc.time_headway_s`); empty for a syntax error.
        path: String,
        /// The parse error, with its line and column (in the message, so not a `source`
        /// that a report would print twice).
        error: Box<toml::de::Error>,
    },
    /// A shard file to merge is not one of the evaluation's parts, or parts are
    /// missing or given twice ([`crate::shard`]).
    #[error("cannot merge {}: {reason}", path.display())]
    Shard {
        /// The shard file (or the first shard directory, for a part missing).
        path: PathBuf,
        /// What differs or is missing.
        reason: String,
    },
    /// The evaluation was cancelled ([`crate::Progress::cancelled`]) before its
    /// last run; nothing was written.
    #[error("the evaluation was cancelled; no output was written")]
    Cancelled,
    /// A config value is out of its bound.
    #[error("`{field}` is {value}, expected {bound}")]
    InvalidConfig {
        /// Dotted path of the field.
        field: String,
        /// The value found.
        value: String,
        /// The bound it violates.
        bound: String,
    },
    /// An option of the evaluation (not a field of its config) is out of its bound.
    #[error("`{option}` is {value}, expected {bound}")]
    InvalidOption {
        /// The option, as on the command line (`--jobs`).
        option: &'static str,
        /// The value given.
        value: String,
        /// The bound it violates.
        bound: String,
    },
    /// The config expands to more runs than it allows.
    #[error(
        "the config expands to more than {max_runs} runs, its bound `max_runs`; set `max_runs` higher for a study that large"
    )]
    TooManyRuns {
        /// The bound.
        max_runs: usize,
    },
    /// A name (speed case, user kind) that the config does not define.
    #[error("unknown {kind} `{name}` in `{field}`: defined are {known:?}")]
    Unknown {
        /// What kind of name.
        kind: &'static str,
        /// The name.
        name: String,
        /// Where it was found.
        field: String,
        /// The names that are defined.
        known: Vec<String>,
    },
    /// The base learning config is invalid.
    #[error("the base learning config: {0}")]
    Harness(#[from] palc_harness::HarnessError),
    /// The learning config of one run is invalid.
    #[error("run `{run}`: {source}")]
    Run {
        /// The run's label.
        run: String,
        /// The cause.
        source: palc_harness::HarnessError,
    },
    /// A worker thread could not start.
    #[error("cannot start a worker thread: {0}")]
    Thread(std::io::Error),
    /// Results could not be serialized.
    #[error("cannot serialize the results: {0}")]
    Json(#[from] serde_json::Error),
    /// `runs.csv` could not be written.
    #[error("cannot write the CSV: {0}")]
    Csv(#[from] csv::Error),
    /// A figure could not be drawn.
    #[error("cannot draw the figure `{figure}`: {message}")]
    Figure {
        /// The figure's file stem.
        figure: String,
        /// What the plotting backend said.
        message: String,
    },
}

impl EvalError {
    /// A user kind's invalid family or spread, as an error of the evaluation
    /// config (the field path already names `users[i]`).
    pub(crate) fn invalid_user(source: palc_harness::HarnessError) -> EvalError {
        match source {
            palc_harness::HarnessError::InvalidConfig {
                field,
                value,
                bound,
            } => EvalError::InvalidConfig {
                field,
                value: format!("{value:e}"),
                bound,
            },
            other => EvalError::Harness(other),
        }
    }

    /// Adds the path of the file the error is in.
    pub fn in_file(self, path: impl Into<PathBuf>) -> EvalError {
        EvalError::InFile {
            path: path.into(),
            source: Box::new(self),
        }
    }

    pub(crate) fn invalid(
        field: impl Into<String>,
        value: impl std::fmt::Display,
        bound: impl Into<String>,
    ) -> EvalError {
        EvalError::InvalidConfig {
            field: field.into(),
            value: value.to_string(),
            bound: bound.into(),
        }
    }
}

/// `` `path`: `` before a message, or nothing for an empty path.
fn at_field(path: &str) -> String {
    if path.is_empty() {
        String::new()
    } else {
        format!("`{path}`: ")
    }
}
