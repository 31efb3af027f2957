"""palc in highway-env (`palc.highway`): the conversions, the registered environment
with lane-keeping IDM traffic at 10 Hz, the learning loop of the paper's users in it,
headless frames, and the error when highway-env is missing."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

import palc
from conftest import LEARN_CONFIG

highway = pytest.importorskip("palc.highway")
gym = pytest.importorskip("gymnasium")


def config(style: str) -> palc.LearnConfig:
    text = LEARN_CONFIG.read_text()
    return palc.LearnConfig.from_toml_str(text.replace('style = "neutral"', f'style = "{style}"'))


def test_lane_zero_is_highway_envs_leftmost_and_positions_are_centres() -> None:
    # palc's lane 0 (the ego's, on the right) is highway-env's lane 1 of two.
    x, y = highway.to_highway(s=50.0, l=0.0, length=5.0, lanes=2, lane_width=3.5)
    assert (x, y) == pytest.approx((47.5, 3.5))
    x, y = highway.to_highway(s=50.0, l=3.5, length=5.0, lanes=2, lane_width=3.5)
    assert y == pytest.approx(0.0)
    for s, l in [(0.0, 0.0), (123.4, 1.75), (-8.0, 3.9)]:
        back = highway.from_highway(*highway.to_highway(s, l, 4.8, 2, 3.5), 4.8, 2, 3.5)
        assert back == pytest.approx((s, l))


def test_the_registered_environment_keeps_lanes_at_10_hz() -> None:
    env = gym.make(highway.ENV_ID)
    env.reset()
    unwrapped = env.unwrapped
    assert unwrapped.config["simulation_frequency"] == unwrapped.config["policy_frequency"] == 10
    scene = highway.default_scene()
    placed = {v["id"]: v for v in scene["vehicles"]}
    ego = dict(s=20.0, l=0.0, v=20.1, heading=0.0)
    for _ in range(30):
        ego["s"] += ego["v"] * 0.1
        env.step(ego)
    reports = unwrapped.report()
    assert sorted(r["id"] for r in reports) == sorted(i for i in placed if i != 0)
    for report in reports:
        assert report["l"] == pytest.approx(placed[report["id"]]["l"], abs=1e-6)
        assert report["s"] > placed[report["id"]]["s"]
    ego_s, ego_l = highway.from_highway(*unwrapped.vehicle.position, 5.0, 2, 3.5)
    assert (ego_s, ego_l) == pytest.approx((ego["s"], 0.0))
    env.close()


@pytest.mark.parametrize("style", ["aggressive", "cautious"])
def test_the_papers_users_are_taught_in_highway_env_traffic(style: str) -> None:
    own = palc.learn(config(style))
    world = highway.HighwayWorld()
    there = palc.learn(config(style), world=world)
    assert there.outcome == "personalized"
    assert abs(there.counted_takeovers - own.counted_takeovers) <= 0.5
    assert world.placements == there.lane_changes
    assert all(not r["safety"]["collision"] for r in there.records)


def test_frames_are_rendered_headless() -> None:
    world = highway.HighwayWorld(record=True)
    world.place(highway.default_scene())
    world.step({"s": 22.0, "l": 0.0, "v": 20.1, "heading": 0.0})
    assert len(world.frames) == 2
    frame = world.frames[-1]
    assert frame.ndim == 3 and frame.shape[2] == 3 and frame.dtype == np.uint8
    assert frame.std() > 0  # a road and vehicles, not a blank image
    world.close()


def test_a_missing_highway_env_names_the_package_and_the_extra() -> None:
    code = (
        "import sys; sys.modules['highway_env'] = None\n"
        "import palc\n"
        "try:\n"
        "    import palc.highway\n"
        "except palc.SimulatorMissing as e:\n"
        "    print(e.package, e.extra, isinstance(e, ImportError), e)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.startswith("highway-env highway True")
    assert "pip install palc[highway]" in out
