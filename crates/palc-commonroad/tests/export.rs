//! The export's XML read back with quick-xml: the same numbers, centres and not
//! front bumpers, the first state the planning problem's, errors on NaN, and the
//! KS steering of a circle.

use palc_commonroad::export::*;
use serde::Deserialize;

const LENGTH: f64 = 4.8;

/// A small scenario: the ego at 20 m/s on the right lane, one obstacle ahead on
/// the left lane, 11 steps of 0.1 s.
fn scenario() -> Scenario {
    let obstacle_states = (0..=10)
        .map(|i| {
            let front = Pose {
                x: 30.0 + 1.8 * f64::from(i),
                y: 3.5,
                orientation: 0.0,
                velocity: 18.0,
            };
            let centre = front.centre_from_front_bumper(LENGTH);
            ObstacleState {
                time_step: i,
                x: centre.x,
                y: centre.y,
                orientation: centre.orientation,
                velocity: centre.velocity,
                acceleration: -0.25,
            }
        })
        .collect();
    let first = ego_poses()[0];
    Scenario {
        id: "ZAM_Palc-1_1_T-1".to_owned(),
        dt: 0.1,
        author: "palc".to_owned(),
        affiliation: "palc".to_owned(),
        source: "test".to_owned(),
        date: None,
        road: Road {
            lane_width: 3.5,
            x_start: -50.0,
            x_end: 150.0,
            ego_lane: Lane::Right,
        },
        obstacles: vec![DynamicObstacle {
            id: 101,
            length: LENGTH,
            width: 1.8,
            states: obstacle_states,
        }],
        planning_problem: PlanningProblem {
            id: 10,
            initial: InitialState {
                time_step: 0,
                x: first.x,
                y: first.y,
                orientation: first.orientation,
                velocity: first.velocity,
                yaw_rate: 0.0,
                slip_angle: 0.0,
            },
            goal: GoalRegion {
                time_start: 5,
                time_end: 10,
            },
        },
    }
}

/// The ego's centres: front bumpers along a gentle curve to the left.
fn ego_poses() -> Vec<Pose> {
    (0..=10)
        .map(|i| {
            let t = f64::from(i) * 0.1;
            Pose {
                x: 20.0 * t,
                y: 0.3 * t * t,
                orientation: (0.6 * t / 20.0).atan(),
                velocity: 20.0,
            }
            .centre_from_front_bumper(LENGTH)
        })
        .collect()
}

fn solution() -> Solution {
    Solution {
        scenario_id: "ZAM_Palc-1_1_T-1".to_owned(),
        vehicle_type: VehicleType::Bmw320i,
        cost_function: CostFunction::Sm1,
        computation_time_s: 0.0123,
        date: None,
        planning_problem_id: 10,
        trajectory: ks_trajectory_from_poses(&ego_poses(), VehicleType::Bmw320i.wheelbase(), 0)
            .unwrap(),
    }
}

// The parts of the documents the tests read back, written here from CommonRoad's
// element names, independently of the crate's own serde types.

#[derive(Debug, Deserialize)]
struct Exact {
    exact: f64,
}

#[derive(Debug, Deserialize)]
struct Point {
    x: f64,
    y: f64,
}

#[derive(Debug, Deserialize)]
struct Position {
    point: Point,
}

#[derive(Debug, Deserialize)]
struct ObstacleStateDoc {
    position: Position,
    orientation: Exact,
    time: Exact,
    velocity: Exact,
    acceleration: Exact,
}

#[derive(Debug, Deserialize)]
struct TrajectoryDoc {
    state: Vec<ObstacleStateDoc>,
}

#[derive(Debug, Deserialize)]
struct ObstacleDoc {
    #[serde(rename = "@id")]
    id: u32,
    #[serde(rename = "initialState")]
    initial_state: ObstacleStateDoc,
    trajectory: TrajectoryDoc,
}

#[derive(Debug, Deserialize)]
struct Adjacent {
    #[serde(rename = "@ref")]
    reference: u32,
    #[serde(rename = "@drivingDir")]
    driving_dir: String,
}

