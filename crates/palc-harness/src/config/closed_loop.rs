//! Closed-loop execution's parameters (`[planning.closed_loop]`): whether the
//! lane change is re-planned while it is driven, and how often.

use serde::{Deserialize, Serialize};

use crate::HarnessError;

/// Closed-loop execution (`[planning.closed_loop]`); defaults in `configs/learn.toml`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ClosedLoopConfig {
    /// Whether the lane change is re-planned while it is driven. Off by default:
    /// the paper's figures use one plan per lane change.
    pub enabled: bool,
    /// Time between re-plans (s): a multiple of `planning.dt`, at most the
    /// horizon. 0.1 s is 10 Hz.
    pub replan_period_s: f64,
}

impl Default for ClosedLoopConfig {
    fn default() -> Self {
        Self {
            enabled: false,
            replan_period_s: 0.1,
        }
    }
}

impl ClosedLoopConfig {
    /// Checks the period: finite and `> 0`, and, when closed loop is enabled, a
    /// whole number of steps of `dt` (a disabled table does not hold back a run at
    /// another step, e.g. the timing experiment's 0.2 s). `table` is the dotted
    /// path of the table (`planning.closed_loop`).
    ///
    /// # Errors
    /// [`HarnessError::InvalidConfig`] naming `{table}.replan_period_s`.
    pub fn validate(&self, table: &str, dt: f64) -> Result<(), HarnessError> {
        let field = format!("{table}.replan_period_s");
        let period = self.replan_period_s;
        if !(period.is_finite() && period > 0.0) {
            return Err(HarnessError::InvalidConfig {
                field,
                value: period,
                bound: "a finite value > 0".to_owned(),
            });
        }
        if !self.enabled {
            return Ok(());
        }
        let steps = period / dt;
        if !(steps.is_finite() && steps >= 0.5 && (steps - steps.round()).abs() <= 1e-6) {
            return Err(HarnessError::InvalidConfig {
                field,
                value: period,
                bound: format!("a whole multiple of planning.dt = {dt:?} s"),
            });
        }
        Ok(())
    }

    /// The period in steps of `dt` (valid after [`ClosedLoopConfig::validate`]).
    pub fn period_steps(&self, dt: f64) -> usize {
        ((self.replan_period_s / dt).round() as usize).max(1)
    }

    /// Checks the period against the horizon of a scenario (`K` steps of `dt`).
    ///
    /// # Errors
    /// [`HarnessError::InvalidConfig`] naming `{table}.replan_period_s` when the
    /// period is longer than the horizon.
    pub fn check_horizon(&self, table: &str, dt: f64, horizon: usize) -> Result<(), HarnessError> {
        if self.period_steps(dt) > horizon {
            return Err(HarnessError::InvalidConfig {
                field: format!("{table}.replan_period_s"),
                value: self.replan_period_s,
                bound: format!(
                    "at most the horizon, {horizon} steps of {dt:?} s ({:?} s)",
                    horizon as f64 * dt
                ),
            });
        }
        Ok(())
    }
}
