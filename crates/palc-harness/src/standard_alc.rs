//! The standard ALC before any learning: its weight matrix.
//!
//! Per stage, `w1 l² + w2 l` with `w2 = −2 w1 l_std(t)` is `w1 (l − l_std(t))²` up to a
//! constant: the plan is pulled towards the standard ALC's own lane change
//! `l_std(t)` (a quintic that starts late and lasts long), with stiffness `w1`.
//! Heading and steering are smoothed by `w3` and `w8`; the cross terms and the
//! distance terms start at zero. Learning then moves `w1` and `w2` per step,
//! which moves the lateral target `−w2 / (2 w1)` and so the start and shape of the
//! lane change (NOTES.md, "Let the planner decide when to move").

use palc_planner::{FEATURE_COUNT, Weights, feature};
use serde::{Deserialize, Serialize};

use crate::HarnessError;
use crate::error::invalid;
use palc_user::ExpectedLaneChange;

/// Weights of the standard ALC, per stage; defaults in `configs/learn.toml`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct StandardWeights {
    /// `w1`: stiffness of the lateral target (per m²).
    pub lateral_stiffness: f64,
    /// `w3`: heading penalty (per rad²).
    pub heading: f64,
    /// `w8`: steering penalty (per rad²).
    pub steering: f64,
}

impl Default for StandardWeights {
    fn default() -> Self {
        Self {
            lateral_stiffness: 1.0,
            heading: 10.0,
            steering: 10.0,
        }
    }
}

impl StandardWeights {
    /// Checks every weight: the stiffness finite and positive (at zero nothing pulls
    /// the plan towards a lane change, and the target rule, which moves the target
    /// `−w2 / (2 w1)`, has nothing to move), heading and steering finite and not
    /// negative (the cost stays convex).
    ///
    /// # Errors
    /// [`HarnessError::InvalidConfig`] naming the `[standard_weights]` field.
    pub fn validate(&self) -> Result<(), HarnessError> {
        if !(self.lateral_stiffness.is_finite() && self.lateral_stiffness > 0.0) {
            let (field, value) = ("standard_weights.lateral_stiffness", self.lateral_stiffness);
            return Err(invalid(field, value, "a finite value > 0"));
        }
        let penalties = [
            ("standard_weights.heading", self.heading),
            ("standard_weights.steering", self.steering),
        ];
        for (field, value) in penalties {
            if !(value.is_finite() && value >= 0.0) {
                return Err(invalid(field, value, "a finite value >= 0"));
            }
        }
        Ok(())
    }

    /// The 10 x K weight matrix whose plan follows `lane_change` (column `c` weighs
    /// the state at step `c`, time `c dt`).
    pub fn weights(&self, lane_change: &ExpectedLaneChange, horizon: usize, dt: f64) -> Weights {
        let columns = (0..horizon)
            .map(|c| {
                let target = lane_change.lateral(c as f64 * dt);
                let mut column = [0.0; FEATURE_COUNT];
                column[feature::L_SQUARED] = self.lateral_stiffness;
                column[feature::L] = -2.0 * self.lateral_stiffness * target;
                column[feature::PHI_SQUARED] = self.heading;
                column[feature::DELTA_SQUARED] = self.steering;
                column
            })
            .collect();
        Weights::from_columns(columns)
    }
}
