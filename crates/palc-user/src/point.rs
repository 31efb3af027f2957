//! A point of a lateral profile: time since the start of the lane change and
//! lateral offset, shared by the table and the recorded profiles.

use serde::{Deserialize, Serialize};

/// One point of a table profile.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProfilePoint {
    /// Time since the start of the lane change (s).
    pub time_s: f64,
    /// Lateral offset from the current lane's centre towards the target lane (m).
    pub offset_m: f64,
}
