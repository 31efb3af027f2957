"""The learning loop in a simulator written in Python (`palc.World`): a pure-Python
IDM world teaches the paper's users as palc's own traffic does, and a world that
fails ends the run with its own exception or a `palc.SimulatorError`."""

from __future__ import annotations

import math
import traceback
from typing import Dict, List

import pytest

import palc
from conftest import LEARN_CONFIG


class IdmWorld(palc.World):
    """Every background vehicle follows the IDM behind the nearest vehicle ahead
    occupying its lane (the ego occupies every lane its body overlaps), with a
    ballistic update: palc's traffic model, written again in Python."""

    name = "python-idm"
    max_braking = 9.0

    def place(self, scene: Dict) -> None:
        self.dt = scene["dt"]
        self.lane_width = scene["lane_width"]
        self.vehicles: List[Dict] = [dict(v) for v in scene["vehicles"]]
        self.steps = 0

    def occupies(self, vehicle: Dict, lane: int) -> bool:
        if vehicle["role"] != "ego":
            return bool(vehicle["lane"] == lane)
        reach = (self.lane_width + vehicle["width"]) / 2
        return abs(vehicle["l"] - lane * self.lane_width) < reach

    def acceleration(self, vehicle: Dict) -> float:
        p = vehicle["idm"]
        v = vehicle["v"]
        ahead = [
            o
            for o in self.vehicles
            if o is not vehicle and o["s"] > vehicle["s"] and self.occupies(o, vehicle["lane"])
        ]
        free = 1 - (v / p["v0"]) ** p["delta"]
        if not ahead:
            return p["a"] * free
        leader = min(ahead, key=lambda o: o["s"])
        gap = max(leader["s"] - leader["length"] - vehicle["s"], 1e-3)
        wanted = p["s0"] + max(0.0, v * p["t"] + v * (v - leader["v"]) / (2 * math.sqrt(p["a"] * p["b"])))
        return max(p["a"] * (free - (wanted / gap) ** 2), -self.max_braking)

    def step(self, ego: Dict) -> List[Dict]:
        self.steps += 1
        others = [v for v in self.vehicles if v["role"] != "ego"]
        accelerations = [self.acceleration(v) for v in others]
        for vehicle, a in zip(others, accelerations):
            v = vehicle["v"]
            if v + a * self.dt < 0:
                vehicle["s"] += v * v / (2 * -a)
                vehicle["v"] = 0.0
            else:
                vehicle["s"] += v * self.dt + a * self.dt**2 / 2
                vehicle["v"] = v + a * self.dt
        self.vehicles[0].update(s=ego["s"], l=ego["l"], v=ego["v"])
        return [{"id": v["id"], "s": v["s"], "l": v["l"], "v": v["v"]} for v in others]


def config(style: str) -> palc.LearnConfig:
    text = LEARN_CONFIG.read_text()
    return palc.LearnConfig.from_toml_str(text.replace('style = "neutral"', f'style = "{style}"'))


@pytest.mark.parametrize("style", ["aggressive", "neutral", "cautious"])
def test_a_python_idm_world_teaches_as_palc_traffic_does(style: str) -> None:
    own = palc.learn(config(style))
    world = IdmWorld()
    there = palc.learn(config(style), world=world)
    assert there.outcome == own.outcome == "personalized"
    assert abs(there.counted_takeovers - own.counted_takeovers) <= 1
    assert world.steps >= there.lane_changes * 10
    for a, b in zip(own.records, there.records):
        assert a["planned_l"] == pytest.approx(b["planned_l"], abs=0.05)


class Dies(IdmWorld):
    name = "dies"

    def step(self, ego: Dict) -> List[Dict]:
        if self.steps == 5:
            raise ConnectionError("the simulator's process exited")
        return super().step(ego)


class LosesAVehicle(IdmWorld):
    name = "loses"

    def step(self, ego: Dict) -> List[Dict]:
        return super().step(ego)[:-1]


def test_a_world_that_raises_ends_the_run_with_its_exception() -> None:
    with pytest.raises(ConnectionError, match="process exited") as raised:
        palc.learn(config("neutral"), world=Dies())
    assert "in step" in "".join(traceback.format_tb(raised.value.__traceback__))
    learning = palc.LearningLoop(config("neutral"), world=Dies())
    with pytest.raises(ConnectionError):
        next(learning)


def test_a_world_that_loses_a_vehicle_is_a_simulator_error() -> None:
    with pytest.raises(palc.SimulatorError, match="loses") as raised:
        palc.learn(config("neutral"), world=LosesAVehicle())
    assert "was not reported" in str(raised.value.__cause__)


def test_a_world_must_define_place_and_step() -> None:
    with pytest.raises(NotImplementedError, match="place"):
        palc.learn(config("neutral"), world=palc.World())
