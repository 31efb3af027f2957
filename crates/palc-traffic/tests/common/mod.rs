//! Fixtures shared by the integration tests: platoons built by hand.

#![allow(dead_code)]

use palc_traffic::{
    Driver, IdmParams, Lane, Road, Scene, SpeedProfile, Vehicle, VehicleId, VehicleState,
};

pub const LENGTH: f64 = 5.0;

/// A one-lane road long enough for every platoon in the tests.
pub fn road() -> Road {
    Road {
        length: 1e5,
        lane_width: 3.5,
        lanes: 1,
    }
}

pub fn vehicle(id: u32, s: f64, v: f64, driver: Driver) -> Vehicle {
    Vehicle {
        id: VehicleId(id),
        length: LENGTH,
        width: 1.8,
        lane: Lane(0),
        state: VehicleState {
            s,
            l: 0.0,
            v,
            a: 0.0,
            heading: 0.0,
        },
        driver,
    }
}

/// A scripted leader (id 0) at `s = 5000` followed by IDM vehicles at the given net gaps and speeds.
pub fn platoon(profile: SpeedProfile, idm: IdmParams, followers: &[(f64, f64)]) -> Scene {
    let leader_v = profile.speed_at(0.0);
    let mut vehicles = vec![vehicle(0, 5000.0, leader_v, Driver::Scripted(profile))];
    let mut s = 5000.0;
    for (i, &(gap, v)) in followers.iter().enumerate() {
        s -= LENGTH + gap;
        vehicles.push(vehicle(i as u32 + 1, s, v, Driver::Idm(idm)));
    }
    Scene::new(road(), vehicles, 9.0).expect("valid platoon")
}

/// Net gaps between consecutive vehicles, front to back.
pub fn net_gaps(scene: &Scene) -> Vec<f64> {
    scene
        .vehicles()
        .windows(2)
        .map(|w| w[0].rear() - w[1].state.s)
        .collect()
}
