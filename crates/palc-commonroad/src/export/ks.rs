//! The ego's trajectory in CommonRoad's kinematic single-track model (KS) and
//! the solution that carries it.
//!
//! KS moves the rear axle along the heading, `ψ' = v tan(δ) / l_wb`, so a path of
//! curvature `κ = dψ/ds` is driven at the steering angle `δ = atan(l_wb κ)`.
//! [`ks_trajectory_from_poses`] estimates `κ` from the poses by central
//! differences of the heading over the arc length and turns it into `δ` with the
//! vehicle's wheelbase (the BMW 320i's by default, [`VehicleType::wheelbase`]).

use crate::export::error::ExportError;
use crate::export::scene::{Pose, consecutive, finite, positive, scenario_id};

/// A state of the KS model (the centre of the vehicle, as CommonRoad writes it;
/// its checker moves it to the rear axle itself).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct KsState {
    /// Time step.
    pub time_step: u32,
    /// Centre, along the road (m).
    pub x: f64,
    /// Centre, lateral (m).
    pub y: f64,
    /// Front wheel steering angle (rad).
    pub steering_angle: f64,
    /// Speed (m/s).
    pub velocity: f64,
    /// Heading (rad).
    pub orientation: f64,
}

/// CommonRoad's vehicle types (the number in `KS2`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum VehicleType {
    /// Type 1.
    FordEscort,
    /// Type 2, CommonRoad's usual car.
    #[default]
    Bmw320i,
    /// Type 3.
    VwVanagon,
}

impl VehicleType {
    /// The number CommonRoad gives the type.
    pub fn number(self) -> u8 {
        match self {
            VehicleType::FordEscort => 1,
            VehicleType::Bmw320i => 2,
            VehicleType::VwVanagon => 3,
        }
    }

    /// Distance from the rear axle to the centre, `b` (m), from
    /// commonroad-vehicle-models' parameter files; CommonRoad's checker moves a
    /// KS state's centre this far back along the heading to the rear axle.
    pub fn rear_axle_to_centre(self) -> f64 {
        match self {
            VehicleType::FordEscort => 1.508_76,
            VehicleType::Bmw320i => 1.422_717_093_6,
            VehicleType::VwVanagon => 1.321_136_397_6,
        }
    }

    /// Distance between the axles, `a + b` (m), from commonroad-vehicle-models'
    /// parameter files (`parameters_vehicle1..3`): the BMW 320i's is
    /// 1.156 + 1.423 = 2.579 m.
    pub fn wheelbase(self) -> f64 {
        match self {
            VehicleType::FordEscort => 0.883_92 + 1.508_76,
            VehicleType::Bmw320i => 1.156_195_706_4 + 1.422_717_093_6,
            VehicleType::VwVanagon => 1.150_791_602_4 + 1.321_136_397_6,
        }
    }
}

/// CommonRoad's cost functions (the `SM1` of a benchmark ID).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum CostFunction {
    /// `JB1`.
    Jb1,
    /// `SA1`.
    Sa1,
    /// `WX1`.
    Wx1,
    /// `SM1`, the usual one.
    #[default]
    Sm1,
    /// `SM2`.
    Sm2,
    /// `SM3`.
    Sm3,
    /// `MW1`.
    Mw1,
    /// `TR1`.
    Tr1,
}

impl CostFunction {
    /// The ID as written, e.g. `SM1`.
    pub fn id(self) -> &'static str {
        match self {
            CostFunction::Jb1 => "JB1",
            CostFunction::Sa1 => "SA1",
            CostFunction::Wx1 => "WX1",
            CostFunction::Sm1 => "SM1",
            CostFunction::Sm2 => "SM2",
            CostFunction::Sm3 => "SM3",
            CostFunction::Mw1 => "MW1",
            CostFunction::Tr1 => "TR1",
        }
    }
}

/// A CommonRoad solution: one KS trajectory for one planning problem.
#[derive(Debug, Clone, PartialEq)]
pub struct Solution {
    /// The scenario's benchmark ID.
    pub scenario_id: String,
    /// The vehicle (BMW 320i by default).
    pub vehicle_type: VehicleType,
    /// The cost function (SM1 by default).
    pub cost_function: CostFunction,
    /// Wall time of computing the trajectory (s).
    pub computation_time_s: f64,
    /// The `date` attribute (`YYYY-MM-DD`), omitted when `None`.
    pub date: Option<String>,
    /// The planning problem solved.
    pub planning_problem_id: u32,
    /// The trajectory; its first state is the planning problem's initial state.
    pub trajectory: Vec<KsState>,
}

