//! A scene: the road, its vehicles and the rules that advance them in time.

use crate::config::LagAcceleratingConfig;
use crate::error::{ConfigError, SceneError};
use crate::idm::ballistic_step;
use crate::road::{Lane, Road};
use crate::vehicle::{Driver, EgoState, Vehicle, VehicleId, VehicleState};

/// Largest time step a scene accepts (s); the ballistic IDM update is accurate well below it.
pub const MAX_DT: f64 = 1.0;

/// Largest number of vehicles a scene accepts, so that a mistyped config cannot exhaust memory.
pub const MAX_VEHICLES: usize = 10_000;

/// A road with vehicles at one instant, advanced by [`Scene::step`].
///
/// The ego (if any) is never driven by the IDM: its state is supplied from outside at every
/// step. Background vehicles follow the IDM behind the nearest vehicle ahead that occupies
/// their lane, or a scripted speed profile. `Scene` is `Clone` so that identical scenarios
/// can be replayed.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    pub(crate) road: Road,
    pub(crate) time: f64,
    pub(crate) max_braking: f64,
    pub(crate) vehicles: Vec<Vehicle>,
    pub(crate) ego: Option<usize>,
    pub(crate) preceding: Option<usize>,
    pub(crate) adjacent: Option<usize>,
    /// The accelerating lag vehicle of a stress scene, if armed.
    pub(crate) lag_push: Option<LagPush>,
}

/// The state of the accelerating lag vehicle in a scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct LagPush {
    pub(crate) config: LagAcceleratingConfig,
    /// The ego's lateral position at the start of the scene (m).
    pub(crate) start_l: f64,
    /// The index of the vehicle that accelerates, once triggered.
    pub(crate) pushing: Option<usize>,
}

impl Scene {
    /// Builds a scene from vehicles placed by hand, at time 0, without preceding or adjacent
    /// roles. The vehicle driven by [`Driver::External`], if any, is the ego; there may be at
    /// most one. IDM decelerations are clipped to `max_braking` (m/s^2, positive).
    pub fn new(road: Road, vehicles: Vec<Vehicle>, max_braking: f64) -> Result<Scene, ConfigError> {
        crate::validate::positive("max_braking", max_braking)?;
        if vehicles.len() > MAX_VEHICLES {
            return Err(crate::validate::out_of_range(
                "vehicles",
                vehicles.len() as f64,
                &format!("at most {MAX_VEHICLES} vehicles"),
            ));
        }
        let mut ego = None;
        for (index, vehicle) in vehicles.iter().enumerate() {
            let field = |name: &str| format!("vehicle {}.{name}", vehicle.id.0);
            crate::validate::positive(&field("length"), vehicle.length)?;
            crate::validate::positive(&field("width"), vehicle.width)?;
            crate::validate::in_range(&field("s"), vehicle.state.s, f64::MIN, f64::MAX, "finite")?;
            crate::validate::in_range(&field("l"), vehicle.state.l, f64::MIN, f64::MAX, "finite")?;
            crate::validate::non_negative(&field("v"), vehicle.state.v)?;
            if vehicle.lane.0 >= road.lanes {
                return Err(crate::validate::out_of_range(
                    &field("lane"),
                    f64::from(vehicle.lane.0),
                    &format!("below the number of lanes, {}", road.lanes),
                ));
            }
            if matches!(vehicle.driver, Driver::External { .. }) {
                if ego.is_some() {
                    return Err(crate::validate::out_of_range(
                        &field("driver"),
                        2.0,
                        "at most 1 external (ego) vehicle",
                    ));
                }
                ego = Some(index);
            }
            if vehicles[..index].iter().any(|other| other.id == vehicle.id) {
                return Err(crate::validate::out_of_range(
                    &field("id"),
                    f64::from(vehicle.id.0),
                    "unique in the scene",
                ));
            }
        }
        let scene = Scene {
            road,
            time: 0.0,
            max_braking,
            vehicles,
            ego,
            preceding: None,
            adjacent: None,
            lag_push: None,
        };
        scene.check_no_overlap()?;
        Ok(scene)
    }

    /// The road.
    pub fn road(&self) -> &Road {
        &self.road
    }

    /// Simulated time since the scene was built (s).
    pub fn time(&self) -> f64 {
        self.time
    }

    /// All vehicles; the ego, when present, is first.
    pub fn vehicles(&self) -> &[Vehicle] {
        &self.vehicles
    }

    /// The vehicle with identifier `id`.
    pub fn vehicle(&self, id: VehicleId) -> Option<&Vehicle> {
        self.vehicles.iter().find(|v| v.id == id)
    }

