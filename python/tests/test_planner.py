"""The planner from Python: the same plan as `palc plan`, arrays of the documented
shapes, and problems built from arrays."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import numpy as np
import pytest

import palc
from conftest import PLAN_PROBLEM


def example() -> palc.Problem:
    return palc.Problem.from_json(PLAN_PROBLEM.read_text())


def test_plan_equals_the_command_line_bit_for_bit(palc_bin: Path, tmp_path: Path) -> None:
    out = tmp_path / "plan.json"
    subprocess.run(
        [str(palc_bin), "plan", "--problem", str(PLAN_PROBLEM), "--out", str(out)],
        check=True,
    )
    cli = json.loads(out.read_text())
    problem = example()
    assert problem.config is not None
    plan = palc.Planner(**problem.config).plan(problem)

    states = np.array([[x["s"], x["v"], x["l"], x["phi"]] for x in cli["states"]])
    controls = np.array([[u["a"], u["delta"]] for u in cli["controls"]])
    features = np.array(cli["features"]).T
    # Exact equality: serde_json writes the shortest text that reads back the same double.
    assert np.array_equal(plan.states, states)
    assert np.array_equal(plan.controls, controls)
    assert np.array_equal(plan.features, features)
    assert np.array_equal(plan.lateral_violation, np.array(cli["lateral_violation"]))
    assert plan.objective == cli["objective"]
    assert plan.learned_cost == cli["learned_cost"]
    assert plan.extras == cli["extras"]
    assert plan.stats["iterations"] == cli["stats"]["iterations"]
    assert plan.stats["status"] == cli["stats"]["status"] == cli["status"]


def test_plan_arrays_have_the_documented_shapes_and_dtype() -> None:
    problem = example()
    k = problem.horizon
    plan = palc.Planner(**(problem.config or {})).plan(problem)
    for array, shape in [
        (plan.states, (k + 1, 4)),
        (plan.controls, (k, 2)),
        (plan.features, (10, k)),
        (plan.lateral_violation, (k + 1,)),
    ]:
        assert array.shape == shape
        assert array.dtype == np.float64
        assert array.flags["C_CONTIGUOUS"]
    assert plan.objective == pytest.approx(plan.learned_cost + sum(plan.extras.values()))
    # The plan ends in the target lane, as the terminal condition asks.
    assert plan.states[-1, 2] == pytest.approx(json.loads(PLAN_PROBLEM.read_text())["problem"]["terminal"]["l"], abs=1e-6)


def test_a_problem_from_arrays_equals_the_same_problem_from_json() -> None:
    whole = json.loads(PLAN_PROBLEM.read_text())
    p = whole["problem"]
    terminal = p["terminal"]
    bounds = p.get("lateral_bounds")
    bound_array = None
    if bounds is not None:
        bound_array = np.array(
            [
                [
                    -np.inf if b is None or b.get("min") is None else b["min"],
                    np.inf if b is None or b.get("max") is None else b["max"],
                ]
                for b in bounds
            ]
        )
    from_arrays = palc.Problem(
        initial=[p["initial"][key] for key in ("s", "v", "l", "phi")],
        reference_speed=p["reference_speed"],
        weights=np.array(p["weights"]).T,
        preceding=[[x["s"], x["l"]] for x in p["preceding"]],
        adjacent=[[x["s"], x["l"]] for x in p["adjacent"]],
        terminal_v=terminal["v"],
        terminal_l=terminal["l"],
        terminal_s=terminal.get("s"),
        lateral_bounds=bound_array,
        curvature=p.get("curvature", 0.0),
    )
    from_json = example()
    assert from_arrays.horizon == from_json.horizon
    assert np.array_equal(from_arrays.weights, from_json.weights)
    planner = palc.Planner(**whole["config"])
    a = planner.plan(from_arrays)
    b = palc.Planner(**whole["config"]).plan(from_json)
    assert np.array_equal(a.states, b.states)
    assert a.objective == b.objective


def test_stage_weights_by_name_are_the_same_at_every_step() -> None:
    problem = example()
    k = problem.horizon
    stage = {"l_squared": 0.01, "phi_squared": 1.0, "delta_squared": 200.0}
    built = palc.Problem(
        initial=[0.0, 20.0, 0.0, 0.0],
        reference_speed=np.full(k, 20.0),
        weights=stage,
        preceding=np.tile([60.0, 0.0], (k, 1)),
        adjacent=np.tile([-40.0, 3.5], (k, 1)),
        terminal_v=20.0,
        terminal_l=3.5,
    )
    rows = list(palc.STAGE_WEIGHT_NAMES)
    assert len(rows) == 10
    for name, value in stage.items():
        assert np.all(built.weights[rows.index(name)] == value)
    plan = palc.Planner(horizon=k).plan(built)
    assert plan.states.shape == (k + 1, 4)


def test_replan_from_the_previous_plan_gives_the_same_optimum() -> None:
    problem = example()
    planner = palc.Planner(**(problem.config or {}))
    first = planner.plan(problem)
    again = planner.replan(problem, first)
    assert np.allclose(again.states, first.states, atol=1e-6)


def test_the_planner_config_is_filled_in() -> None:
    planner = palc.Planner(horizon=40)
    assert planner.config["horizon"] == 40
    assert planner.config["dt"] == 0.1


def test_problem_json_round_trips() -> None:
    problem = example()
    again = palc.Problem.from_json(problem.to_json())
    assert again.config is None
    assert np.array_equal(again.weights, problem.weights)


def test_a_byte_order_mark_before_the_json_is_skipped() -> None:
    problem = palc.Problem.from_json("\ufeff" + PLAN_PROBLEM.read_text())
    assert problem.horizon == example().horizon
