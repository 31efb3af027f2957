//! A platoon on one lane behind a scripted leader: the usual experiment for comparing IDM
//! implementations (a leader's speed profile propagating through the followers).

use crate::config::ScenarioConfig;
use crate::error::ConfigError;
use crate::road::Lane;
use crate::scene::{MAX_VEHICLES, Scene};
use crate::units::mph_to_mps;
use crate::validate::{in_range, out_of_range, positive, speed_mph};
use crate::vehicle::{Driver, SpeedProfile, Vehicle, VehicleId, VehicleState};

/// Builds the platoon scene: the leader (id 0) at `leader_start_s_m`, followers 1.. behind it
/// at `headway_m` front to front (or each at its own `followers` entry), all on `lane`.
pub(crate) fn build(config: &ScenarioConfig) -> Result<Scene, ConfigError> {
    let platoon = config.platoon.as_ref().ok_or(ConfigError::ScenarioKind {
        found: "no [platoon]",
    })?;
    let road = config.road()?;
    let count = platoon.vehicles as usize;
    if count == 0 || count > MAX_VEHICLES {
        return Err(out_of_range(
            "platoon.vehicles",
            count as f64,
            &format!("in [1, {MAX_VEHICLES}]"),
        ));
    }
    if platoon.lane >= road.lanes {
        return Err(out_of_range(
            "platoon.lane",
            f64::from(platoon.lane),
            &format!("below road.lanes = {}", road.lanes),
        ));
    }
    let headway = positive("platoon.headway_m", platoon.headway_m)?;
    let leader_s = in_range(
        "platoon.leader_start_s_m",
        platoon.leader_start_s_m,
        0.0,
        road.length,
        &format!("in [0, road.length_m = {:?}] m", road.length),
    )?;
    let v_init = mph_to_mps(speed_mph(
        "platoon.initial_speed_mph",
        platoon.initial_speed_mph,
        true,
    )?);
    let v0 = mph_to_mps(speed_mph(
        "platoon.desired_speed_mph",
        platoon.desired_speed_mph,
        false,
    )?);
    if v_init > v0 {
        return Err(ConfigError::SpeedAboveDesired {
            field: "platoon.initial_speed_mph".into(),
            speed_mps: v_init,
            v0_mps: v0,
        });
    }
    if platoon.leader_profile.is_empty() {
        return Err(ConfigError::Empty {
            field: "platoon.leader_profile".into(),
        });
    }
    let mut points = Vec::with_capacity(platoon.leader_profile.len());
    for (i, point) in platoon.leader_profile.iter().enumerate() {
        let t = in_range(
            &format!("platoon.leader_profile[{i}].time_s"),
            point.time_s,
            0.0,
            f64::MAX,
            "finite and at least 0",
        )?;
        let v = speed_mph(
            &format!("platoon.leader_profile[{i}].speed_mph"),
            point.speed_mph,
            true,
        )?;
        points.push((t, mph_to_mps(v)));
    }
    let profile = SpeedProfile::new(points).ok_or(ConfigError::InvalidProfile {
        reason: "times must be strictly increasing",
    })?;

    let lane = Lane(platoon.lane);
    let l = road.lane_centre(lane);
    let (length, width) = (config.vehicle.length_m, config.vehicle.width_m);
    // Per follower: (front-to-front headway to the vehicle ahead, initial speed).
    let mut followers = Vec::with_capacity(count - 1);
    if platoon.followers.is_empty() {
        followers.resize(count - 1, (headway, v_init));
    } else {
        if platoon.followers.len() != count - 1 {
            return Err(out_of_range(
                "platoon.followers",
                platoon.followers.len() as f64,
                &format!("exactly platoon.vehicles - 1 = {} entries", count - 1),
            ));
        }
        for (i, follower) in platoon.followers.iter().enumerate() {
            let headway = positive(
                &format!("platoon.followers[{i}].headway_m"),
                follower.headway_m,
            )?;
            let field = format!("platoon.followers[{i}].speed_mph");
            let v = mph_to_mps(speed_mph(&field, follower.speed_mph, true)?);
            if v > v0 {
                return Err(ConfigError::SpeedAboveDesired {
                    field,
                    speed_mps: v,
                    v0_mps: v0,
                });
            }
            followers.push((headway, v));
        }
    }
    let mut vehicles = Vec::with_capacity(count);
    let leader_v = profile.speed_at(0.0);
    let mut s = leader_s;
    for i in 0..count {
        if i > 0 {
            s -= followers[i - 1].0;
        }
        let id = VehicleId(i as u32);
        if s < 0.0 {
            return Err(ConfigError::OutsideSection {
                id,
                s_m: s,
                length_m: road.length,
                hint: "platoon.leader_start_s_m",
            });
        }
        let (v, driver) = if i == 0 {
            (leader_v, Driver::Scripted(profile.clone()))
        } else {
            (followers[i - 1].1, Driver::Idm(config.idm.params(v0)))
        };
        let state = VehicleState {
            s,
            l,
            v,
            a: 0.0,
            heading: 0.0,
        };
        vehicles.push(Vehicle {
            id,
            length,
            width,
            lane,
            state,
            driver,
        });
    }
    Scene::new(road, vehicles, config.idm.max_braking_mps2)
}
