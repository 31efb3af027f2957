//! The plain data of an exported scenario: a straight two-lane road, the other
//! vehicles as dynamic obstacles, and one planning problem for the ego.
//!
//! Coordinates are CommonRoad's: `x` along the road, `y` to the left, the right
//! lane's centre at `y = 0` and the left lane's at `y = lane_width` (palc's
//! Frenet frame on a straight road, `x = s`, `y = l`). Every position is the
//! **centre** of a vehicle, as CommonRoad wants it; [`Pose::centre_from_front_bumper`]
//! converts palc's front-bumper positions.

use crate::export::error::ExportError;

/// CommonRoad ID of the right lane's lanelet.
pub const RIGHT_LANELET_ID: u32 = 1;
/// CommonRoad ID of the left lane's lanelet.
pub const LEFT_LANELET_ID: u32 = 2;

/// One of the road's two lanes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Lane {
    /// The right lane, centre at `y = 0` (palc's lane 0).
    #[default]
    Right,
    /// The left lane, centre at `y = lane_width` (palc's lane 1).
    Left,
}

impl Lane {
    /// The other lane: the target of a lane change that starts in this one.
    pub fn other(self) -> Lane {
        match self {
            Lane::Right => Lane::Left,
            Lane::Left => Lane::Right,
        }
    }

    /// The lane's centre line `y` on a road of `lane_width` (m).
    pub fn centre_y(self, lane_width: f64) -> f64 {
        match self {
            Lane::Right => 0.0,
            Lane::Left => lane_width,
        }
    }

    /// The lane's lanelet ID.
    pub fn lanelet_id(self) -> u32 {
        match self {
            Lane::Right => RIGHT_LANELET_ID,
            Lane::Left => LEFT_LANELET_ID,
        }
    }
}

/// A straight road of two lanes in the same direction, along `x`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Road {
    /// Width of each lane (m).
    pub lane_width: f64,
    /// Where the road starts (m); behind every vehicle of the scenario.
    pub x_start: f64,
    /// Where the road ends (m); beyond the end of the lane change.
    pub x_end: f64,
    /// The lane the ego starts in; the other lane is the goal's.
    pub ego_lane: Lane,
}

/// A vehicle's position, heading and speed at one instant.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Pose {
    /// Position along the road (m).
    pub x: f64,
    /// Lateral position, positive to the left (m).
    pub y: f64,
    /// Heading from the `x` axis, positive to the left (rad).
    pub orientation: f64,
    /// Speed along the heading (m/s).
    pub velocity: f64,
}

impl Pose {
    /// The centre of a vehicle of `length` whose front bumper's midpoint is at
    /// this pose (palc's `s` is the front bumper): half a length back along the
    /// heading. Orientation and velocity are kept.
    pub fn centre_from_front_bumper(self, length: f64) -> Pose {
        let (sin, cos) = self.orientation.sin_cos();
        Pose {
            x: self.x - 0.5 * length * cos,
            y: self.y - 0.5 * length * sin,
            ..self
        }
    }

    /// The centre of a vehicle whose rear axle is at this pose: `rear_to_centre`
    /// (the model's `b`, [`crate::export::VehicleType::rear_axle_to_centre`])
    /// ahead along the heading. The kinematic single-track model moves the rear
    /// axle along the heading, so a path planned with that model (`y' = v ψ`, as
    /// palc's planner does) is the rear axle's.
    pub fn centre_from_rear_axle(self, rear_to_centre: f64) -> Pose {
        let (sin, cos) = self.orientation.sin_cos();
        Pose {
            x: self.x + rear_to_centre * cos,
            y: self.y + rear_to_centre * sin,
            ..self
        }
    }
}

/// The state of an obstacle at one time step (its centre).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ObstacleState {
    /// Time step (a multiple of the scenario's `dt`).
    pub time_step: u32,
    /// Centre, along the road (m).
    pub x: f64,
    /// Centre, lateral (m).
    pub y: f64,
    /// Heading (rad).
    pub orientation: f64,
    /// Speed (m/s).
    pub velocity: f64,
    /// Acceleration (m/s²).
    pub acceleration: f64,
}

/// Another vehicle, written as a CommonRoad `dynamicObstacle` of type `car`.
#[derive(Debug, Clone, PartialEq)]
pub struct DynamicObstacle {
    /// Unique ID in the scenario (not 1 or 2, the lanelets', nor the planning
    /// problem's).
    pub id: u32,
    /// Length (m).
    pub length: f64,
    /// Width (m).
    pub width: f64,
    /// One state per time step, rising by one; the first is the `initialState`,
    /// the others the `trajectory`.
    pub states: Vec<ObstacleState>,
}

/// The ego's state where the planning problem starts (its centre).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct InitialState {
    /// Time step.
    pub time_step: u32,
    /// Centre, along the road (m).
    pub x: f64,
    /// Centre, lateral (m).
    pub y: f64,
    /// Heading (rad).
    pub orientation: f64,
    /// Speed (m/s).
    pub velocity: f64,
    /// Yaw rate (rad/s).
    pub yaw_rate: f64,
    /// Slip angle (rad); 0 for a kinematic model.
    pub slip_angle: f64,
}

/// The goal: the target lane's area (the lane other than [`Road::ego_lane`], over
/// the road's whole extent) within a time interval.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct GoalRegion {
    /// First time step at which the goal counts.
    pub time_start: u32,
    /// Last time step at which the goal counts.
    pub time_end: u32,
}

