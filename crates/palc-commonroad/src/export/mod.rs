//! Writing CommonRoad 2020a scenarios and solution files.
//!
//! A [`Scenario`] is a straight two-lane road (two lanelets with their bounds,
//! line markings and same-direction adjacency), the other vehicles as
//! `dynamicObstacle`s with an `initialState` and a `trajectory`, and one
//! `planningProblem`: the ego's initial state and a goal, the target lane within
//! a time interval. A [`Solution`] is the ego's trajectory in the kinematic
//! single-track model (`ksTrajectory`), for CommonRoad's
//! `KS<vehicle>:<cost>:<scenario>:2020a` benchmark; [`ks_trajectory_from_poses`]
//! builds it from poses, with the steering angle from the path's curvature.
//!
//! The data is plain (no palc type): positions are vehicle centres in CommonRoad's
//! frame, and [`Pose::centre_from_front_bumper`] converts palc's front-bumper `s`.
//! Every number is checked before anything is written ([`Scenario::validate`],
//! [`Solution::validate`]), and the XML comes from quick-xml's serde serializer.
//!
//! ```
//! use palc_commonroad::export::*;
//!
//! let poses: Vec<Pose> = (0..=10)
//!     .map(|i| Pose { x: 2.0 * f64::from(i), y: 0.0, orientation: 0.0, velocity: 20.0 })
//!     .collect();
//! let trajectory = ks_trajectory_from_poses(&poses, VehicleType::Bmw320i.wheelbase(), 0)?;
//! let solution = Solution {
//!     scenario_id: "ZAM_Palc-1_1_T-1".to_owned(),
//!     vehicle_type: VehicleType::Bmw320i,
//!     cost_function: CostFunction::Sm1,
//!     computation_time_s: 0.01,
//!     date: None,
//!     planning_problem_id: 10,
//!     trajectory,
//! };
//! assert_eq!(solution.file_name(), "solution_KS2_SM1_ZAM_Palc-1_1_T-1_2020a.xml");
//! assert!(solution_xml(&solution)?.contains("<ksTrajectory planningProblem=\"10\">"));
//! # Ok::<(), ExportError>(())
//! ```

mod error;
mod ks;
mod scene;
mod xml;

pub use error::ExportError;
pub use ks::{CostFunction, KsState, Solution, VehicleType, ks_trajectory_from_poses};
pub use scene::{
    DynamicObstacle, GoalRegion, InitialState, LEFT_LANELET_ID, Lane, ObstacleState,
    PlanningProblem, Pose, RIGHT_LANELET_ID, Road, Scenario,
};

use quick_xml::Writer;
use quick_xml::events::{BytesDecl, Event};
use quick_xml::se::Serializer;
use serde::Serialize;

/// `value` as an indented XML document with the root `root`, after the XML
/// declaration.
fn document(root: &str, value: &impl Serialize) -> Result<String, ExportError> {
    let mut declaration = Writer::new(Vec::new());
    declaration.write_event(Event::Decl(BytesDecl::new("1.0", Some("UTF-8"), None)))?;
    let mut text = String::from_utf8_lossy(&declaration.into_inner()).into_owned();
    text.push('\n');
    let mut serializer = Serializer::with_root(&mut text, Some(root))?;
    serializer.indent(' ', 2);
    value.serialize(serializer)?;
    text.push('\n');
    Ok(text)
}

/// The scenario as CommonRoad 2020a XML.
///
/// # Errors
/// What [`Scenario::validate`] finds, or a serializer error.
pub fn scenario_xml(scenario: &Scenario) -> Result<String, ExportError> {
    scenario.validate()?;
    document("commonRoad", &xml::CommonRoadXml::from_scenario(scenario))
}

/// The solution as a CommonRoad solution file.
///
/// # Errors
/// What [`Solution::validate`] finds, or a serializer error.
pub fn solution_xml(solution: &Solution) -> Result<String, ExportError> {
    solution.validate()?;
    document(
        "CommonRoadSolution",
        &xml::SolutionXml::from_solution(solution),
    )
}