    /// The ego vehicle, driven from outside.
    pub fn ego(&self) -> Option<&Vehicle> {
        self.ego.map(|i| &self.vehicles[i])
    }

    /// The slower vehicle ahead of the ego on lane 0 that impedes it (fixed at construction).
    pub fn preceding(&self) -> Option<&Vehicle> {
        self.preceding.map(|i| &self.vehicles[i])
    }

    /// The target-lane vehicle the ego follows after its lane change (fixed at construction).
    pub fn adjacent(&self) -> Option<&Vehicle> {
        self.adjacent.map(|i| &self.vehicles[i])
    }

    /// This scene with its preceding and adjacent vehicles named by hand (a scene
    /// built with [`Scene::new`] has neither; the test bed sets both).
    ///
    /// # Errors
    /// [`ConfigError::OutOfRange`] naming `preceding` or `adjacent` when no vehicle
    /// of the scene has that identifier, or when it is the ego.
    pub fn with_roles(
        mut self,
        preceding: VehicleId,
        adjacent: VehicleId,
    ) -> Result<Scene, ConfigError> {
        let find = |field: &str, id: VehicleId| {
            self.vehicles
                .iter()
                .position(|v| v.id == id && !matches!(v.driver, Driver::External { .. }))
                .ok_or_else(|| {
                    crate::validate::out_of_range(
                        field,
                        f64::from(id.0),
                        "a background vehicle of the scene",
                    )
                })
        };
        let (p, a) = (find("preceding", preceding)?, find("adjacent", adjacent)?);
        self.preceding = Some(p);
        self.adjacent = Some(a);
        Ok(self)
    }

    /// Whether vehicle `index` occupies `lane`: background vehicles occupy their own lane; the
    /// ego occupies every lane its body overlaps laterally (see [`Road::occupies`]).
    fn occupies(&self, index: usize, lane: Lane) -> bool {
        let vehicle = &self.vehicles[index];
        match vehicle.driver {
            Driver::External { .. } => self.road.occupies(vehicle.state.l, vehicle.width, lane),
            _ => vehicle.lane == lane,
        }
    }

    /// The lane whose traffic vehicle `index` reacts to: its own lane, or for the ego the lane
    /// nearest to its lateral position.
    fn reference_lane(&self, index: usize) -> Lane {
        let vehicle = &self.vehicles[index];
        match vehicle.driver {
            Driver::External { .. } => self.road.nearest_lane(vehicle.state.l),
            _ => vehicle.lane,
        }
    }

    /// The leader of vehicle `id`: the vehicle occupying its lane whose front is nearest ahead
    /// of its front, with the net (bumper-to-bumper) gap to it, which may be negative when a
    /// vehicle cuts in beside it.
    pub fn leader_of(&self, id: VehicleId) -> Option<(VehicleId, f64)> {
        let index = self.vehicles.iter().position(|v| v.id == id)?;
        self.leader_index(index)
            .map(|(k, gap)| (self.vehicles[k].id, gap))
    }

    fn leader_index(&self, index: usize) -> Option<(usize, f64)> {
        let lane = self.reference_lane(index);
        let s = self.vehicles[index].state.s;
        (0..self.vehicles.len())
            .filter(|&k| k != index && self.vehicles[k].state.s > s && self.occupies(k, lane))
            .min_by(|&a, &b| {
                self.vehicles[a]
                    .state
                    .s
                    .total_cmp(&self.vehicles[b].state.s)
            })
            .map(|k| (k, self.vehicles[k].rear() - s))
    }

    /// Pairs `(behind, ahead)` of vehicles that occupy a common lane and overlap
    /// longitudinally (net gap not positive). Empty in a collision-free scene.
    pub fn collisions(&self) -> Vec<(VehicleId, VehicleId)> {
        let mut pairs = Vec::new();
        for lane in (0..self.road.lanes).map(Lane) {
            let mut on_lane: Vec<usize> = (0..self.vehicles.len())
                .filter(|&k| self.occupies(k, lane))
                .collect();
            on_lane.sort_by(|&a, &b| {
                self.vehicles[a]
                    .state
                    .s
                    .total_cmp(&self.vehicles[b].state.s)
            });
            for pair in on_lane.windows(2) {
                let (back, front) = (&self.vehicles[pair[0]], &self.vehicles[pair[1]]);
                if front.rear() - back.state.s <= 0.0 && !pairs.contains(&(back.id, front.id)) {
                    pairs.push((back.id, front.id));
                }
            }
        }
        pairs
    }

