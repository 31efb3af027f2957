//! A scene kept in step with a simulator outside palc: after each step, the ego's
//! state is the one supplied and every background vehicle's is the one the
//! simulator reports ([`Scene::step_observed`]).
//!
//! The scene then stays palc's view of that traffic: its roles, leaders, gaps and
//! collisions are read as after [`Scene::step`], and a clone of it predicts the
//! other vehicles by palc's own models from the reported states.

use crate::error::SceneError;
use crate::scene::{Scene, check_dt, check_ego};
use crate::vehicle::{Driver, EgoState, VehicleId, VehicleState};

/// A background vehicle's state as a simulator reports it after a step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Observed {
    /// The vehicle's identifier in the scene.
    pub id: VehicleId,
    /// Longitudinal position of the front bumper (m).
    pub s: f64,
    /// Lateral position of the centre line (m), positive to the left.
    pub l: f64,
    /// Longitudinal speed (m/s), never negative.
    pub v: f64,
}

impl Scene {
    /// Advances the scene by `dt` to the states an outside simulator reached: the ego
    /// at `ego`, every background vehicle at its entry of `observed` (its acceleration
    /// is its speed change over `dt`, its lane the one nearest to its lateral
    /// position). Every background vehicle must be reported exactly once.
    ///
    /// # Errors
    /// [`SceneError::InvalidTimeStep`], [`SceneError::InvalidEgoState`] and
    /// [`SceneError::NoEgo`] as [`Scene::step`]; [`SceneError::InvalidObservation`]
    /// for a report of an unknown vehicle, of the ego, of one vehicle twice, with a
    /// value that is not finite or a negative speed, and
    /// [`SceneError::MissingObservation`] for a background vehicle not reported.
    pub fn step_observed(
        &mut self,
        dt: f64,
        ego: EgoState,
        observed: &[Observed],
    ) -> Result<(), SceneError> {
        check_dt(dt)?;
        let Some(ego_index) = self.ego else {
            return Err(SceneError::NoEgo);
        };
        check_ego(&ego)?;
        let mut seen = vec![false; self.vehicles.len()];
        let mut updates = Vec::with_capacity(observed.len());
        for report in observed {
            let index = self
                .vehicles
                .iter()
                .position(|v| v.id == report.id && !matches!(v.driver, Driver::External { .. }))
                .ok_or(SceneError::InvalidObservation {
                    id: report.id.0,
                    field: "id",
                    value: f64::from(report.id.0),
                    bound: "a background vehicle of the scene",
                })?;
            let invalid = |field, value, bound| SceneError::InvalidObservation {
                id: report.id.0,
                field,
                value,
                bound,
            };
            if seen[index] {
                return Err(invalid(
                    "id",
                    f64::from(report.id.0),
                    "reported once per step",
                ));
            }
            seen[index] = true;
            for (field, value) in [("s", report.s), ("l", report.l)] {
                if !value.is_finite() {
                    return Err(invalid(field, value, "finite"));
                }
            }
            if !(report.v >= 0.0 && report.v.is_finite()) {
                return Err(invalid("v", report.v, "finite and at least 0"));
            }
            updates.push((index, report));
        }
        if let Some(missing) = (0..self.vehicles.len()).find(|&k| k != ego_index && !seen[k]) {
            return Err(SceneError::MissingObservation {
                id: self.vehicles[missing].id.0,
            });
        }
        for (index, report) in updates {
            let lane = self.road.nearest_lane(report.l);
            let vehicle = &mut self.vehicles[index];
            let state = &mut vehicle.state;
            *state = VehicleState {
                s: report.s,
                l: report.l,
                v: report.v,
                a: (report.v - state.v) / dt,
                heading: state.heading,
            };
            vehicle.lane = lane;
        }
        let vehicle = &mut self.vehicles[ego_index];
        let state = &mut vehicle.state;
        *state = VehicleState {
            s: ego.s,
            l: ego.l,
            v: ego.v,
            a: (ego.v - state.v) / dt,
            heading: ego.heading,
        };
        vehicle.lane = self.road.nearest_lane(ego.l);
        self.time += dt;
        Ok(())
    }

    /// The state of every background vehicle, as [`Scene::step_observed`] reads it.
    pub fn observed(&self) -> Vec<Observed> {
        self.vehicles
            .iter()
            .filter(|v| !matches!(v.driver, Driver::External { .. }))
            .map(|v| Observed {
                id: v.id,
                s: v.state.s,
                l: v.state.l,
                v: v.state.v,
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{PredictionModel, ScenarioConfig};

    fn scene() -> Scene {
        let config = ScenarioConfig::from_toml_str(
            r#"
            [testbed]
            speed_cases = [{ name = "collector-high", ego_mph = 45.0, others_mph = 40.0 }]
            adjacent_headways_m = [40.0]
            seeds = [7]
            "#,
        )
        .unwrap();
        Scene::from_config(&config, 0).unwrap()
    }

    fn keep_lane(scene: &Scene, dt: f64) -> EgoState {
        let ego = scene.ego().unwrap().state;
        EgoState {
            s: ego.s + ego.v * dt,
            l: ego.l,
            v: ego.v,
            heading: 0.0,
        }
    }

    #[test]
    fn a_scene_fed_its_own_steps_equals_the_scene_stepped() {
        let dt = 0.1;
        let mut own = scene();
        let mut mirrored = own.clone();
        for _ in 0..50 {
            let ego = keep_lane(&own, dt);
            own.step(dt, ego).unwrap();
            mirrored.step_observed(dt, ego, &own.observed()).unwrap();
            assert_eq!(own, mirrored);
        }
        let a = own.predict(20, dt, PredictionModel::IdmRollout).unwrap();
        let b = mirrored
            .predict(20, dt, PredictionModel::IdmRollout)
            .unwrap();
        assert_eq!(a.adjacent, b.adjacent);
    }

    #[test]
    fn a_missing_unknown_or_invalid_report_is_named() {
        let dt = 0.1;
        let mut mirrored = scene();
        let ego = keep_lane(&mirrored, dt);
        let mut reports = mirrored.observed();
        let dropped = reports.pop().unwrap();
        let error = mirrored.step_observed(dt, ego, &reports).unwrap_err();
        assert!(matches!(error, SceneError::MissingObservation { id } if id == dropped.id.0));
        reports.push(Observed {
            id: VehicleId(9_999),
            ..dropped
        });
        let error = mirrored.step_observed(dt, ego, &reports).unwrap_err();
        assert!(error.to_string().contains("9999"), "{error}");
        reports.pop();
        reports.push(Observed {
            v: f64::NAN,
            ..dropped
        });
        let error = mirrored.step_observed(dt, ego, &reports).unwrap_err();
        assert!(matches!(
            error,
            SceneError::InvalidObservation { field: "v", .. }
        ));
        let ego_report = Observed {
            id: VehicleId(0),
            ..dropped
        };
        let error = mirrored.step_observed(dt, ego, &[ego_report]).unwrap_err();
        assert!(matches!(
            error,
            SceneError::InvalidObservation { field: "id", .. }
        ));
    }
}
