//! The XML documents as serde types, in CommonRoad 2020a's element order, and
//! their conversion from the plain data. quick-xml's serializer writes them:
//! `@name` fields are attributes, the others child elements.

use serde::{Deserialize, Serialize};

use crate::export::ks::Solution;
use crate::export::scene::{
    DynamicObstacle, LEFT_LANELET_ID, Lane, ObstacleState, RIGHT_LANELET_ID, Scenario,
};

/// `<commonRoad>`.
#[derive(Debug, Serialize, Deserialize)]
pub(crate) struct CommonRoadXml {
    #[serde(rename = "@timeStepSize")]
    pub time_step_size: f64,
    #[serde(rename = "@commonRoadVersion")]
    pub version: String,
    #[serde(rename = "@author")]
    pub author: String,
    #[serde(rename = "@affiliation")]
    pub affiliation: String,
    #[serde(rename = "@source")]
    pub source: String,
    #[serde(rename = "@benchmarkID")]
    pub benchmark_id: String,
    #[serde(rename = "@date", skip_serializing_if = "Option::is_none", default)]
    pub date: Option<String>,
    pub location: LocationXml,
    #[serde(rename = "scenarioTags")]
    pub tags: TagsXml,
    pub lanelet: Vec<LaneletXml>,
    #[serde(rename = "dynamicObstacle", default)]
    pub dynamic_obstacle: Vec<DynamicObstacleXml>,
    #[serde(rename = "planningProblem")]
    pub planning_problem: PlanningProblemXml,
}

/// `<location>`: CommonRoad's values for an artificial map (no place on Earth).
#[derive(Debug, Serialize, Deserialize)]
pub(crate) struct LocationXml {
    #[serde(rename = "geoNameId")]
    pub geo_name_id: i64,
    #[serde(rename = "gpsLatitude")]
    pub gps_latitude: f64,
    #[serde(rename = "gpsLongitude")]
    pub gps_longitude: f64,
}

/// An empty element, e.g. `<two_lane/>`.
#[derive(Debug, Serialize, Deserialize, Default)]
pub(crate) struct Empty {}

/// `<scenarioTags>`.
#[derive(Debug, Serialize, Deserialize, Default)]
pub(crate) struct TagsXml {
    pub multi_lane: Empty,
    pub two_lane: Empty,
    pub parallel_lanes: Empty,
    pub no_oncoming_traffic: Empty,
    pub lane_change: Empty,
    pub simulated: Empty,
}

/// `<point>`.
#[derive(Debug, Serialize, Deserialize, Clone, Copy)]
pub(crate) struct PointXml {
    pub x: f64,
    pub y: f64,
}

/// `<leftBound>` or `<rightBound>`.
#[derive(Debug, Serialize, Deserialize)]
pub(crate) struct BoundXml {
    pub point: Vec<PointXml>,
    #[serde(rename = "lineMarking")]
    pub line_marking: String,
}

/// `<adjacentLeft>` or `<adjacentRight>`.
#[derive(Debug, Serialize, Deserialize)]
pub(crate) struct AdjacentXml {
    #[serde(rename = "@ref")]
    pub reference: u32,
    #[serde(rename = "@drivingDir")]
    pub driving_dir: String,
}

/// `<lanelet>`.
#[derive(Debug, Serialize, Deserialize)]
pub(crate) struct LaneletXml {
    #[serde(rename = "@id")]
    pub id: u32,
    #[serde(rename = "leftBound")]
    pub left_bound: BoundXml,
    #[serde(rename = "rightBound")]
    pub right_bound: BoundXml,
    #[serde(
        rename = "adjacentLeft",
        skip_serializing_if = "Option::is_none",
        default
    )]
    pub adjacent_left: Option<AdjacentXml>,
    #[serde(
        rename = "adjacentRight",
        skip_serializing_if = "Option::is_none",
        default
    )]
    pub adjacent_right: Option<AdjacentXml>,
    #[serde(rename = "laneletType")]
    pub lanelet_type: String,
}

/// An exact value, `<exact>v</exact>`.
#[derive(Debug, Serialize, Deserialize, Clone, Copy)]
pub(crate) struct Exact<T> {
    pub exact: T,
}

/// An interval, `<intervalStart>a</intervalStart><intervalEnd>b</intervalEnd>`.
#[derive(Debug, Serialize, Deserialize, Clone, Copy)]
pub(crate) struct Interval<T> {
    #[serde(rename = "intervalStart")]
    pub start: T,
    #[serde(rename = "intervalEnd")]
    pub end: T,
}

/// `<position><point>..</point></position>`.
#[derive(Debug, Serialize, Deserialize, Clone, Copy)]
pub(crate) struct PositionXml {
    pub point: PointXml,
}

