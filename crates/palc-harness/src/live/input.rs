//! What a live driver sees at a step ([`LiveView`]), what it answers
//! ([`LiveInput`]) and the physical limits its commands are held to
//! ([`LiveLimits`]).

use palc_planner::State;
use palc_traffic::Scene;
use palc_user::Situation;
use serde::{Deserialize, Serialize};

use crate::HarnessError;

/// Largest lateral speed a configuration may allow (m/s).
pub const MAX_LATERAL_SPEED_BOUND_MPS: f64 = 10.0;

/// Largest acceleration or deceleration a configuration may allow (m/s²).
pub const MAX_LONGITUDINAL_BOUND_MPS2: f64 = 12.0;

/// A live driver's answer at one step.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct LiveInput {
    /// Whether the driver takes over (from this step on it drives; a takeover
    /// cannot be undone within the lane change).
    pub take_over: bool,
    /// After a takeover, the lateral speed commanded (m/s, positive to the
    /// left), held to [`LiveLimits::max_lateral_speed_mps`].
    pub lateral_speed_mps: f64,
    /// After a takeover, the acceleration commanded (m/s²), held to the limits;
    /// `None` leaves the speed to the ego's ACC, as a simulated user does.
    pub acceleration_mps2: Option<f64>,
}

/// The physical limits of a live driver's commands.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LiveLimits {
    /// Largest lateral speed (m/s). A driver who takes over 0.3 m from the path it
    /// expects steers back within a step or two at highway speeds.
    pub max_lateral_speed_mps: f64,
    /// Largest acceleration (m/s²).
    pub max_acceleration_mps2: f64,
    /// Largest deceleration (m/s², positive).
    pub max_deceleration_mps2: f64,
}

impl Default for LiveLimits {
    fn default() -> Self {
        Self {
            max_lateral_speed_mps: 4.0,
            max_acceleration_mps2: 3.0,
            max_deceleration_mps2: 8.0,
        }
    }
}

impl LiveLimits {
    /// Checks every limit is finite, positive and within its bound.
    ///
    /// # Errors
    /// [`HarnessError::InvalidConfig`] naming the field under `table`.
    pub fn validate(&self, table: &str) -> Result<(), HarnessError> {
        let checks = [
            (
                "max_lateral_speed_mps",
                self.max_lateral_speed_mps,
                MAX_LATERAL_SPEED_BOUND_MPS,
            ),
            (
                "max_acceleration_mps2",
                self.max_acceleration_mps2,
                MAX_LONGITUDINAL_BOUND_MPS2,
            ),
            (
                "max_deceleration_mps2",
                self.max_deceleration_mps2,
                MAX_LONGITUDINAL_BOUND_MPS2,
            ),
        ];
        for (field, value, bound) in checks {
            if !(value.is_finite() && value > 0.0 && value <= bound) {
                return Err(HarnessError::InvalidConfig {
                    field: format!("{table}.{field}"),
                    value,
                    bound: format!("in (0, {bound}]"),
                });
            }
        }
        Ok(())
    }

    /// `input`'s lateral speed held to the limit; a value that is not finite is 0.
    pub fn lateral_speed(&self, input: &LiveInput) -> f64 {
        let v = input.lateral_speed_mps;
        if v.is_finite() {
            v.clamp(-self.max_lateral_speed_mps, self.max_lateral_speed_mps)
        } else {
            0.0
        }
    }

    /// `input`'s acceleration held to the limits, or `acc` (the ACC's command)
    /// when it leaves the speed to the ACC or is not finite.
    pub fn acceleration(&self, input: &LiveInput, acc: f64) -> f64 {
        match input.acceleration_mps2 {
            Some(a) if a.is_finite() => {
                a.clamp(-self.max_deceleration_mps2, self.max_acceleration_mps2)
            }
            _ => acc,
        }
    }
}

/// What a live driver sees at one step of a lane change.
#[derive(Debug, Clone, Copy)]
pub struct LiveView<'a> {
    /// The step being decided (`0..=K`).
    pub step: usize,
    /// The step length (s).
    pub dt: f64,
    /// The ego's state at the previous step (plan frame); `None` at step 0.
    pub previous: Option<State>,
    /// The state the system drives the ego to at this step unless the driver
    /// takes over (plan frame); after a takeover, where the ego would be had it
    /// kept its lateral position.
    pub proposed: State,
    /// Whether the driver has taken over.
    pub taken_over: bool,
    /// The acceleration the ego's ACC would command now (m/s²).
    pub acc_mps2: f64,
    /// The scene at the previous step (at step 0, at the trigger).
    pub scene: &'a Scene,
    /// What a user sees in that scene.
    pub situation: &'a Situation,
}

/// A driver who decides in real time, step by step.
pub trait LiveDriver: std::fmt::Debug + Send {
    /// The driver's answer at the step of `view`.
    fn decide(&mut self, view: &LiveView<'_>) -> LiveInput;
}