    fn check_no_overlap(&self) -> Result<(), ConfigError> {
        for lane in (0..self.road.lanes).map(Lane) {
            let mut on_lane: Vec<usize> = (0..self.vehicles.len())
                .filter(|&k| self.vehicles[k].lane == lane)
                .collect();
            on_lane.sort_by(|&a, &b| {
                self.vehicles[a]
                    .state
                    .s
                    .total_cmp(&self.vehicles[b].state.s)
            });
            for pair in on_lane.windows(2) {
                let (back, front) = (&self.vehicles[pair[0]], &self.vehicles[pair[1]]);
                let gap_m = front.rear() - back.state.s;
                if gap_m <= 0.0 {
                    return Err(ConfigError::Overlap {
                        lane,
                        front: front.id,
                        back: back.id,
                        gap_m,
                    });
                }
            }
        }
        Ok(())
    }

    /// Advances the scene by `dt` with the ego's state at the end of the step supplied from
    /// outside.
    ///
    /// The update is synchronous: every background acceleration is computed from the states at
    /// the start of the step (the ego's included), then every vehicle moves. IDM vehicles use
    /// the ballistic update of [`ballistic_step`]; the ego's recorded acceleration is its speed
    /// change over `dt`.
    pub fn step(&mut self, dt: f64, ego: EgoState) -> Result<(), SceneError> {
        check_dt(dt)?;
        if self.ego.is_none() {
            return Err(SceneError::NoEgo);
        }
        check_ego(&ego)?;
        self.advance(dt, Some(ego));
        Ok(())
    }

    /// Advances the scene by `dt` with every vehicle driven by its own model; the ego, if
    /// any, keeps its lateral position and follows its stand-in IDM in the nearest lane.
    ///
    /// This is how `palc traffic simulate` runs a test-bed scene without a planner.
    pub fn step_autonomous(&mut self, dt: f64) -> Result<(), SceneError> {
        check_dt(dt)?;
        self.advance(dt, None);
        Ok(())
    }

    /// One synchronous update; `ego_next` replaces the ego's stand-in when given.
    pub(crate) fn advance(&mut self, dt: f64, ego_next: Option<EgoState>) {
        self.trigger_lag_push();
        let accelerations: Vec<f64> = (0..self.vehicles.len())
            .map(|i| self.model_acceleration(i))
            .collect();
        let t0 = self.time;
        for (vehicle, acc) in self.vehicles.iter_mut().zip(accelerations) {
            let state = &mut vehicle.state;
            match (&vehicle.driver, ego_next) {
                (Driver::External { .. }, Some(next)) => {
                    state.a = (next.v - state.v) / dt;
                    *state = VehicleState {
                        s: next.s,
                        l: next.l,
                        v: next.v,
                        a: state.a,
                        heading: next.heading,
                    };
                    vehicle.lane = self.road.nearest_lane(next.l);
                }
                (Driver::Scripted(profile), _) => {
                    let v = profile.speed_at(t0 + dt);
                    state.s += profile.distance(t0, t0 + dt);
                    state.a = (v - state.v) / dt;
                    state.v = v;
                }
                _ => {
                    let moved = ballistic_step(state.v, acc, dt);
                    state.s += moved.distance;
                    state.a = (moved.speed - state.v) / dt;
                    state.v = moved.speed;
                }
            }
        }
        self.time = t0 + dt;
    }

    /// The IDM acceleration of vehicle `index` at the current states, clipped to the braking
    /// limit; zero for scripted vehicles (they do not use it).
    fn model_acceleration(&self, index: usize) -> f64 {
        let params = match &self.vehicles[index].driver {
            Driver::Idm(params) | Driver::External { stand_in: params } => params,
            Driver::Scripted(_) => return 0.0,
        };
        let v = self.vehicles[index].state.v;
        let leader = self
            .leader_index(index)
            .map(|(k, gap)| (gap, v - self.vehicles[k].state.v));
        params.acceleration_behind(v, leader).max(-self.max_braking)
    }
}

pub(crate) fn check_dt(dt: f64) -> Result<(), SceneError> {
    if dt > 0.0 && dt <= MAX_DT {
        Ok(())
    } else {
        Err(SceneError::InvalidTimeStep { dt, max: MAX_DT })
    }
}

pub(crate) fn check_ego(ego: &EgoState) -> Result<(), SceneError> {
    let finite = [("s", ego.s), ("l", ego.l), ("heading", ego.heading)];
    if let Some(&(field, value)) = finite.iter().find(|(_, value)| !value.is_finite()) {
        return Err(SceneError::InvalidEgoState {
            field,
            value,
            bound: "finite",
        });
    }
    if !(ego.v >= 0.0 && ego.v.is_finite()) {
        return Err(SceneError::InvalidEgoState {
            field: "v",
            value: ego.v,
            bound: "finite and at least 0",
        });
    }
    Ok(())
}