/// The ego's planning problem.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanningProblem {
    /// Unique ID in the scenario.
    pub id: u32,
    /// Where the ego starts; a solution's first state equals it.
    pub initial: InitialState,
    /// Where and when the ego must be.
    pub goal: GoalRegion,
}

/// A whole scenario: road, obstacles and the ego's planning problem.
#[derive(Debug, Clone, PartialEq)]
pub struct Scenario {
    /// The CommonRoad benchmark ID, e.g. `ZAM_Palc-1_1_T-1`.
    pub id: String,
    /// Time step size (s).
    pub dt: f64,
    /// The `author` attribute.
    pub author: String,
    /// The `affiliation` attribute.
    pub affiliation: String,
    /// The `source` attribute: where the scenario comes from.
    pub source: String,
    /// The `date` attribute (`YYYY-MM-DD`); omitted when `None`, so that the
    /// same scene gives the same bytes on any day.
    pub date: Option<String>,
    /// The road.
    pub road: Road,
    /// The other vehicles.
    pub obstacles: Vec<DynamicObstacle>,
    /// The ego's planning problem.
    pub planning_problem: PlanningProblem,
}

/// Checks that `value` is finite, naming it.
pub(crate) fn finite(
    owner: &dyn Fn() -> String,
    field: &'static str,
    step: usize,
    value: f64,
) -> Result<(), ExportError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(ExportError::NotFinite {
            owner: owner(),
            field,
            step,
            value,
        })
    }
}

/// Checks that `value` is finite and positive, naming it.
pub(crate) fn positive(
    owner: &dyn Fn() -> String,
    field: &'static str,
    value: f64,
) -> Result<(), ExportError> {
    finite(owner, field, 0, value)?;
    if value > 0.0 {
        Ok(())
    } else {
        Err(ExportError::NotPositive {
            owner: owner(),
            field,
            value,
        })
    }
}

/// Checks that time steps rise by one from state to state.
pub(crate) fn consecutive(
    owner: &dyn Fn() -> String,
    steps: impl Iterator<Item = u32>,
) -> Result<(), ExportError> {
    let mut previous: Option<u32> = None;
    for (step, found) in steps.enumerate() {
        if let Some(previous) = previous {
            let expected = previous.saturating_add(1);
            if found != expected {
                return Err(ExportError::TimeSteps {
                    owner: owner(),
                    step,
                    found,
                    expected,
                });
            }
        }
        previous = Some(found);
    }
    Ok(())
}

/// Checks that a CommonRoad ID can be written into a solution's benchmark ID.
pub(crate) fn scenario_id(id: &str) -> Result<(), ExportError> {
    if id.is_empty() || id.contains(':') || id.chars().any(char::is_whitespace) {
        Err(ExportError::ScenarioId { id: id.to_owned() })
    } else {
        Ok(())
    }
}

impl Scenario {
    /// Checks every number and ID: finite values, positive sizes, a non-empty
    /// road, consecutive time steps, unique IDs, a goal interval in order.
    ///
    /// # Errors
    /// The first problem found, naming the field and the step.
    pub fn validate(&self) -> Result<(), ExportError> {
        scenario_id(&self.id)?;
        positive(&|| "scenario".to_owned(), "dt", self.dt)?;
        let road = &self.road;
        let owner = || "road".to_owned();
        positive(&owner, "lane_width", road.lane_width)?;
        finite(&owner, "x_start", 0, road.x_start)?;
        finite(&owner, "x_end", 0, road.x_end)?;
        if road.x_end <= road.x_start {
            return Err(ExportError::EmptyRoad {
                x_start: road.x_start,
                x_end: road.x_end,
            });
        }
        let mut ids = vec![RIGHT_LANELET_ID, LEFT_LANELET_ID];
        for obstacle in &self.obstacles {
            let owner = || format!("obstacle {}", obstacle.id);
            ids.push(obstacle.id);
            positive(&owner, "length", obstacle.length)?;
            positive(&owner, "width", obstacle.width)?;
            if obstacle.states.is_empty() {
                return Err(ExportError::Empty { owner: owner() });
            }
            for (step, state) in obstacle.states.iter().enumerate() {
                finite(&owner, "x", step, state.x)?;
                finite(&owner, "y", step, state.y)?;
                finite(&owner, "orientation", step, state.orientation)?;
                finite(&owner, "velocity", step, state.velocity)?;
                finite(&owner, "acceleration", step, state.acceleration)?;
            }
            consecutive(&owner, obstacle.states.iter().map(|s| s.time_step))?;
        }
        let problem = &self.planning_problem;
        ids.push(problem.id);
        let owner = || format!("planning problem {}", problem.id);
        let initial = &problem.initial;
        finite(&owner, "x", 0, initial.x)?;
        finite(&owner, "y", 0, initial.y)?;
        finite(&owner, "orientation", 0, initial.orientation)?;
        finite(&owner, "velocity", 0, initial.velocity)?;
        finite(&owner, "yaw_rate", 0, initial.yaw_rate)?;
        finite(&owner, "slip_angle", 0, initial.slip_angle)?;
        let goal = &problem.goal;
        if goal.time_end < goal.time_start {
            return Err(ExportError::GoalInterval {
                start: goal.time_start,
                end: goal.time_end,
            });
        }
        ids.sort_unstable();
        if let Some(pair) = ids.windows(2).find(|pair| pair[0] == pair[1]) {
            return Err(ExportError::DuplicateId { id: pair[0] });
        }
        Ok(())
    }
}
