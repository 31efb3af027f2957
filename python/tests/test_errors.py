"""Errors as Python expects them: one `PalcError` hierarchy, the field, value and
bound named, the Rust causes chained, and no panic or bare Rust error reaching Python."""

from __future__ import annotations

import json

import numpy as np
import pytest

import palc
from conftest import LEARN_CONFIG, PLAN_PROBLEM


def test_every_exception_is_a_palc_error() -> None:
    for cls in (
        palc.ConfigError,
        palc.PlanError,
        palc.SolverFailed,
        palc.ScenarioRefused,
        palc.ZoneError,
        palc.ShapeError,
    ):
        assert issubclass(cls, palc.PalcError)
        assert issubclass(cls, Exception)
    assert issubclass(palc.SolverFailed, palc.PlanError)


def test_a_planner_config_out_of_range_names_field_value_and_bound() -> None:
    with pytest.raises(palc.ConfigError) as caught:
        palc.Planner(horizon=0)
    error = caught.value
    assert error.field == "horizon"
    assert error.value == 0
    assert error.bound
    assert "horizon" in str(error)


def test_an_unknown_planner_field_is_refused() -> None:
    with pytest.raises(palc.ConfigError, match="horizn"):
        palc.Planner(horizn=40)


def test_a_wrong_type_in_a_problem_names_its_path() -> None:
    text = PLAN_PROBLEM.read_text().replace('"v": 20.1168', '"v": "fast"', 1)
    with pytest.raises(palc.ConfigError) as caught:
        palc.Problem.from_json(text)
    assert caught.value.field == "problem.initial.v"


def test_invalid_json_is_a_config_error() -> None:
    with pytest.raises(palc.ConfigError):
        palc.Problem.from_json("{")


def test_a_problem_of_the_wrong_horizon_is_a_plan_error() -> None:
    problem = palc.Problem.from_json(PLAN_PROBLEM.read_text())
    with pytest.raises(palc.PlanError) as caught:
        palc.Planner(horizon=problem.horizon + 1).plan(problem)
    assert caught.value.field


def test_a_wrong_shape_names_the_argument() -> None:
    k = 10
    with pytest.raises(palc.ShapeError) as caught:
        palc.Problem(
            initial=[0.0, 20.0, 0.0],
            reference_speed=np.full(k, 20.0),
            weights={"delta_squared": 1.0},
            preceding=np.zeros((k, 2)),
            adjacent=np.zeros((k, 2)),
            terminal_v=20.0,
            terminal_l=3.5,
        )
    assert caught.value.field == "initial"
    assert isinstance(caught.value, ValueError)
    with pytest.raises(palc.ShapeError) as caught:
        palc.ZoneModel().fit(np.zeros((4, 5)), np.zeros(4))
    assert caught.value.field == "X"
    with pytest.raises(palc.ShapeError) as caught:
        palc.ZoneModel().fit(np.zeros((4, 6)), [0, 1, 2, 1])
    assert caught.value.field == "y[2]"


def test_a_non_finite_input_names_its_field_and_index() -> None:
    k = 10
    speeds = np.full(k, 20.0)
    speeds[4] = np.nan
    with pytest.raises(palc.PlanError) as caught:
        palc.Problem(
            initial=[0.0, 20.0, 0.0, 0.0],
            reference_speed=speeds,
            weights={"delta_squared": 1.0},
            preceding=np.zeros((k, 2)),
            adjacent=np.zeros((k, 2)),
            terminal_v=20.0,
            terminal_l=3.5,
        )
    assert caught.value.field == "reference_speed[4]"


def test_a_misnamed_stage_weight_names_its_path() -> None:
    k = 5
    with pytest.raises(palc.ConfigError) as caught:
        palc.Problem(
            initial=[0.0, 20.0, 0.0, 0.0],
            reference_speed=np.full(k, 20.0),
            weights={"delta_sqared": 1.0},
            preceding=np.zeros((k, 2)),
            adjacent=np.zeros((k, 2)),
            terminal_v=20.0,
            terminal_l=3.5,
        )
    assert caught.value.field is not None and caught.value.field.startswith("weights")


def test_a_learn_config_error_keeps_the_dotted_path() -> None:
    with pytest.raises(palc.ConfigError) as caught:
        palc.LearnConfig.from_dict({"loop": {"max_takeovers": 0}})
    assert caught.value.field == "loop.max_takeovers"
    assert caught.value.value == 0
    with pytest.raises(palc.ConfigError) as caught:
        palc.LearnConfig.from_dict({"planning": {"standard_alc": {"time_headway_s": "x"}}})
    assert caught.value.field == "planning.standard_alc.time_headway_s"


def test_an_unknown_style_names_the_field_and_the_choices() -> None:
    with pytest.raises(palc.ConfigError) as caught:
        palc.LearnConfig.from_dict({"user": {"style": "reckless"}})
    assert caught.value.field == "user.style"
    assert "reckless" in str(caught.value) and "neutral" in str(caught.value)


def test_a_missing_file_is_an_os_error_or_a_palc_error() -> None:
    with pytest.raises((OSError, palc.PalcError)):
        palc.LearnConfig.from_toml(LEARN_CONFIG.parent / "no-such-config.toml")


def test_zone_model_json_errors_name_the_field() -> None:
    model = json.loads(palc.ZoneModel().to_json())
    model["config"]["ridge"] = "large"
    with pytest.raises(palc.ConfigError) as caught:
        palc.ZoneModel.from_json(json.dumps(model))
    assert caught.value.field == "config.ridge"