/// An obstacle's `<initialState>` or trajectory `<state>`.
#[derive(Debug, Serialize, Deserialize)]
pub(crate) struct ObstacleStateXml {
    pub position: PositionXml,
    pub orientation: Exact<f64>,
    pub time: Exact<u32>,
    pub velocity: Exact<f64>,
    pub acceleration: Exact<f64>,
}

/// `<rectangle>` of an obstacle's shape.
#[derive(Debug, Serialize, Deserialize)]
pub(crate) struct SizeXml {
    pub length: f64,
    pub width: f64,
}

/// `<shape>`.
#[derive(Debug, Serialize, Deserialize)]
pub(crate) struct ShapeXml {
    pub rectangle: SizeXml,
}

/// `<trajectory>`.
#[derive(Debug, Serialize, Deserialize)]
pub(crate) struct TrajectoryXml {
    pub state: Vec<ObstacleStateXml>,
}

/// `<dynamicObstacle>`.
#[derive(Debug, Serialize, Deserialize)]
pub(crate) struct DynamicObstacleXml {
    #[serde(rename = "@id")]
    pub id: u32,
    #[serde(rename = "type")]
    pub kind: String,
    pub shape: ShapeXml,
    #[serde(rename = "initialState")]
    pub initial_state: ObstacleStateXml,
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub trajectory: Option<TrajectoryXml>,
}

/// The planning problem's `<initialState>`.
#[derive(Debug, Serialize, Deserialize)]
pub(crate) struct InitialStateXml {
    pub position: PositionXml,
    pub velocity: Exact<f64>,
    pub orientation: Exact<f64>,
    #[serde(rename = "yawRate")]
    pub yaw_rate: Exact<f64>,
    #[serde(rename = "slipAngle")]
    pub slip_angle: Exact<f64>,
    pub time: Exact<u32>,
}

/// A goal `<rectangle>`.
#[derive(Debug, Serialize, Deserialize)]
pub(crate) struct RectangleXml {
    pub length: f64,
    pub width: f64,
    pub orientation: f64,
    pub center: PointXml,
}

/// The goal's `<position>`.
#[derive(Debug, Serialize, Deserialize)]
pub(crate) struct GoalPositionXml {
    pub rectangle: RectangleXml,
}

/// `<goalState>`.
#[derive(Debug, Serialize, Deserialize)]
pub(crate) struct GoalStateXml {
    pub position: GoalPositionXml,
    pub time: Interval<u32>,
}

/// `<planningProblem>`.
#[derive(Debug, Serialize, Deserialize)]
pub(crate) struct PlanningProblemXml {
    #[serde(rename = "@id")]
    pub id: u32,
    #[serde(rename = "initialState")]
    pub initial_state: InitialStateXml,
    #[serde(rename = "goalState")]
    pub goal_state: GoalStateXml,
}

/// `<CommonRoadSolution>`.
#[derive(Debug, Serialize, Deserialize)]
pub(crate) struct SolutionXml {
    #[serde(rename = "@benchmark_id")]
    pub benchmark_id: String,
    #[serde(rename = "@computation_time")]
    pub computation_time: f64,
    #[serde(rename = "@date", skip_serializing_if = "Option::is_none", default)]
    pub date: Option<String>,
    #[serde(rename = "ksTrajectory")]
    pub ks_trajectory: KsTrajectoryXml,
}

/// `<ksTrajectory>`.
#[derive(Debug, Serialize, Deserialize)]
pub(crate) struct KsTrajectoryXml {
    #[serde(rename = "@planningProblem")]
    pub planning_problem: u32,
    #[serde(rename = "ksState")]
    pub ks_state: Vec<KsStateXml>,
}

/// `<ksState>`.
#[derive(Debug, Serialize, Deserialize)]
pub(crate) struct KsStateXml {
    pub x: f64,
    pub y: f64,
    #[serde(rename = "steeringAngle")]
    pub steering_angle: f64,
    pub velocity: f64,
    pub orientation: f64,
    pub time: u32,
}

/// Lanelet bounds get a point at least every this many metres, so that tools
/// which resample polylines see a fine road.
const MAX_POINT_SPACING_M: f64 = 10.0;

/// Points from `x_start` to `x_end` at lateral `y`, at most
/// [`MAX_POINT_SPACING_M`] apart.
fn bound_points(x_start: f64, x_end: f64, y: f64) -> Vec<PointXml> {
    let pieces = ((x_end - x_start) / MAX_POINT_SPACING_M)
        .ceil()
        .clamp(1.0, 1e5) as usize;
    (0..=pieces)
        .map(|i| PointXml {
            x: x_start + (x_end - x_start) * i as f64 / pieces as f64,
            y,
        })
        .collect()
}

