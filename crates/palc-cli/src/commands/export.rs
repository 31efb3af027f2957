//! `palc export commonroad`: the learned lane change of a scene as a CommonRoad
//! 2020a scenario and a KS solution file, for CommonRoad's tools (its solution
//! checker, planners to compare with, visualisation).
//!
//! The command runs the lesson-learning loop on the config's scene and user
//! until it ends, takes the plan the loop ends with (the learned lane change,
//! which the user accepted when the run personalized), drives it once in the
//! scene prepared at the trigger so that the background traffic reacts to it as
//! in the loop, and maps it onto `palc_commonroad::export`'s plain types: `x = s`
//! and `y = l` on the straight road (from the ego's front bumper at the trigger),
//! positions moved from palc's front bumpers to vehicle centres, the steering
//! angle from the path's curvature with the BMW 320i's wheelbase (CommonRoad's
//! vehicle type 2). The trajectory is the lane change and one second more
//! ([`AFTER_SETTLED_S`]): past it palc's ACC drives, not the plan. The goal is
//! the target lane from the earlier of the standard ALC's end and the learned
//! lane change's to the end of the trajectory. `--grid` does the same for every
//! cell of the config's test bed (its seed) and each of the paper's three styles.

use std::path::{Path, PathBuf};

use anyhow::Context;
use clap::{Args, Subcommand};
use palc_aggregator::output;
use palc_commonroad::export::{
    CostFunction, DynamicObstacle, GoalRegion, InitialState, Lane, ObstacleState, PlanningProblem,
    Pose, Road, Scenario, Solution, VehicleType, ks_trajectory_from_poses, scenario_xml,
    solution_xml,
};
use palc_harness::config::UserStyle;
use palc_harness::{CellChoice, LearnConfig, LearningLoop, NoObserver, Outcome, StylePreset};
use palc_traffic::{Driver, EgoState};

use crate::commands::learn::{ScenarioArgs, load_config};
use crate::console::say;

/// Arguments of `palc export`.
#[derive(Debug, Args)]
pub struct ExportArgs {
    #[command(subcommand)]
    format: Format,
}

/// The formats `palc export` writes.
#[derive(Debug, Subcommand)]
enum Format {
    /// A CommonRoad 2020a scenario and a KS solution (`KS2:SM1`) per learned lane
    /// change: `DIR/<scenario id>.xml` and `DIR/solution_KS2_SM1_<id>_2020a.xml`.
    Commonroad(CommonRoadArgs),
}

/// Arguments of `palc export commonroad`.
#[derive(Debug, Args)]
struct CommonRoadArgs {
    #[command(flatten)]
    scenario: ScenarioArgs,
    /// Output directory.
    #[arg(long, default_value = "target/commonroad-export")]
    out: PathBuf,
    /// Every cell of the config's test bed (speed cases x adjacent headways, the
    /// config's seed) with each of the paper's three styles, instead of the one
    /// scene.
    #[arg(long)]
    grid: bool,
}

/// Obstacle IDs are the palc vehicle's ID plus this (the lanelets are 1 and 2).
const OBSTACLE_ID_OFFSET: u32 = 100;
/// The planning problem's ID.
const PLANNING_PROBLEM_ID: u32 = 10;
/// Road ahead of and behind every vehicle of the scenario (m).
const ROAD_MARGIN_M: f64 = 20.0;
/// How long the exported trajectory goes on once the lane change has settled
/// (s). Past the lane change palc's ACC drives the ego; the plan's tail keeps
/// the planned speed and would run into a slower target-lane leader that the
/// ACC follows, so it is not what palc drives.
const AFTER_SETTLED_S: f64 = 1.0;

/// Runs `palc export`.
pub fn run(args: ExportArgs) -> anyhow::Result<()> {
    match args.format {
        Format::Commonroad(args) => commonroad(&args),
    }
}

