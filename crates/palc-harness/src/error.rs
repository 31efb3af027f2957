//! Errors of the harness.

use thiserror::Error;

/// What can go wrong while setting up or running the lesson-learning loop.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum HarnessError {
    /// A config value is out of its bound.
    #[error("invalid config: `{field}` is {value:?}, expected {bound}")]
    InvalidConfig {
        /// Dotted path of the field.
        field: String,
        /// The value found.
        value: f64,
        /// The bound it violates.
        bound: String,
    },
    /// A table that the config needs is missing.
    #[error("invalid config: the table [{table}] is missing; it is needed because {reason}")]
    MissingTable {
        /// Dotted path of the table.
        table: &'static str,
        /// Why the table is needed.
        reason: &'static str,
    },
    /// A style name that is none of the valid ones.
    #[error("unknown driving style `{name}`: expected one of {expected}")]
    UnknownStyle {
        /// The name found.
        name: String,
        /// The valid names, quoted.
        expected: String,
    },
    /// A speed case that the scenario config does not define.
    #[error("unknown speed case `{0}`: the scenario config defines {1}")]
    UnknownSpeedCase(String, String),
    /// The scenario does not fit the planning set-up (e.g. a user who never starts).
    #[error("scenario {scenario}: {reason}")]
    Scenario {
        /// Which grid cell.
        scenario: String,
        /// What does not hold.
        reason: String,
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
    /// An error of the traffic simulation.
    #[error(transparent)]
    Traffic(#[from] palc_traffic::SceneError),
    /// An error of the traffic config.
    #[error(transparent)]
    TrafficConfig(#[from] palc_traffic::ConfigError),
    /// An error of the planner.
    #[error(transparent)]
    Planner(#[from] palc_planner::PlanError),
    /// An error of the zone filter.
    #[error(transparent)]
    Zone(#[from] palc_zone_filter::ZoneError),
    /// An error of the aggregator.
    #[error(transparent)]
    Aggregator(#[from] palc_aggregator::AggregatorError),
}

/// `` `path`: `` before a message, or nothing for an empty path.
fn at_field(path: &str) -> String {
    if path.is_empty() {
        String::new()
    } else {
        format!("`{path}`: ")
    }
}