fn obstacle_state(state: &ObstacleState) -> ObstacleStateXml {
    ObstacleStateXml {
        position: PositionXml {
            point: PointXml {
                x: state.x,
                y: state.y,
            },
        },
        orientation: Exact {
            exact: state.orientation,
        },
        time: Exact {
            exact: state.time_step,
        },
        velocity: Exact {
            exact: state.velocity,
        },
        acceleration: Exact {
            exact: state.acceleration,
        },
    }
}

fn obstacle(obstacle: &DynamicObstacle) -> Option<DynamicObstacleXml> {
    let (first, rest) = obstacle.states.split_first()?;
    Some(DynamicObstacleXml {
        id: obstacle.id,
        kind: "car".to_owned(),
        shape: ShapeXml {
            rectangle: SizeXml {
                length: obstacle.length,
                width: obstacle.width,
            },
        },
        initial_state: obstacle_state(first),
        trajectory: (!rest.is_empty()).then(|| TrajectoryXml {
            state: rest.iter().map(obstacle_state).collect(),
        }),
    })
}

impl CommonRoadXml {
    /// The document of a validated scenario.
    pub(crate) fn from_scenario(scenario: &Scenario) -> CommonRoadXml {
        let road = &scenario.road;
        let w = road.lane_width;
        let bound = |y: f64, marking: &str| BoundXml {
            point: bound_points(road.x_start, road.x_end, y),
            line_marking: marking.to_owned(),
        };
        let same = |reference: u32| {
            Some(AdjacentXml {
                reference,
                driving_dir: "same".to_owned(),
            })
        };
        let lanelets = vec![
            LaneletXml {
                id: RIGHT_LANELET_ID,
                left_bound: bound(0.5 * w, "dashed"),
                right_bound: bound(-0.5 * w, "solid"),
                adjacent_left: same(LEFT_LANELET_ID),
                adjacent_right: None,
                lanelet_type: "unknown".to_owned(),
            },
            LaneletXml {
                id: LEFT_LANELET_ID,
                left_bound: bound(1.5 * w, "solid"),
                right_bound: bound(0.5 * w, "dashed"),
                adjacent_left: None,
                adjacent_right: same(RIGHT_LANELET_ID),
                lanelet_type: "unknown".to_owned(),
            },
        ];
        let problem = &scenario.planning_problem;
        let initial = &problem.initial;
        let target: Lane = road.ego_lane.other();
        CommonRoadXml {
            time_step_size: scenario.dt,
            version: "2020a".to_owned(),
            author: scenario.author.clone(),
            affiliation: scenario.affiliation.clone(),
            source: scenario.source.clone(),
            benchmark_id: scenario.id.clone(),
            date: scenario.date.clone(),
            location: LocationXml {
                geo_name_id: -999,
                gps_latitude: 999.0,
                gps_longitude: 999.0,
            },
            tags: TagsXml::default(),
            lanelet: lanelets,
            dynamic_obstacle: scenario.obstacles.iter().filter_map(obstacle).collect(),
            planning_problem: PlanningProblemXml {
                id: problem.id,
                initial_state: InitialStateXml {
                    position: PositionXml {
                        point: PointXml {
                            x: initial.x,
                            y: initial.y,
                        },
                    },
                    velocity: Exact {
                        exact: initial.velocity,
                    },
                    orientation: Exact {
                        exact: initial.orientation,
                    },
                    yaw_rate: Exact {
                        exact: initial.yaw_rate,
                    },
                    slip_angle: Exact {
                        exact: initial.slip_angle,
                    },
                    time: Exact {
                        exact: initial.time_step,
                    },
                },
                goal_state: GoalStateXml {
                    position: GoalPositionXml {
                        rectangle: RectangleXml {
                            length: road.x_end - road.x_start,
                            width: w,
                            orientation: 0.0,
                            center: PointXml {
                                x: 0.5 * (road.x_start + road.x_end),
                                y: target.centre_y(w),
                            },
                        },
                    },
                    time: Interval {
                        start: problem.goal.time_start,
                        end: problem.goal.time_end,
                    },
                },
            },
        }
    }
}

impl SolutionXml {
    /// The document of a validated solution.
    pub(crate) fn from_solution(solution: &Solution) -> SolutionXml {
        SolutionXml {
            benchmark_id: solution.benchmark_id(),
            computation_time: solution.computation_time_s,
            date: solution.date.clone(),
            ks_trajectory: KsTrajectoryXml {
                planning_problem: solution.planning_problem_id,
                ks_state: (solution.trajectory.iter())
                    .map(|s| KsStateXml {
                        x: s.x,
                        y: s.y,
                        steering_angle: s.steering_angle,
                        velocity: s.velocity,
                        orientation: s.orientation,
                        time: s.time_step,
                    })
                    .collect(),
            },
        }
    }
}
