//! The paper's test bed (Section III.A): the ego behind a slower preceding vehicle on lane 0,
//! a platoon at the background speed on the target lane 1, and the grid of speed cases,
//! adjacent headways and seeds.
//!
//! Placement (docs/experiments/0015-test-bed-geometry-and-platoon.md):
//! - the ego (id 0) starts on lane 0 at `ego_start_s_m` with the case's ego speed;
//! - the preceding vehicle (id 1) starts `initial_time_headway_s` times the ego speed ahead,
//!   front to front, at the background speed, with IDM v0 equal to the background speed;
//! - an optional follower (id 2) starts `follower_headway_m` behind the ego, front to front;
//! - on lane 1 the adjacent vehicle starts `u H` ahead of the ego (front to front), with `u`
//!   drawn from `adjacent_phase` and `H` the adjacent headway; the rest of the platoon is
//!   spaced by `H` over the whole section `[0, length]`;
//! - every background vehicle but the preceding one gets a uniform position jitter.

use crate::config::{PrecedingBrakingConfig, ScenarioConfig, TestbedConfig};
use crate::error::ConfigError;
use crate::road::Lane;
use crate::scene::{MAX_VEHICLES, Scene};
use crate::units::{mph_to_mps, mps_to_mph};
use crate::validate::{MAX_SPEED_MPH, in_range, out_of_range, positive};
use crate::vehicle::{Driver, SpeedProfile, Vehicle, VehicleId, VehicleState};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

/// Largest `testbed.position_jitter_m` (m): half the test bed's road length, far
/// beyond any sensible jitter, and a bound that keeps every draw finite.
pub const MAX_POSITION_JITTER_M: f64 = 100.0;

/// One of the paper's speed cases, in SI units.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SpeedCase {
    /// Name used in reports, e.g. `collector-high`.
    pub name: String,
    /// Initial ego speed (m/s).
    pub ego_speed: f64,
    /// Speed of the background vehicles, and their IDM desired speed v0 (m/s).
    pub background_speed: f64,
}

impl SpeedCase {
    /// A speed case from speeds in mph, as the paper states them.
    pub fn from_mph(name: &str, ego_mph: f64, others_mph: f64) -> SpeedCase {
        SpeedCase {
            name: name.to_owned(),
            ego_speed: mph_to_mps(ego_mph),
            background_speed: mph_to_mps(others_mph),
        }
    }

    /// The paper's four speed cases: 45/40, 45/35, 65/60 and 65/55 mph (ego/others).
    pub fn paper() -> [SpeedCase; 4] {
        [
            SpeedCase::from_mph("collector-high", 45.0, 40.0),
            SpeedCase::from_mph("collector-slow", 45.0, 35.0),
            SpeedCase::from_mph("arterial-high", 65.0, 60.0),
            SpeedCase::from_mph("arterial-slow", 65.0, 55.0),
        ]
    }
}

/// Largest `testbed.preceding_braking.deceleration_mps2` (m/s^2): about the friction
/// limit of a passenger car on dry asphalt.
pub const MAX_PRECEDING_DECELERATION_MPS2: f64 = 10.0;

/// The preceding vehicle's speed profile of a braking stress scene: the background
/// speed until `start_s`, then a constant deceleration down to the final speed.
fn braking_profile(
    braking: &PrecedingBrakingConfig,
    v_bg: f64,
) -> Result<SpeedProfile, ConfigError> {
    let start = in_range(
        "testbed.preceding_braking.start_s",
        braking.start_s,
        0.0,
        3600.0,
        "in [0, 3600] s",
    )?;
    let deceleration = in_range(
        "testbed.preceding_braking.deceleration_mps2",
        braking.deceleration_mps2,
        0.1,
        MAX_PRECEDING_DECELERATION_MPS2,
        &format!("in [0.1, {MAX_PRECEDING_DECELERATION_MPS2}] m/s^2"),
    )?;
    let ratio = in_range(
        "testbed.preceding_braking.final_speed_ratio",
        braking.final_speed_ratio,
        0.0,
        0.99,
        "in [0, 0.99]",
    )?;
    let final_speed = ratio * v_bg;
    let end = start + (v_bg - final_speed) / deceleration;
    let points = if start > 0.0 {
        vec![(0.0, v_bg), (start, v_bg), (end, final_speed)]
    } else {
        vec![(0.0, v_bg), (end, final_speed)]
    };
    SpeedProfile::new(points).ok_or_else(|| {
        out_of_range(
            "testbed.preceding_braking",
            braking.deceleration_mps2,
            "a braking that ends after it starts",
        )
    })
}

/// The paper's adjacent-vehicle headways (m, front to front), from light to heavy congestion.
pub const PAPER_ADJACENT_HEADWAYS: [f64; 5] = [50.0, 45.0, 40.0, 35.0, 30.0];

/// One cell of the test-bed grid: a speed case, an adjacent headway and a seed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TestbedCell {
    /// The speed case.
    pub speed_case: SpeedCase,
    /// Front-to-front headway between consecutive target-lane vehicles (m).
    pub adjacent_headway: f64,
    /// Seed of every random draw of the cell.
    pub seed: u64,
}

