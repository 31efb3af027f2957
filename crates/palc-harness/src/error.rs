//! Errors of the harness: an invalid config, a refused scenario ([`Refusal`]),
//! and the errors of the crates below, each wrapped once.

use palc_user::UserError;
use thiserror::Error;

use crate::refusal::Refusal;

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
    #[error("unknown speed case `{name}`: the scenario config defines {defined}")]
    UnknownSpeedCase {
        /// The name found.
        name: String,
        /// The speed cases the config defines, quoted.
        defined: String,
    },
    /// The scenario does not fit the planning set-up (e.g. a user who never starts).
    #[error("scenario {scenario}: {refusal}")]
    Refused {
        /// Which scenario, e.g. `collector-high / 40 m / seed 1 / neutral`.
        scenario: String,
        /// What does not hold (boxed: a refusal carries its numbers, and errors
        /// stay small).
        refusal: Box<Refusal>,
    },
    /// A user of an embedder's own failed.
    #[error("scenario {scenario}: user `{user}` failed")]
    UserFailed {
        /// Which scenario.
        scenario: String,
        /// The user's name.
        user: String,
        /// What failed.
        #[source]
        source: Box<dyn std::error::Error + Send + Sync>,
    },
    /// The simulator a lane change was driven in failed or reported what cannot be
    /// used (a vehicle missing or out of range).
    #[error("world `{world}` failed")]
    World {
        /// The world's name.
        world: String,
        /// What failed.
        #[source]
        source: Box<dyn std::error::Error + Send + Sync>,
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
    /// The experience a run starts from plans its first lane change off the road:
    /// weights that pass the planner's convexity check can still pull the ego
    /// sideways without bound (a large negative weight on `l`), so the first plan
    /// from a given experience is checked against the road's edges.
    #[error(
        "scenario {scenario}: the experience's weights plan the first lane change off the road \
         (l = {l:?} m at step {step}, the road spans [{right_edge:?}, {left_edge:?}] m); \
         the experience is refused"
    )]
    ExperienceOffRoad {
        /// The scenario's label.
        scenario: String,
        /// The first step of the plan off the road.
        step: usize,
        /// The lateral position planned there (m).
        l: f64,
        /// The road's right edge (m).
        right_edge: f64,
        /// The road's left edge (m).
        left_edge: f64,
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
    /// A live lane change was finished before its last step, or stepped after it.
    #[error("live lane change: {steps} of {expected} steps driven when it was {action}")]
    LiveOutOfStep {
        /// Steps driven.
        steps: usize,
        /// Steps of the lane change (`K + 1`).
        expected: usize,
        /// What was asked (`finished`, `stepped`).
        action: &'static str,
    },
}

impl HarnessError {
    /// A user's error in `scenario`: its refusal becomes [`HarnessError::Refused`],
    /// its config errors keep their field.
    pub fn from_user(scenario: &str, error: UserError) -> HarnessError {
        match error {
            UserError::InvalidConfig {
                field,
                value,
                bound,
            } => HarnessError::InvalidConfig {
                field,
                value,
                bound,
            },
            UserError::UnknownStyle { name, expected } => {
                HarnessError::UnknownStyle { name, expected }
            }
            UserError::Refused { user, refusal } => HarnessError::Refused {
                scenario: scenario.to_owned(),
                refusal: Box::new(Refusal::User { user, refusal }),
            },
            UserError::Failed { user, source } => HarnessError::UserFailed {
                scenario: scenario.to_owned(),
                user,
                source,
            },
            other => HarnessError::UserFailed {
                scenario: scenario.to_owned(),
                user: String::new(),
                source: Box::new(other),
            },
        }
    }
}

impl From<UserError> for HarnessError {
    /// A user's config error keeps its field (a user's checks refuse only in a
    /// scenario, through [`HarnessError::from_user`]).
    fn from(error: UserError) -> Self {
        HarnessError::from_user("", error)
    }
}

/// The error of a config field out of its bound.
pub(crate) fn invalid(field: &str, value: f64, bound: &str) -> HarnessError {
    HarnessError::InvalidConfig {
        field: field.to_owned(),
        value,
        bound: bound.to_owned(),
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
