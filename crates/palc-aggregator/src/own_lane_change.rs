//! The user's own lane change as last seen whole: what the experience keeps of
//! its shape, so that a later lesson that sees only the end of a lane change can
//! place its start by the user's own shape rather than by a model's.
//!
//! The aggregator stores and checks it; the harness records it (from a lesson in
//! which the user was seen at rest before it moved) and fits later lessons with it.

use serde::{Deserialize, Serialize};

use crate::AggregatorError;

/// Fewest samples of a stored shape: its two ends.
pub const MIN_OWN_LANE_CHANGE_SAMPLES: usize = 2;
/// Most samples of a stored shape: a minute of lane change at 100 Hz.
pub const MAX_OWN_LANE_CHANGE_SAMPLES: usize = 6_000;

/// The fraction of the lane change done (0 at its start, 1 at its end) at equally
/// spaced fractions of its duration, from the start to the end: a shape that a
/// lane change of any duration and lane width stretches over itself.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OwnLaneChange {
    /// `progress[i]` is the fraction done at `i / (len − 1)` of the duration;
    /// from 0 to 1, never decreasing.
    pub progress: Vec<f64>,
}

impl OwnLaneChange {
    /// Checks the invariants of a stored shape: [`MIN_OWN_LANE_CHANGE_SAMPLES`] to
    /// [`MAX_OWN_LANE_CHANGE_SAMPLES`] finite samples, starting at 0, ending at 1
    /// and never decreasing.
    ///
    /// # Errors
    /// [`AggregatorError::NonFinite`] or [`AggregatorError::OutOfRange`] naming
    /// `own_lane_change.progress` (with the sample's index), the value and the bound.
    pub fn validate(&self) -> Result<(), AggregatorError> {
        let field = |i: usize| format!("own_lane_change.progress[{i}]");
        let out_of_range = |field: String, value: f64, bound: &str| AggregatorError::OutOfRange {
            field,
            value,
            bound: bound.to_owned(),
        };
        let n = self.progress.len();
        if !(MIN_OWN_LANE_CHANGE_SAMPLES..=MAX_OWN_LANE_CHANGE_SAMPLES).contains(&n) {
            return Err(out_of_range(
                "own_lane_change.progress".into(),
                n as f64,
                &format!("{MIN_OWN_LANE_CHANGE_SAMPLES} to {MAX_OWN_LANE_CHANGE_SAMPLES} samples"),
            ));
        }
        let mut before = 0.0;
        for (i, &p) in self.progress.iter().enumerate() {
            if !p.is_finite() {
                return Err(AggregatorError::NonFinite {
                    field: field(i),
                    value: p,
                });
            }
            if !(0.0..=1.0).contains(&p) {
                return Err(out_of_range(
                    field(i),
                    p,
                    "a fraction of the lane change in [0, 1]",
                ));
            }
            if p < before {
                return Err(out_of_range(
                    field(i),
                    p,
                    &format!("at least the sample before ({before}): the shape never turns back"),
                ));
            }
            before = p;
        }
        if self.progress[0] != 0.0 {
            return Err(out_of_range(
                field(0),
                self.progress[0],
                "0 (the lane change's start)",
            ));
        }
        if self.progress[n - 1] != 1.0 {
            return Err(out_of_range(
                field(n - 1),
                self.progress[n - 1],
                "1 (the lane change's end)",
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shape(progress: &[f64]) -> OwnLaneChange {
        OwnLaneChange {
            progress: progress.to_vec(),
        }
    }

    #[test]
    fn a_shape_from_zero_to_one_that_never_turns_back_is_valid() {
        assert!(shape(&[0.0, 1.0]).validate().is_ok());
        assert!(shape(&[0.0, 0.1, 0.1, 0.7, 1.0]).validate().is_ok());
    }

    #[test]
    fn a_bad_shape_is_refused_naming_the_sample_and_the_bound() {
        let message = |progress: &[f64]| shape(progress).validate().unwrap_err().to_string();
        let turns_back = message(&[0.0, 0.5, 0.4, 1.0]);
        assert!(
            turns_back.contains("own_lane_change.progress[2]"),
            "{turns_back}"
        );
        assert!(
            turns_back.contains("0.4") && turns_back.contains("never turns back"),
            "{turns_back}"
        );
        assert!(message(&[0.0, f64::NAN, 1.0]).contains("progress[1]"));
        assert!(message(&[0.0, 1.5]).contains("[0, 1]"));
        assert!(message(&[0.1, 1.0]).contains("start"));
        assert!(message(&[0.0, 0.9]).contains("end"));
        assert!(message(&[0.0]).contains("samples"));
    }
}
