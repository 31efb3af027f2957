//! A stress scene: a vehicle on the target lane that accelerates into the gap
//! when the ego starts its lane change (`[testbed.lag_accelerating]`).
//!
//! The trigger is the ego's own motion, which the scene sees: once the ego's
//! lateral offset from the centre of the lane it started in reaches
//! `trigger_lateral_m` towards the neighbouring lane, the vehicle nearest behind
//! the ego's front on that lane (the lag vehicle) switches to a pushier IDM: its
//! maximum acceleration becomes `acceleration_mps2` and its desired speed
//! `speed_ratio` times its speed at the trigger. It still brakes for whatever
//! occupies its lane ahead, the ego included once the ego's body enters it, so it
//! closes the gap without ramming: the ego finds a shrinking gap, below the safe
//! distance if it goes on.
//!
//! The table is [`LagAcceleratingConfig`], kept with the other tables in `config.rs`,
//! and the armed state a field of the [`Scene`] (`LagPush`); this module holds the
//! behaviour.

use crate::config::LagAcceleratingConfig;
use crate::error::ConfigError;
use crate::road::Lane;
use crate::scene::{LagPush, Scene};
use crate::vehicle::Driver;

impl Scene {
    /// Arms the accelerating lag vehicle of `config` on this scene, the ego's
    /// current lateral position being its start.
    ///
    /// # Errors
    /// A config out of its bounds, naming the field.
    pub fn with_lag_accelerating(
        mut self,
        config: LagAcceleratingConfig,
    ) -> Result<Scene, ConfigError> {
        config.validate(self.road.lane_width)?;
        let start_l = self.ego().map_or(0.0, |e| e.state.l);
        self.lag_push = Some(LagPush {
            config,
            start_l,
            pushing: None,
        });
        Ok(self)
    }

    /// The identifier of the vehicle that accelerates into the gap, once the ego
    /// has triggered it.
    pub fn accelerating_lag(&self) -> Option<crate::VehicleId> {
        let push = self.lag_push?;
        push.pushing.map(|k| self.vehicles[k].id)
    }

    /// Before a step: triggers the lag vehicle when the ego has moved far enough
    /// towards the neighbouring lane.
    pub(crate) fn trigger_lag_push(&mut self) {
        let Some(push) = self.lag_push else { return };
        if push.pushing.is_some() {
            return;
        }
        let Some(ego) = self.ego.map(|k| &self.vehicles[k]) else {
            return;
        };
        let offset = ego.state.l - push.start_l;
        if offset.abs() < push.config.trigger_lateral_m {
            return;
        }
        let start = self.road.nearest_lane(push.start_l);
        let target = if offset > 0.0 {
            Lane(start.0 + 1)
        } else {
            match start.0.checked_sub(1) {
                Some(lane) => Lane(lane),
                None => return,
            }
        };
        let ego_s = ego.state.s;
        let lag = (0..self.vehicles.len())
            .filter(|&k| {
                let v = &self.vehicles[k];
                v.lane == target && v.state.s <= ego_s && matches!(v.driver, Driver::Idm(_))
            })
            .max_by(|&a, &b| {
                self.vehicles[a]
                    .state
                    .s
                    .total_cmp(&self.vehicles[b].state.s)
            });
        let Some(lag) = lag else { return };
        let vehicle = &mut self.vehicles[lag];
        if let Driver::Idm(params) = &mut vehicle.driver {
            params.a = push.config.acceleration_mps2;
            params.v0 = push.config.speed_ratio * vehicle.state.v;
        }
        self.lag_push = Some(LagPush {
            pushing: Some(lag),
            ..push
        });
    }
}
