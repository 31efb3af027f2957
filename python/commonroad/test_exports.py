"""palc's CommonRoad exports, checked with CommonRoad's own tools.

`palc export commonroad` writes the default scene's learned lane change into
`<export>/default` and the paper's grid (speed cases x adjacent headways x
styles) into `<export>/grid`, where `<export>` is `target/commonroad-export`
or `$PALC_COMMONROAD_EXPORT`. These tests

- read every scenario and solution back with commonroad-io,
- check the default scene's solution with the drivability checker's
  `valid_solution` (goal, start state, collisions, road boundary, KS feasibility),
- measure the share of the grid's lane changes that pass the KS feasibility
  check (`trajectory_feasibility` with `position_orientation_objective` and the
  default 2 cm / 0.03 rad tolerance) and write it, with the reason for each
  failure, to `target/commonroad-check/SUMMARY.md` (or
  `$PALC_COMMONROAD_SUMMARY`). The share is reported, not asserted.
"""

import os
import time
import warnings
from pathlib import Path

import numpy as np
import pytest
from commonroad.common.file_reader import CommonRoadFileReader
from commonroad.common.solution import CommonRoadSolutionReader
from commonroad_dc.feasibility import feasibility_checker
from commonroad_dc.feasibility.solution_checker import (
    SolutionCheckerException,
    obstacle_collision,
    valid_solution,
)
from commonroad_dc.feasibility.vehicle_dynamics import VehicleDynamics

ROOT = Path(__file__).resolve().parents[2]
EXPORT = Path(os.environ.get("PALC_COMMONROAD_EXPORT", ROOT / "target" / "commonroad-export"))
SUMMARY = Path(
    os.environ.get("PALC_COMMONROAD_SUMMARY", ROOT / "target" / "commonroad-check" / "SUMMARY.md")
)
HINT = "run `palc export commonroad [--grid] --out DIR` first, or `cargo xtask test`"


def exports(directory: Path):
    """(scenario path, solution path) of every scenario in `directory`."""
    if not directory.is_dir():
        pytest.fail(f"{directory} does not exist: {HINT}")
    pairs = []
    for scenario in sorted(directory.glob("*.xml")):
        if scenario.name.startswith("solution_"):
            continue
        solution = directory / f"solution_KS2_SM1_{scenario.stem}_2020a.xml"
        assert solution.is_file(), f"{scenario} has no solution {solution.name}"
        pairs.append((scenario, solution))
    if not pairs:
        pytest.fail(f"no scenario in {directory}: {HINT}")
    return pairs