impl Solution {
    /// The benchmark ID, e.g. `KS2:SM1:ZAM_Palc-1_1_T-1:2020a`.
    pub fn benchmark_id(&self) -> String {
        format!(
            "KS{}:{}:{}:2020a",
            self.vehicle_type.number(),
            self.cost_function.id(),
            self.scenario_id
        )
    }

    /// CommonRoad's file name for the solution, e.g.
    /// `solution_KS2_SM1_ZAM_Palc-1_1_T-1_2020a.xml`.
    pub fn file_name(&self) -> String {
        format!("solution_{}.xml", self.benchmark_id().replace(':', "_"))
    }

    /// Checks the ID, the computation time, every number and the time steps.
    ///
    /// # Errors
    /// The first problem found, naming the field and the step.
    pub fn validate(&self) -> Result<(), ExportError> {
        scenario_id(&self.scenario_id)?;
        let owner = || "ego trajectory".to_owned();
        finite(&owner, "computation_time", 0, self.computation_time_s)?;
        if self.trajectory.is_empty() {
            return Err(ExportError::Empty { owner: owner() });
        }
        for (step, state) in self.trajectory.iter().enumerate() {
            check_ks(step, state)?;
        }
        consecutive(&owner, self.trajectory.iter().map(|s| s.time_step))
    }
}

fn check_ks(step: usize, state: &KsState) -> Result<(), ExportError> {
    let owner = || "ego trajectory".to_owned();
    finite(&owner, "x", step, state.x)?;
    finite(&owner, "y", step, state.y)?;
    finite(&owner, "steering_angle", step, state.steering_angle)?;
    finite(&owner, "velocity", step, state.velocity)?;
    finite(&owner, "orientation", step, state.orientation)
}

/// The angle `a` wrapped to `(-π, π]`.
fn wrap(a: f64) -> f64 {
    let w = a.rem_euclid(std::f64::consts::TAU);
    if w > std::f64::consts::PI {
        w - std::f64::consts::TAU
    } else {
        w
    }
}

/// The KS states of a sequence of poses (vehicle centres, one per time step from
/// `first_time_step`), with the steering angle `δ_i = atan(wheelbase κ_i)`.
///
/// The curvature `κ_i` is the heading's change over the distance driven, by
/// central differences (`(ψ_{i+1} − ψ_{i−1}) / (d_{i−1,i} + d_{i,i+1})`) inside and
/// one-sided at both ends; where the vehicle does not move it is 0. Positions,
/// headings and speeds are written as given.
///
/// # Errors
/// A non-finite input (naming the field and the step), a wheelbase that is not
/// positive, or no pose at all.
pub fn ks_trajectory_from_poses(
    poses: &[Pose],
    wheelbase: f64,
    first_time_step: u32,
) -> Result<Vec<KsState>, ExportError> {
    let owner = || "ego trajectory".to_owned();
    positive(&owner, "wheelbase", wheelbase)?;
    if poses.is_empty() {
        return Err(ExportError::Empty { owner: owner() });
    }
    for (step, pose) in poses.iter().enumerate() {
        finite(&owner, "x", step, pose.x)?;
        finite(&owner, "y", step, pose.y)?;
        finite(&owner, "orientation", step, pose.orientation)?;
        finite(&owner, "velocity", step, pose.velocity)?;
    }
    let distance = |a: &Pose, b: &Pose| (b.x - a.x).hypot(b.y - a.y);
    let last = poses.len() - 1;
    let mut states = Vec::with_capacity(poses.len());
    for (i, pose) in poses.iter().enumerate() {
        let (before, after) = (i.saturating_sub(1), (i + 1).min(last));
        let run: f64 = (before..after)
            .map(|j| distance(&poses[j], &poses[j + 1]))
            .sum();
        let turn = wrap(poses[after].orientation - poses[before].orientation);
        let curvature = if run > 1e-9 { turn / run } else { 0.0 };
        let steering_angle = (wheelbase * curvature).atan();
        let time_step = u32::try_from(i)
            .ok()
            .and_then(|i| first_time_step.checked_add(i))
            .ok_or_else(|| ExportError::TimeSteps {
                owner: owner(),
                step: i,
                found: u32::MAX,
                expected: u32::MAX,
            })?;
        let state = KsState {
            time_step,
            x: pose.x,
            y: pose.y,
            steering_angle,
            velocity: pose.velocity,
            orientation: pose.orientation,
        };
        check_ks(i, &state)?;
        states.push(state);
    }
    Ok(states)
}