fn commonroad(args: &CommonRoadArgs) -> anyhow::Result<()> {
    let config = load_config(&args.scenario)?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    if !args.grid {
        let written = export_one(&config, "ZAM_Palc-1_1_T-1", &args.out)?;
        say!("{written}");
        return Ok(());
    }
    let cells = config.traffic.testbed_cells()?;
    let seed = config.cell.seed;
    let (mut written, mut refused) = (0, 0);
    let mut index = 0;
    for cell in cells.iter().filter(|c| c.seed == seed) {
        for preset in StylePreset::ALL {
            index += 1;
            let choice = CellChoice {
                speed_case: cell.speed_case.name.clone(),
                headway_m: cell.adjacent_headway,
                seed,
            };
            let user = palc_harness::UserConfig {
                style: UserStyle::Preset(preset),
                ..config.user.clone()
            };
            let cell_config = config.clone().with_cell(choice).with_user(user);
            let id = format!("ZAM_PalcGrid-{index}_1_T-1");
            match export_one(&cell_config, &id, &args.out) {
                Ok(line) => {
                    written += 1;
                    say!("{line}");
                }
                Err(error) => {
                    refused += 1;
                    say!("{id}: {}: not exported: {error:#}", cell_config.label());
                }
            }
        }
    }
    say!(
        "{written} scenarios written to {}, {refused} cells not exported",
        args.out.display()
    );
    anyhow::ensure!(written > 0, "no cell of the grid could be exported");
    Ok(())
}

