//! A step of a lane change at which a gap to a surrounding vehicle falls below
//! the RSS safe distance, and the role of that vehicle: what the safety
//! measures ([`crate::safety`]) report and the safety layer refuses a plan for.

use std::fmt;

use serde::{Deserialize, Serialize};

/// The role of a surrounding vehicle in a lane change.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Role {
    /// The slower vehicle ahead on the ego's own lane.
    Preceding,
    /// The nearest vehicle ahead on the target lane.
    TargetLead,
    /// The nearest vehicle behind on the target lane.
    TargetLag,
    /// Any other vehicle (another lane's, or behind the ego in its own lane).
    Other,
}

impl Role {
    /// The role's name in messages and reports.
    pub const fn name(self) -> &'static str {
        match self {
            Role::Preceding => "preceding vehicle",
            Role::TargetLead => "target-lane lead vehicle",
            Role::TargetLag => "target-lane lag vehicle",
            Role::Other => "vehicle",
        }
    }
}

/// A step at which a gap is below the safe distance (or the footprints overlap).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Violation {
    /// Step of the lane change (0 = the start of the plan).
    pub step: usize,
    /// Role of the other vehicle.
    pub role: Role,
    /// Its identifier in the scene.
    pub vehicle: u32,
    /// Net gap between the two (m); not positive in a collision.
    pub gap_m: f64,
    /// The RSS safe distance at that step (m).
    pub safe_distance_m: f64,
}

impl fmt::Display for Violation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "unsafe gap: {} {} at {:.1} m, safe distance {:.1} m at step {}",
            self.role.name(),
            self.vehicle,
            self.gap_m,
            self.safe_distance_m,
            self.step
        )
    }
}