#[derive(Debug, Deserialize)]
struct Bound {
    point: Vec<Point>,
    #[serde(rename = "lineMarking")]
    line_marking: String,
}

#[derive(Debug, Deserialize)]
struct LaneletDoc {
    #[serde(rename = "@id")]
    id: u32,
    #[serde(rename = "leftBound")]
    left_bound: Bound,
    #[serde(rename = "rightBound")]
    right_bound: Bound,
    #[serde(rename = "adjacentLeft")]
    adjacent_left: Option<Adjacent>,
    #[serde(rename = "adjacentRight")]
    adjacent_right: Option<Adjacent>,
}

#[derive(Debug, Deserialize)]
struct InitialDoc {
    position: Position,
    velocity: Exact,
    orientation: Exact,
    #[serde(rename = "yawRate")]
    yaw_rate: Exact,
    #[serde(rename = "slipAngle")]
    slip_angle: Exact,
    time: Exact,
}

#[derive(Debug, Deserialize)]
struct Interval {
    #[serde(rename = "intervalStart")]
    start: u32,
    #[serde(rename = "intervalEnd")]
    end: u32,
}

#[derive(Debug, Deserialize)]
struct GoalDoc {
    time: Interval,
}

#[derive(Debug, Deserialize)]
struct ProblemDoc {
    #[serde(rename = "@id")]
    id: u32,
    #[serde(rename = "initialState")]
    initial_state: InitialDoc,
    #[serde(rename = "goalState")]
    goal_state: GoalDoc,
}

#[derive(Debug, Deserialize)]
struct ScenarioDoc {
    #[serde(rename = "@benchmarkID")]
    benchmark_id: String,
    #[serde(rename = "@commonRoadVersion")]
    version: String,
    #[serde(rename = "@timeStepSize")]
    dt: f64,
    lanelet: Vec<LaneletDoc>,
    #[serde(rename = "dynamicObstacle")]
    obstacles: Vec<ObstacleDoc>,
    #[serde(rename = "planningProblem")]
    problem: ProblemDoc,
}

#[derive(Debug, Deserialize)]
struct KsStateDoc {
    x: f64,
    y: f64,
    #[serde(rename = "steeringAngle")]
    steering_angle: f64,
    velocity: f64,
    orientation: f64,
    time: u32,
}

#[derive(Debug, Deserialize)]
struct KsTrajectoryDoc {
    #[serde(rename = "@planningProblem")]
    planning_problem: u32,
    #[serde(rename = "ksState")]
    states: Vec<KsStateDoc>,
}

#[derive(Debug, Deserialize)]
struct SolutionDoc {
    #[serde(rename = "@benchmark_id")]
    benchmark_id: String,
    #[serde(rename = "@computation_time")]
    computation_time: f64,
    #[serde(rename = "ksTrajectory")]
    trajectory: KsTrajectoryDoc,
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * (1.0 + a.abs().max(b.abs()))
}