def read(scenario_path: Path, solution_path: Path):
    """The scenario, its planning problems and the solution, read by commonroad-io."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scenario, problems = CommonRoadFileReader(str(scenario_path)).open()
        solution = CommonRoadSolutionReader.open(str(solution_path))
    return scenario, problems, solution


def all_exports():
    return exports(EXPORT / "default") + exports(EXPORT / "grid")


@pytest.mark.parametrize("scenario_path, solution_path", all_exports(), ids=lambda p: p.stem)
def test_every_export_reads_back(scenario_path, solution_path):
    scenario, problems, solution = read(scenario_path, solution_path)
    assert str(scenario.scenario_id) == scenario_path.stem
    assert solution.scenario_id == scenario.scenario_id
    assert solution.benchmark_id == f"KS2:SM1:{scenario_path.stem}:2020a"
    assert len(scenario.lanelet_network.lanelets) == 2
    right, left = (scenario.lanelet_network.find_lanelet_by_id(i) for i in (1, 2))
    assert right.adj_left == 2 and right.adj_left_same_direction
    assert left.adj_right == 1 and left.adj_right_same_direction
    assert scenario.dynamic_obstacles, "the scene has other vehicles"
    (problem_solution,) = solution.planning_problem_solutions
    problem = problems.planning_problem_dict[problem_solution.planning_problem_id]
    states = problem_solution.trajectory.state_list
    assert [s.time_step for s in states] == list(range(len(states)))
    first, initial = states[0], problem.initial_state
    assert np.allclose(first.position, initial.position)
    assert first.velocity == pytest.approx(initial.velocity)
    assert first.orientation == pytest.approx(initial.orientation)
    # Every obstacle is known at every step of the ego's trajectory.
    for obstacle in scenario.dynamic_obstacles:
        assert obstacle.prediction.final_time_step >= states[-1].time_step


def test_the_default_scene_is_a_valid_solution():
    ((scenario_path, solution_path),) = exports(EXPORT / "default")
    scenario, problems, solution = read(scenario_path, solution_path)
    valid, results = valid_solution(scenario, problems, solution)
    feasible = {pp: result[0] for pp, result in results.items()}
    assert valid, f"{scenario_path.name}: feasibility per planning problem {feasible}"


def failure_reason(scenario, problem_solution, inputs) -> str:
    """Why the KS feasibility check failed: the first transition it could not
    reproduce, with the errors of the best input it found."""
    dynamics = VehicleDynamics.from_model(problem_solution.vehicle_model, problem_solution.vehicle_type)
    states = problem_solution.trajectory.state_list
    step = len(inputs.state_list) - 1
    x0, _ = dynamics.state_to_array(states[step])
    x1, _ = dynamics.state_to_array(states[step + 1])
    u = inputs.state_list[-1]
    simulated = dynamics.forward_simulation(
        x0, np.array([u.steering_angle_speed, u.acceleration]), scenario.dt, throw=False
    )
    if simulated is None:
        return (
            f"step {step} -> {step + 1}: no input within the BMW 320i's bounds "
            f"(steering rate {u.steering_angle_speed:.3f} rad/s, acceleration {u.acceleration:.2f} m/s^2)"
        )
    dx, dy = np.abs(x1[:2] - simulated[:2])
    dpsi = abs((x1[4] - simulated[4] + np.pi) % (2 * np.pi) - np.pi)
    return (
        f"step {step} -> {step + 1}: best input misses by x {100 * dx:.1f} cm, y {100 * dy:.1f} cm, "
        f"heading {dpsi:.4f} rad (tolerance 2 cm, 2 cm, 0.03 rad); "
        f"steering {x0[2]:.4f} rad, heading {x0[4]:.4f} -> {x1[4]:.4f} rad"
    )


def test_grid_feasibility_summary():
    started = time.monotonic()
    rows = []
    for scenario_path, solution_path in exports(EXPORT / "grid"):
        scenario, problems, solution = read(scenario_path, solution_path)
        (problem_solution,) = solution.planning_problem_solutions
        dynamics = VehicleDynamics.from_model(
            problem_solution.vehicle_model, problem_solution.vehicle_type
        )
        feasible, inputs = feasibility_checker.trajectory_feasibility(
            problem_solution.trajectory,
            dynamics,
            scenario.dt,
            objective=feasibility_checker.position_orientation_objective,
        )
        try:
            collides = obstacle_collision(scenario, problems, solution)
        except SolutionCheckerException:
            collides = True
        reason = "" if feasible else failure_reason(scenario, problem_solution, inputs)
        rows.append((scenario_path.stem, scenario.source, feasible, collides, reason))
    passed = sum(1 for row in rows if row[2])
    lines = [
        "# CommonRoad check of palc's exported lane changes",
        "",
        f"{passed} of {len(rows)} learned lane changes of the grid ({100 * passed / len(rows):.0f} %) "
        "pass the KS feasibility check (BMW 320i, `trajectory_feasibility` with "
        "`position_orientation_objective`, 2 cm and 0.03 rad per step).",
        f"{sum(1 for row in rows if row[3])} collide with an obstacle (CommonRoad's collision checker, "
        "the BMW 320i's shape).",
        f"Checked in {time.monotonic() - started:.0f} s.",
        "",
    ]
    failures = [row for row in rows if not row[2]]
    if failures:
        lines += ["## Failures", "", "| scenario | scene | reason |", "| --- | --- | --- |"]
        lines += [f"| {stem} | {source} | {reason} |" for stem, source, _, _, reason in failures]
        lines.append("")
    lines += ["## Every lane change", "", "| scenario | scene | KS feasible | collision |", "| --- | --- | --- | --- |"]
    lines += [
        f"| {stem} | {source} | {'yes' if ok else 'no'} | {'yes' if hit else 'no'} |"
        for stem, source, ok, hit, _ in rows
    ]
    SUMMARY.parent.mkdir(parents=True, exist_ok=True)
    partial = SUMMARY.with_suffix(".md.tmp")
    partial.write_text("\n".join(lines) + "\n")
    partial.replace(SUMMARY)
    assert SUMMARY.is_file() and SUMMARY.stat().st_size > 0
