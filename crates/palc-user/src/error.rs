//! Errors of a user: a parameter out of its bound, and the typed refusals of a
//! scenario in which a user has no sane lane change.

use thiserror::Error;

/// What can go wrong with a user: its configuration, or a scenario it cannot
/// drive a sane lane change in.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum UserError {
    /// A parameter is out of its bound.
    #[error("invalid config: `{field}` is {value:?}, expected {bound}")]
    InvalidConfig {
        /// Dotted path of the field.
        field: String,
        /// The value found.
        value: f64,
        /// The bound it violates.
        bound: String,
    },
    /// A style name that is none of the valid ones.
    #[error("unknown driving style `{name}`: expected one of {expected}")]
    UnknownStyle {
        /// The name found.
        name: String,
        /// The valid names, quoted.
        expected: String,
    },
    /// The user has no sane lane change in the scenario it was shown.
    #[error("user `{user}`: {refusal}")]
    Refused {
        /// The user's name.
        user: String,
        /// What does not hold.
        refusal: UserRefusal,
    },
    /// A user of an embedder's own failed (a recorded driver's file, a model in
    /// another language, a person's input device).
    #[error("user `{user}` failed")]
    Failed {
        /// The user's name.
        user: String,
        /// What failed.
        #[source]
        source: Box<dyn std::error::Error + Send + Sync>,
    },
}

/// Why a user has no sane lane change in a scenario: one variant per check of
/// [`crate::SimulatedUser`]'s expectation, with the numbers that failed it.
/// Displayed as the sentence a report prints after the user's name.
#[derive(Debug, Clone, PartialEq, Error, serde::Serialize, serde::Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
#[non_exhaustive]
pub enum UserRefusal {
    /// The start rule is never met within the search window.
    #[error("its {rule} start rule is never met within the {window_s:.1} s search window")]
    StartRuleNeverMet {
        /// The start rule's name.
        rule: String,
        /// The search window (s).
        window_s: f64,
    },
    /// The start rule is met at the first step: the user would have gone before
    /// the system plans.
    #[error(
        "its {rule} start rule is already met when planning starts (time headway \
         {time_headway_s:.2} s): the user would have changed lanes before the system plans"
    )]
    StartRuleMetAtTrigger {
        /// The start rule's name.
        rule: String,
        /// The time headway at the first step (s).
        time_headway_s: f64,
    },
    /// After the decision, the target lane's gaps never become acceptable.
    #[error(
        "the target lane's gaps never become acceptable to it (lead {min_lead_gap_s:.2} s, lag \
         {min_lag_gap_s:.2} s{}) within the search window after its decision at step \
         {decision_step}",
        safe_distance_clause(.safe_distance)
    )]
    GapsNeverAcceptable {
        /// Smallest lead time gap the user accepts (s).
        min_lead_gap_s: f64,
        /// Smallest lag time gap the user accepts (s).
        min_lag_gap_s: f64,
        /// Whether the user also waits for the RSS safe distance.
        safe_distance: bool,
        /// The step of the decision.
        decision_step: usize,
    },
    /// The lane change ends after the search window.
    #[error("its lane change ends at {end_s:.2} s, after the {window_s:.1} s search window")]
    EndsAfterWindow {
        /// End of the lane change (s).
        end_s: f64,
        /// The search window (s).
        window_s: f64,
    },
    /// The profile does not go from one lane centre to the other.
    #[error(
        "its lane change goes from l = {start_l:.3} m to l = {end_l:.3} m, not from the lane \
         centre at {from_l:.3} m to the target lane's at {to_l:.3} m"
    )]
    NotCentreToCentre {
        /// Where the profile starts (m).
        start_l: f64,
        /// Where the profile ends (m).
        end_l: f64,
        /// The current lane's centre (m).
        from_l: f64,
        /// The target lane's centre (m).
        to_l: f64,
    },
    /// The profile leaves the two lanes.
    #[error("its lane change leaves the two lanes (l = {l:.3} m, outside [{low:.3}, {high:.3}] m)")]
    LeavesLanes {
        /// The lateral position outside (m).
        l: f64,
        /// The lowest lateral position allowed (m).
        low: f64,
        /// The highest lateral position allowed (m).
        high: f64,
    },
    /// The profile's lateral acceleration or jerk is beyond the bounds.
    #[error(
        "its {profile} profile over {duration_s:.2} s is not smooth enough: lateral acceleration \
         {acceleration_mps2:.1} m/s² (at most {max_acceleration_mps2:?}), jerk {jerk_mps3:.0} m/s³ \
         (at most {max_jerk_mps3})"
    )]
    NotSmooth {
        /// The profile's name.
        profile: String,
        /// The lane change's duration (s).
        duration_s: f64,
        /// Peak lateral acceleration (m/s²).
        acceleration_mps2: f64,
        /// Its bound (m/s²).
        max_acceleration_mps2: f64,
        /// Peak lateral jerk (m/s³).
        jerk_mps3: f64,
        /// Its bound (m/s³).
        max_jerk_mps3: f64,
    },
    /// A user with spread has no random generator to draw from.
    #[error("has no generator for its spread")]
    NoSpreadGenerator,
}

impl UserRefusal {
    /// The kind's name, as in `runs.json` and the report's table of refusals.
    pub fn kind(&self) -> &'static str {
        match self {
            UserRefusal::StartRuleNeverMet { .. } => "start-rule-never-met",
            UserRefusal::StartRuleMetAtTrigger { .. } => "start-rule-met-at-trigger",
            UserRefusal::GapsNeverAcceptable { .. } => "gaps-never-acceptable",
            UserRefusal::EndsAfterWindow { .. } => "ends-after-window",
            UserRefusal::NotCentreToCentre { .. } => "not-centre-to-centre",
            UserRefusal::LeavesLanes { .. } => "leaves-lanes",
            UserRefusal::NotSmooth { .. } => "not-smooth",
            UserRefusal::NoSpreadGenerator => "no-spread-generator",
        }
    }
}

/// The clause a refusal adds when the user also waits for the safe distance.
fn safe_distance_clause(safe_distance: &bool) -> &'static str {
    if *safe_distance {
        ", and the RSS safe distance at every step of the lane change"
    } else {
        ""
    }
}

/// `Ok` when `value` is finite and in `[low, high]`, else the error naming `field`.
pub fn within(field: &str, value: f64, (low, high): (f64, f64)) -> Result<(), UserError> {
    if value.is_finite() && (low..=high).contains(&value) {
        Ok(())
    } else {
        Err(UserError::InvalidConfig {
            field: field.to_owned(),
            value,
            bound: format!("a value in [{low:?}, {high:?}]"),
        })
    }
}