impl TestbedConfig {
    /// The grid in order: speed case (outer), adjacent headway, seed (inner).
    pub fn cells(&self) -> Result<Vec<TestbedCell>, ConfigError> {
        if self.speed_cases.is_empty() {
            return Err(ConfigError::Empty {
                field: "testbed.speed_cases".into(),
            });
        }
        if self.adjacent_headways_m.is_empty() {
            return Err(ConfigError::Empty {
                field: "testbed.adjacent_headways_m".into(),
            });
        }
        if self.seeds.is_empty() {
            return Err(ConfigError::Empty {
                field: "testbed.seeds".into(),
            });
        }
        let mut cases = Vec::with_capacity(self.speed_cases.len());
        for (i, case) in self.speed_cases.iter().enumerate() {
            crate::validate::speed_mph(
                &format!("testbed.speed_cases[{i}].ego_mph"),
                case.ego_mph,
                false,
            )?;
            crate::validate::speed_mph(
                &format!("testbed.speed_cases[{i}].others_mph"),
                case.others_mph,
                false,
            )?;
            cases.push(SpeedCase::from_mph(
                &case.name,
                case.ego_mph,
                case.others_mph,
            ));
        }
        for (i, &headway) in self.adjacent_headways_m.iter().enumerate() {
            positive(&format!("testbed.adjacent_headways_m[{i}]"), headway)?;
        }
        let mut cells = Vec::new();
        for case in &cases {
            for &adjacent_headway in &self.adjacent_headways_m {
                for &seed in &self.seeds {
                    cells.push(TestbedCell {
                        speed_case: case.clone(),
                        adjacent_headway,
                        seed,
                    });
                }
            }
        }
        Ok(cells)
    }
}

impl ScenarioConfig {
    /// The test-bed grid of this config; see [`TestbedConfig::cells`].
    pub fn testbed_cells(&self) -> Result<Vec<TestbedCell>, ConfigError> {
        self.testbed
            .as_ref()
            .ok_or(ConfigError::NotATestbed)?
            .cells()
    }
}

