//! Predictions of the preceding and adjacent vehicles over a planning horizon: what the zone
//! filter and the planner consume, as plain `(s, l)` pairs.

use crate::error::SceneError;
use crate::scene::{Scene, check_dt};
use crate::vehicle::{EgoState, Vehicle};
use serde::{Deserialize, Serialize};

/// Largest prediction horizon (steps), so that a mistyped horizon cannot exhaust memory.
pub const MAX_HORIZON_STEPS: usize = 100_000;

/// How the surrounding vehicles are predicted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[non_exhaustive]
pub enum PredictionModel {
    /// Every vehicle keeps its current speed and lateral position: `s_i = s + v i dt`.
    ConstantSpeed,
    /// The whole background is rolled out with its own models (IDM, scripted profiles) on a
    /// copy of the scene, while the ego keeps its current speed and lateral position.
    IdmRollout,
}

/// Predicted positions at steps `i = 0..=K` (index 0 is the current position).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Prediction {
    /// Time step between points (s).
    pub dt: f64,
    /// `[s, l]` of the preceding vehicle per step (m).
    pub preceding: Vec<[f64; 2]>,
    /// `[s, l]` of the adjacent vehicle per step (m).
    pub adjacent: Vec<[f64; 2]>,
}

impl Scene {
    /// Predicts the preceding and adjacent vehicles over `k` steps of `dt` (K + 1 points).
    pub fn predict(
        &self,
        k: usize,
        dt: f64,
        model: PredictionModel,
    ) -> Result<Prediction, SceneError> {
        check_dt(dt)?;
        if k > MAX_HORIZON_STEPS {
            return Err(SceneError::HorizonTooLong {
                steps: k,
                max: MAX_HORIZON_STEPS,
            });
        }
        let preceding = self
            .preceding
            .ok_or(SceneError::MissingVehicle { role: "preceding" })?;
        let adjacent = self
            .adjacent
            .ok_or(SceneError::MissingVehicle { role: "adjacent" })?;
        let position = |v: &Vehicle| [v.state.s, v.state.l];
        match model {
            PredictionModel::ConstantSpeed => {
                let line = |v: &Vehicle| -> Vec<[f64; 2]> {
                    (0..=k)
                        .map(|i| [v.state.s + v.state.v * i as f64 * dt, v.state.l])
                        .collect()
                };
                Ok(Prediction {
                    dt,
                    preceding: line(&self.vehicles[preceding]),
                    adjacent: line(&self.vehicles[adjacent]),
                })
            }
            PredictionModel::IdmRollout => {
                let mut rollout = self.clone();
                let mut prediction = Prediction {
                    dt,
                    preceding: Vec::with_capacity(k + 1),
                    adjacent: Vec::with_capacity(k + 1),
                };
                for i in 0..=k {
                    prediction
                        .preceding
                        .push(position(&rollout.vehicles[preceding]));
                    prediction
                        .adjacent
                        .push(position(&rollout.vehicles[adjacent]));
                    if i == k {
                        break;
                    }
                    let ego_next = rollout.ego().map(|ego| EgoState {
                        s: ego.state.s + ego.state.v * dt,
                        l: ego.state.l,
                        v: ego.state.v,
                        heading: ego.state.heading,
                    });
                    rollout.advance(dt, ego_next);
                }
                Ok(prediction)
            }
        }
    }
}