#[test]
fn the_scenario_reads_back_with_the_same_numbers() {
    let scenario = scenario();
    let xml = scenario_xml(&scenario).unwrap();
    assert!(xml.starts_with("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<commonRoad"));
    let doc: ScenarioDoc = quick_xml::de::from_str(&xml).unwrap();
    assert_eq!(doc.benchmark_id, "ZAM_Palc-1_1_T-1");
    assert_eq!(doc.version, "2020a");
    assert!(close(doc.dt, 0.1));

    assert_eq!(doc.lanelet.len(), 2);
    let (right, left) = (&doc.lanelet[0], &doc.lanelet[1]);
    assert_eq!((right.id, left.id), (RIGHT_LANELET_ID, LEFT_LANELET_ID));
    let adjacent = right.adjacent_left.as_ref().unwrap();
    assert_eq!(
        (adjacent.reference, adjacent.driving_dir.as_str()),
        (2, "same")
    );
    let adjacent = left.adjacent_right.as_ref().unwrap();
    assert_eq!(
        (adjacent.reference, adjacent.driving_dir.as_str()),
        (1, "same")
    );
    assert!(right.adjacent_right.is_none() && left.adjacent_left.is_none());
    assert_eq!(right.right_bound.line_marking, "solid");
    assert_eq!(right.left_bound.line_marking, "dashed");
    assert_eq!(left.left_bound.line_marking, "solid");
    for (bound, y) in [
        (&right.right_bound, -1.75),
        (&right.left_bound, 1.75),
        (&left.right_bound, 1.75),
        (&left.left_bound, 5.25),
    ] {
        assert!(bound.point.iter().all(|p| close(p.y, y)));
        assert!(close(bound.point[0].x, -50.0));
        assert!(close(bound.point.last().unwrap().x, 150.0));
        assert!(
            bound
                .point
                .windows(2)
                .all(|w| w[1].x - w[0].x <= 10.0 + 1e-9)
        );
    }

    let obstacle = &doc.obstacles[0];
    assert_eq!(obstacle.id, 101);
    let expected = &scenario.obstacles[0].states;
    let read: Vec<&ObstacleStateDoc> = std::iter::once(&obstacle.initial_state)
        .chain(&obstacle.trajectory.state)
        .collect();
    assert_eq!(read.len(), expected.len());
    for (r, e) in read.iter().zip(expected) {
        assert!(close(r.position.point.x, e.x) && close(r.position.point.y, e.y));
        assert!(close(r.orientation.exact, e.orientation));
        assert!(close(r.velocity.exact, e.velocity));
        assert!(close(r.acceleration.exact, e.acceleration));
        assert!(close(r.time.exact, f64::from(e.time_step)));
    }

    let problem = &doc.problem;
    assert_eq!(problem.id, 10);
    let initial = &scenario.planning_problem.initial;
    let read = &problem.initial_state;
    assert!(close(read.position.point.x, initial.x) && close(read.position.point.y, initial.y));
    assert!(close(read.velocity.exact, initial.velocity));
    assert!(close(read.orientation.exact, initial.orientation));
    assert!(close(read.yaw_rate.exact, 0.0) && close(read.slip_angle.exact, 0.0));
    assert!(close(read.time.exact, 0.0));
    assert_eq!(
        (problem.goal_state.time.start, problem.goal_state.time.end),
        (5, 10)
    );
}

#[test]
fn the_solution_reads_back_and_starts_at_the_initial_state() {
    let solution = solution();
    let doc: SolutionDoc = quick_xml::de::from_str(&solution_xml(&solution).unwrap()).unwrap();
    assert_eq!(doc.benchmark_id, "KS2:SM1:ZAM_Palc-1_1_T-1:2020a");
    assert!(close(doc.computation_time, 0.0123));
    assert_eq!(doc.trajectory.planning_problem, 10);
    assert_eq!(doc.trajectory.states.len(), solution.trajectory.len());
    for (r, e) in doc.trajectory.states.iter().zip(&solution.trajectory) {
        assert!(close(r.x, e.x) && close(r.y, e.y));
        assert!(close(r.steering_angle, e.steering_angle));
        assert!(close(r.velocity, e.velocity) && close(r.orientation, e.orientation));
        assert_eq!(r.time, e.time_step);
    }
    let first = &doc.trajectory.states[0];
    let initial = &scenario().planning_problem.initial;
    assert!(close(first.x, initial.x) && close(first.y, initial.y));
    assert!(close(first.velocity, initial.velocity));
    assert!(close(first.orientation, initial.orientation));
    assert_eq!(first.time, initial.time_step);
}

#[test]
fn positions_are_centres_half_a_length_behind_the_front_bumper() {
    let front = Pose {
        x: 10.0,
        y: 1.0,
        orientation: 0.0,
        velocity: 5.0,
    };
    let centre = front.centre_from_front_bumper(4.0);
    assert!(close(centre.x, 8.0) && close(centre.y, 1.0));
    // Along the heading when the vehicle is turned.
    let turned = Pose {
        orientation: std::f64::consts::FRAC_PI_6,
        ..front
    }
    .centre_from_front_bumper(4.0);
    assert!(close(turned.x, 10.0 - 2.0 * 3f64.sqrt() / 2.0));
    assert!(close(turned.y, 1.0 - 1.0));
    assert!(close(turned.velocity, 5.0));
    // The obstacle written is 2.4 m behind its front bumper at 30 m.
    let doc: ScenarioDoc = quick_xml::de::from_str(&scenario_xml(&scenario()).unwrap()).unwrap();
    assert!(close(
        doc.obstacles[0].initial_state.position.point.x,
        30.0 - 2.4
    ));
}

