"""Drivers written in Python and the learning loop lane change by lane change."""

from __future__ import annotations

import traceback

import numpy as np
import pytest

import palc
from conftest import LEARN_CONFIG


class Neutral(palc.User):
    """The paper's neutral driver in a few lines: it starts when the time headway
    to the preceding vehicle falls to 1.23 s and changes lanes in 2.1 s."""

    name = "neutral in Python"

    def nominal(self, scene: palc.Scene) -> palc.LaneChange:
        headway = scene["situations"]["time_headway_s"]
        start = int(np.argmax(headway <= 1.23))
        return {"start_s": start * scene["dt"], "duration_s": 2.1}


class Broken(Neutral):
    def next(self, scene: palc.Scene) -> palc.LaneChange:
        raise KeyError("no such habit")


def config() -> palc.LearnConfig:
    return palc.LearnConfig.from_toml(LEARN_CONFIG)


def test_the_loop_yields_every_lane_change_and_the_same_result_as_learn() -> None:
    whole = palc.learn(config())
    learning = palc.LearningLoop(config())
    records = list(learning)
    assert learning.outcome == whole.outcome
    result = learning.result()
    assert result.summary == whole.summary
    assert len(records) == len(whole.records) == result.lane_changes
    for mine, theirs in zip(records, whole.records):
        assert mine["index"] == theirs["index"]
        assert np.array_equal(mine["planned_l"], theirs["planned_l"])
    with pytest.raises(palc.PalcError, match="result"):
        next(learning)


def test_the_loop_says_what_it_believes_about_the_driver_after_a_lesson() -> None:
    learning = palc.LearningLoop(config())
    assert learning.driver_estimate() is None
    first = next(learning)
    assert first["takeover"] is not None, "the standard plan is taken over"
    belief = learning.driver_estimate()
    assert belief is not None and "decides on the time-headway" in belief, belief
    assert "scenes seen: 1" in belief
    allowed = learning.gap_acceptance()
    assert allowed is not None and "decides on the time-headway at" in allowed, allowed
    assert "follower's gap of" in allowed


def test_no_start_allows_no_gap_acceptance_driver() -> None:
    assert palc.LearningLoop(config()).gap_acceptance() is None


def test_result_runs_a_loop_to_its_end() -> None:
    learning = palc.LearningLoop(config())
    first = next(learning)
    assert first["index"] == 0
    assert learning.result().summary == palc.learn(config()).summary


def test_a_python_driver_is_taught_by_the_loop() -> None:
    result = palc.learn(config(), user=Neutral())
    assert result.outcome == "personalized"
    assert result.lane_changes >= 3
    last = result.records[-1]
    assert np.abs(last["planned_l"] - last["expected_l"]).max() <= 0.3


def test_a_python_driver_like_the_built_in_one_gives_its_run() -> None:
    ours = palc.learn(config(), user=Neutral())
    built_in = palc.learn(config())
    assert ours.summary == built_in.summary
    for mine, theirs in zip(ours.records, built_in.records):
        assert np.array_equal(mine["expected_l"], theirs["expected_l"])


def test_an_exception_in_a_python_driver_surfaces_with_its_traceback() -> None:
    with pytest.raises(KeyError, match="no such habit") as caught:
        palc.learn(config(), user=Broken())
    frames = traceback.extract_tb(caught.value.__traceback__)
    assert any(frame.name == "next" for frame in frames)


def test_a_bad_answer_names_the_field() -> None:
    class Late(Neutral):
        def nominal(self, scene: palc.Scene) -> palc.LaneChange:
            return {"start_s": 1e6, "duration_s": 2.1}

    with pytest.raises(palc.PalcError, match="start_s"):
        palc.learn(config(), user=Late())

    class Misspelt(Neutral):
        def nominal(self, scene: palc.Scene) -> palc.LaneChange:
            return {"start_s": 1.0, "duration": 2.1}  # type: ignore[typeddict-item]

    with pytest.raises(palc.ConfigError) as caught:
        palc.learn(config(), user=Misspelt())
    assert "duration" in str(caught.value)


def test_a_driver_that_never_takes_over_is_personalized_at_once() -> None:
    class Lenient(Neutral):
        def takes_over(self, step: int, ego: dict, expected_l: float, seen: dict) -> bool:
            return False

    result = palc.learn(config(), user=Lenient())
    assert result.outcome == "personalized"
    assert result.takeovers == 0


def test_an_exception_in_takes_over_surfaces_with_its_traceback() -> None:
    class Nervous(Neutral):
        def takes_over(self, step: int, ego: dict, expected_l: float, seen: dict) -> bool:
            raise ValueError(f"no rule for step {step}")

    with pytest.raises(ValueError, match="no rule for step") as caught:
        palc.learn(config(), user=Nervous())
    assert any(frame.name == "takes_over" for frame in traceback.extract_tb(caught.value.__traceback__))
    learning = palc.LearningLoop(config(), user=Nervous())
    with pytest.raises(ValueError, match="no rule for step"):
        next(learning)


def test_the_acceleration_after_a_takeover_is_the_python_drivers() -> None:
    calls: list[tuple[int, float, float]] = []

    class Follows(Neutral):
        def acceleration_after_takeover(self, step: int, speed: float, acc: float) -> float:
            calls.append((step, speed, acc))
            return acc

    built_in = palc.learn(config())
    result = palc.learn(config(), user=Follows())
    assert result.takeovers >= 1 and calls, "no takeover, so no acceleration asked"
    assert all(np.isfinite(speed) and np.isfinite(acc) for _, speed, acc in calls)
    # Answering the ACC's command is the built-in rule for this user: the same run.
    assert result.summary == built_in.summary

    class Brakes(Neutral):
        def acceleration_after_takeover(self, step: int, speed: float, acc: float) -> float:
            return float("nan")

    with pytest.raises(ValueError, match="finite acceleration"):
        palc.learn(config(), user=Brakes())