/// Learns in the scene of `config`, writes its scenario and solution as `id`
/// into `out`, and returns a line saying what was written.
fn export_one(config: &LearnConfig, id: &str, out: &Path) -> anyhow::Result<String> {
    let label = config.label();
    let setup = palc_harness::prepare(config)?;
    let mut run = LearningLoop::new(config, None)?;
    let outcome = loop {
        run.step(&mut NoObserver)?;
        if let Some(outcome) = run.termination() {
            break outcome;
        }
    };
    let mut plan = run.next_plan().clone();
    let takeovers = run
        .records()
        .iter()
        .filter(|r| r.takeover.is_some())
        .count();
    let dt = setup.dt;
    // The lane change and AFTER_SETTLED_S more: from the step after which the ego
    // stays within SETTLED_M of the target lane's centre.
    let settled = (plan.states.iter())
        .rposition(|x| (x.l - setup.target_l).abs() > palc_harness::user::SETTLED_M)
        .map_or(0, |last_off| last_off + 1);
    let keep = settled + (AFTER_SETTLED_S / dt).round() as usize + 1;
    plan.states.truncate(keep.max(2));
    let states = &plan.states;
    let horizon = states.len().saturating_sub(1);
    let ego = setup.scene.ego().context("the scene has no ego")?;
    let ego_length = ego.length;

    // The background traffic as it reacts to the ego driving the plan.
    let mut scene = setup.scene.clone();
    let mut obstacles: Vec<DynamicObstacle> = (scene.vehicles().iter())
        .filter(|v| !matches!(v.driver, Driver::External { .. }))
        .map(|v| DynamicObstacle {
            id: OBSTACLE_ID_OFFSET + v.id.0,
            length: v.length,
            width: v.width,
            states: Vec::with_capacity(horizon + 1),
        })
        .collect();
    for (step, state) in states.iter().enumerate() {
        if step > 0 {
            scene.step(
                dt,
                EgoState {
                    s: state.s + setup.origin_s,
                    l: state.l,
                    v: state.v.max(0.0),
                    heading: state.phi,
                },
            )?;
        }
        let time_step = u32::try_from(step)?;
        let others =
            (scene.vehicles().iter()).filter(|v| !matches!(v.driver, Driver::External { .. }));
        for (obstacle, vehicle) in obstacles.iter_mut().zip(others) {
            let centre = Pose {
                x: vehicle.state.s - setup.origin_s,
                y: vehicle.state.l,
                orientation: vehicle.state.heading,
                velocity: vehicle.state.v,
            }
            .centre_from_front_bumper(vehicle.length);
            obstacle.states.push(ObstacleState {
                time_step,
                x: centre.x,
                y: centre.y,
                orientation: centre.orientation,
                velocity: centre.velocity,
                acceleration: vehicle.state.a,
            });
        }
    }

    // The ego. palc's planner is a kinematic single-track model about the rear
    // axle (`l' = v φ`, `φ' = v δ / l_fr`), so the plan's `(s, l)` path is the rear
    // axle's, labelled with the front bumper's `s`: the rear axle is taken
    // `length / 2 + b` behind the front bumper along the road, and the centre `b`
    // ahead of it along the heading. Straight, the centre is `s − length / 2`;
    // rotating the front bumper's point about the heading instead moves the
    // centre sideways against the path and is not KS-feasible
    // (`python/commonroad`). palc's `v` is the speed along the road (`s' = v`),
    // KS's the speed along the heading: `v / cos φ`.
    let vehicle_type = VehicleType::Bmw320i;
    let b = vehicle_type.rear_axle_to_centre();
    let poses: Vec<Pose> = states
        .iter()
        .map(|x| {
            Pose {
                x: x.s - 0.5 * ego_length - b,
                y: x.l,
                orientation: x.phi,
                velocity: x.v / x.phi.cos(),
            }
            .centre_from_rear_axle(b)
        })
        .collect();
    let trajectory = ks_trajectory_from_poses(&poses, vehicle_type.wheelbase(), 0)?;

    // The road: behind and ahead of every vehicle over the whole plan.
    let extents = (poses.iter().map(|p| (p.x, ego_length))).chain(obstacles.iter().flat_map(|o| {
        let length = o.length;
        o.states.iter().map(move |s| (s.x, length))
    }));
    let (mut x_start, mut x_end) = (f64::INFINITY, f64::NEG_INFINITY);
    for (x, length) in extents {
        x_start = x_start.min(x - length);
        x_end = x_end.max(x + length);
    }
    let first = poses.first().context("the plan has no state")?;
    let yaw_rate = match states.as_slice() {
        [a, b, ..] => (b.phi - a.phi) / dt,
        _ => 0.0,
    };
    let standard = &config.planning.standard_alc;
    let standard_end =
        setup.standard_start_step + (standard.lane_change_duration_s / dt).ceil() as usize;
    let scenario = Scenario {
        id: id.to_owned(),
        dt,
        author: "palc".to_owned(),
        affiliation: "palc".to_owned(),
        source: format!(
            "palc export commonroad: {label}, {} method, {} after {takeovers} takeovers in {} lane changes",
            config.method.name(),
            match outcome {
                Outcome::Personalized => "personalized",
                Outcome::CapReached => "cap reached",
            },
            run.records().len()
        ),
        date: None,
        road: Road {
            lane_width: setup.scene.road().lane_width,
            x_start: x_start - ROAD_MARGIN_M,
            x_end: x_end + ROAD_MARGIN_M,
            ego_lane: Lane::Right,
        },
        obstacles,
        planning_problem: PlanningProblem {
            id: PLANNING_PROBLEM_ID,
            initial: InitialState {
                time_step: 0,
                x: first.x,
                y: first.y,
                orientation: first.orientation,
                velocity: first.velocity,
                yaw_rate,
                slip_angle: 0.0,
            },
            goal: GoalRegion {
                time_start: u32::try_from(standard_end.min(settled).min(horizon))?,
                time_end: u32::try_from(horizon)?,
            },
        },
    };
    let solution = Solution {
        scenario_id: id.to_owned(),
        vehicle_type,
        cost_function: CostFunction::Sm1,
        computation_time_s: plan.stats.build_seconds + plan.stats.solve_seconds,
        date: None,
        planning_problem_id: PLANNING_PROBLEM_ID,
        trajectory,
    };
    let scenario_path = out.join(format!("{id}.xml"));
    let solution_path = out.join(solution.file_name());
    let scenario_text = scenario_xml(&scenario).with_context(|| format!("scenario {id}"))?;
    let solution_text = solution_xml(&solution).with_context(|| format!("solution of {id}"))?;
    output::write(&scenario_path, scenario_text.as_bytes())?;
    output::write(&solution_path, solution_text.as_bytes())?;
    Ok(format!(
        "{id}: {label} ({outcome:?} after {takeovers} takeovers): {} and {}",
        scenario_path.display(),
        solution_path.display()
    ))
}