#[test]
fn nan_is_an_error_naming_the_field_and_step() {
    let mut poses = ego_poses();
    poses[3].y = f64::NAN;
    let error = ks_trajectory_from_poses(&poses, 2.578, 0).unwrap_err();
    let message = error.to_string();
    assert!(message.contains("`y` at step 3"), "{message}");

    let mut scenario = scenario();
    scenario.obstacles[0].states[7].velocity = f64::INFINITY;
    let message = scenario_xml(&scenario).unwrap_err().to_string();
    assert!(message.contains("obstacle 101") && message.contains("`velocity` at step 7"));

    let mut solution = solution();
    solution.trajectory[4].orientation = f64::NAN;
    let message = solution_xml(&solution).unwrap_err().to_string();
    assert!(message.contains("`orientation` at step 4"), "{message}");
}

#[test]
fn malformed_scenes_are_errors_not_panics() {
    let mut s = scenario();
    s.obstacles[0].id = 2;
    assert!(matches!(
        scenario_xml(&s),
        Err(ExportError::DuplicateId { id: 2 })
    ));
    let mut s = scenario();
    s.road.x_end = s.road.x_start;
    assert!(matches!(
        scenario_xml(&s),
        Err(ExportError::EmptyRoad { .. })
    ));
    let mut s = scenario();
    s.obstacles[0].states[5].time_step = 9;
    assert!(matches!(
        scenario_xml(&s),
        Err(ExportError::TimeSteps { step: 5, .. })
    ));
    let mut s = scenario();
    s.planning_problem.goal.time_start = 11;
    assert!(matches!(
        scenario_xml(&s),
        Err(ExportError::GoalInterval { .. })
    ));
    let mut s = scenario();
    s.obstacles[0].states.clear();
    assert!(matches!(scenario_xml(&s), Err(ExportError::Empty { .. })));
    let mut s = scenario();
    s.id = "bad id".to_owned();
    assert!(matches!(
        scenario_xml(&s),
        Err(ExportError::ScenarioId { .. })
    ));
    assert!(ks_trajectory_from_poses(&[], 2.578, 0).is_err());
    assert!(ks_trajectory_from_poses(&ego_poses(), 0.0, 0).is_err());
    assert!(ks_trajectory_from_poses(&ego_poses(), 2.578, u32::MAX).is_err());
}

#[test]
fn the_steering_angle_of_a_circle_is_atan_of_wheelbase_over_radius() {
    let wheelbase = VehicleType::Bmw320i.wheelbase();
    assert!((wheelbase - 2.578_912_8).abs() < 1e-6);
    for radius in [50.0, 200.0, -80.0] {
        // 20 m/s, 0.1 s steps, counter-clockwise for a positive radius.
        let step = 2.0 / radius;
        let poses: Vec<Pose> = (0..=30)
            .map(|i| {
                let angle = step * f64::from(i);
                Pose {
                    x: radius * angle.sin(),
                    y: radius * (1.0 - angle.cos()),
                    orientation: angle,
                    velocity: 20.0,
                }
            })
            .collect();
        let states = ks_trajectory_from_poses(&poses, wheelbase, 3).unwrap();
        let expected = (wheelbase / radius).atan();
        for (i, state) in states.iter().enumerate() {
            assert!(
                (state.steering_angle - expected).abs() < 1e-4 * expected.abs(),
                "radius {radius}, step {i}: {} vs {expected}",
                state.steering_angle
            );
            assert_eq!(state.time_step, 3 + i as u32);
        }
    }
    // A straight line steers at zero, and a vehicle standing still too.
    let still = vec![Pose::default(); 3];
    let states = ks_trajectory_from_poses(&still, wheelbase, 0).unwrap();
    assert!(states.iter().all(|s| s.steering_angle == 0.0));
}