/// Builds the scene of one test-bed cell.
pub(crate) fn build(config: &ScenarioConfig, cell: &TestbedCell) -> Result<Scene, ConfigError> {
    config.validate()?;
    let testbed = config.testbed.as_ref().ok_or(ConfigError::NotATestbed)?;
    let road = config.road()?;
    if road.lanes < 2 {
        return Err(out_of_range(
            "road.lanes",
            f64::from(road.lanes),
            "at least 2 for the test bed",
        ));
    }
    let case = &cell.speed_case;
    let max_speed = mph_to_mps(MAX_SPEED_MPH);
    let bound = format!("finite, above 0 and at most {max_speed} m/s");
    let v_ego = in_range(
        "speed_case.ego_speed",
        case.ego_speed,
        f64::MIN_POSITIVE,
        max_speed,
        &bound,
    )?;
    let v_bg = in_range(
        "speed_case.background_speed",
        case.background_speed,
        f64::MIN_POSITIVE,
        max_speed,
        &bound,
    )?;
    if v_bg >= v_ego {
        return Err(ConfigError::NotImpeded {
            case: case.name.clone(),
            ego_mph: mps_to_mph(v_ego),
            others_mph: mps_to_mph(v_bg),
        });
    }
    let headway = positive("testbed.adjacent_headways_m", cell.adjacent_headway)?;
    let ego_start = in_range(
        "testbed.ego_start_s_m",
        testbed.ego_start_s_m,
        0.0,
        road.length,
        &format!("in [0, road.length_m = {:?}] m", road.length),
    )?;
    let time_headway = positive(
        "testbed.initial_time_headway_s",
        testbed.initial_time_headway_s,
    )?;
    let [phase_min, phase_max] = testbed.adjacent_phase;
    in_range(
        "testbed.adjacent_phase[0]",
        phase_min,
        0.0,
        1.0,
        "in [0, 1]",
    )?;
    in_range(
        "testbed.adjacent_phase[1]",
        phase_max,
        phase_min,
        1.0,
        "in [adjacent_phase[0], 1]",
    )?;
    let jitter = in_range(
        "testbed.position_jitter_m",
        testbed.position_jitter_m,
        0.0,
        MAX_POSITION_JITTER_M,
        &format!("in [0, {MAX_POSITION_JITTER_M}] m"),
    )?;
    if let Some(follower) = testbed.follower_headway_m {
        positive("testbed.follower_headway_m", follower)?;
    }

    let length = config.vehicle.length_m;
    let width = config.vehicle.width_m;
    let idm = &config.idm;
    // Target-lane followers hold the background speed at the headway: their desired speed is
    // `desired_speed_ratio` times it and their time gap T solves s_e(v_bg) = H - length.
    let follower_v0 = idm.desired_speed_ratio * v_bg;
    let free = (1.0 - idm.desired_speed_ratio.powf(-idm.delta)).sqrt();
    let calibrated_t = ((headway - length) * free - idm.s0_m) / v_bg;
    if calibrated_t <= 0.0 || !calibrated_t.is_finite() {
        return Err(ConfigError::HeadwayCannotHold {
            field: "testbed.adjacent_headways_m".into(),
            headway_m: headway,
            speed_mps: v_bg,
            min_m: length + idm.s0_m / free,
        });
    }

    let mut rng = ChaCha8Rng::seed_from_u64(cell.seed);
    let phase = rng.random_range(phase_min..=phase_max);
    let mut draw_jitter = move || {
        if jitter > 0.0 {
            rng.random_range(-jitter..=jitter)
        } else {
            0.0
        }
    };

    let state = |s: f64, lane: Lane, v: f64| VehicleState {
        s,
        l: road.lane_centre(lane),
        v,
        a: 0.0,
        heading: 0.0,
    };
    let vehicle = |id: u32, lane: Lane, s: f64, v: f64, driver: Driver| Vehicle {
        id: VehicleId(id),
        length,
        width,
        lane,
        state: state(s, lane, v),
        driver,
    };
    let inside = |v: &Vehicle, hint: &'static str| {
        if v.state.s >= 0.0 && v.state.s <= road.length {
            Ok(())
        } else {
            Err(ConfigError::OutsideSection {
                id: v.id,
                s_m: v.state.s,
                length_m: road.length,
                hint,
            })
        }
    };

    let mut vehicles = Vec::new();
    vehicles.push(vehicle(
        0,
        Lane(0),
        ego_start,
        v_ego,
        Driver::External {
            stand_in: idm.params(v_ego),
        },
    ));
    let preceding_driver = match testbed.preceding_braking {
        None => Driver::Idm(idm.params(v_bg)),
        Some(braking) => Driver::Scripted(braking_profile(&braking, v_bg)?),
    };
    let preceding = vehicle(
        1,
        Lane(0),
        ego_start + time_headway * v_ego,
        v_bg,
        preceding_driver,
    );
    inside(&preceding, "testbed.initial_time_headway_s")?;
    vehicles.push(preceding);
    if let Some(follower_headway) = testbed.follower_headway_m {
        let s = ego_start - follower_headway + draw_jitter();
        let follower = vehicle(2, Lane(0), s, v_bg, Driver::Idm(idm.params(v_bg)));
        inside(&follower, "testbed.follower_headway_m")?;
        vehicles.push(follower);
    }

    let adjacent_s = ego_start + phase * headway;
    let k_min = (-adjacent_s / headway).ceil();
    let k_max = ((road.length - adjacent_s) / headway).floor();
    if k_max < 0.0 {
        return Err(ConfigError::OutsideSection {
            id: VehicleId(vehicles.len() as u32),
            s_m: adjacent_s,
            length_m: road.length,
            hint: "testbed.ego_start_s_m",
        });
    }
    if k_max - k_min + 1.0 + vehicles.len() as f64 > MAX_VEHICLES as f64 {
        return Err(out_of_range(
            "road.length_m",
            road.length,
            &format!("short enough for at most {MAX_VEHICLES} vehicles at this headway"),
        ));
    }
    // Both bounds are integers within +-MAX_VEHICLES here, so the casts are exact.
    let (k_min, k_max) = (k_min as i64, k_max as i64);
    let mut adjacent = 0;
    for k in (k_min..=k_max).rev() {
        let id = vehicles.len() as u32;
        let params = if k == k_max {
            idm.params(v_bg)
        } else {
            crate::idm::IdmParams {
                v0: follower_v0,
                t: calibrated_t,
                ..idm.params(v_bg)
            }
        };
        let s = adjacent_s + k as f64 * headway + draw_jitter();
        let target = vehicle(id, Lane(1), s, v_bg, Driver::Idm(params));
        if k == 0 {
            adjacent = vehicles.len();
        }
        vehicles.push(target);
    }

    let mut scene = Scene::new(road, vehicles, idm.max_braking_mps2)?;
    scene.preceding = Some(1);
    scene.adjacent = Some(adjacent);
    match testbed.lag_accelerating {
        Some(lag) => scene.with_lag_accelerating(lag),
        None => Ok(scene),
    }
}

impl Scene {
    /// Builds the scene of one test-bed cell of `config` (which must have a `[testbed]` table).
    pub fn for_cell(config: &ScenarioConfig, cell: &TestbedCell) -> Result<Scene, ConfigError> {
        build(config, cell)
    }

    /// Builds the scene a config describes: for a test bed, the cell with index `cell` of
    /// [`ScenarioConfig::testbed_cells`]; for a platoon, the platoon (`cell` must be 0).
    pub fn from_config(config: &ScenarioConfig, cell: usize) -> Result<Scene, ConfigError> {
        config.validate()?;
        if config.platoon.is_some() {
            if cell != 0 {
                return Err(ConfigError::NoSuchCell {
                    index: cell,
                    cells: 1,
                });
            }
            return crate::platoon::build(config);
        }
        let cells = config.testbed_cells()?;
        let chosen = cells.get(cell).ok_or(ConfigError::NoSuchCell {
            index: cell,
            cells: cells.len(),
        })?;
        build(config, chosen)
    }
}
