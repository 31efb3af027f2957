"""palc in highway-env: a registered environment, ``palc/HighwayLaneChange-v0``, that
places a palc scene on a straight road of highway-env, and :class:`HighwayWorld`,
the :class:`palc.World` that lets the learning loop drive its lane changes there::

    import palc
    from palc.highway import HighwayWorld

    world = HighwayWorld()
    result = palc.learn(palc.LearnConfig(), world=world)

The background vehicles are highway-env's ``IDMVehicle`` with palc's IDM parameters
(desired speed, time gap, acceleration, comfortable deceleration, exponent; the
standstill gap plus the vehicle's length, as highway-env measures distances between
centres), lane changes disabled, stepped at 10 Hz (``simulation_frequency`` =
``policy_frequency`` = 10, palc's planning step). The ego is placed where palc's plan
(or the user, after a takeover) drives it at each step, with palc's ACC underneath.

Coordinates: highway-env's lane 0 is the leftmost and its ``y`` grows to the right;
palc's lane 0 is the ego's lane and ``l`` grows to the left; highway-env's
positions are centres, palc's ``s`` is the front bumper. :func:`to_highway` and
:func:`from_highway` convert.

highway-env and gymnasium are an optional extra: ``pip install palc[highway]``;
without them, importing this module raises :class:`palc.SimulatorMissing`.
"""

from __future__ import annotations

from typing import Any, Dict, List, Optional, Tuple, cast

from palc._errors import SimulatorMissing
from palc._world import Ego, Placement, Report, World

try:
    import gymnasium as gym
    import numpy as np
    from highway_env.envs.common.abstract import AbstractEnv  # type: ignore[import-untyped]
    from highway_env.road.lane import LineType, StraightLane  # type: ignore[import-untyped]
    from highway_env.road.road import Road, RoadNetwork  # type: ignore[import-untyped]
    from highway_env.vehicle.behavior import IDMVehicle  # type: ignore[import-untyped]
    from highway_env.vehicle.kinematics import Vehicle  # type: ignore[import-untyped]
except ImportError as _missing:  # pragma: no cover - depends on the installation
    _package = "gymnasium" if getattr(_missing, "name", "") == "gymnasium" else "highway-env"
    raise SimulatorMissing(_package, "highway") from _missing

__all__ = [
    "ENV_ID",
    "HighwayLaneChangeEnv",
    "HighwayWorld",
    "default_scene",
    "from_highway",
    "to_highway",
]

#: The environment's identifier in gymnasium's registry.
ENV_ID = "palc/HighwayLaneChange-v0"

#: The road's length in highway-env (m): far beyond any lane change's reach.
ROAD_LENGTH_M = 10_000.0


def to_highway(s: float, l: float, length: float, lanes: int, lane_width: float) -> Tuple[float, float]:
    """palc's ``(s, l)`` of a vehicle (front bumper, left of lane 0's centre) as
    highway-env's centre ``(x, y)`` (lane 0 leftmost, ``y`` to the right)."""
    return s - length / 2, (lanes - 1) * lane_width - l


def from_highway(x: float, y: float, length: float, lanes: int, lane_width: float) -> Tuple[float, float]:
    """highway-env's centre ``(x, y)`` as palc's ``(s, l)``; the inverse of :func:`to_highway`."""
    return x + length / 2, (lanes - 1) * lane_width - y


def default_scene(dt: float = 0.1) -> Dict[str, Any]:
    """A scene in the shape :meth:`palc.World.place` receives, for a ``reset()``
    without one: the ego at 20.1 m/s behind a slower vehicle at 17.9 m/s (the paper's
    45 / 40 mph), and a target-lane platoon of four vehicles 40 m apart."""
    idm = {"v0": 17.9, "t": 1.6, "s0": 2.0, "a": 0.73, "b": 1.67, "delta": 4.0}

    def vehicle(id: int, role: str, lane: int, s: float, v: float) -> Dict[str, Any]:
        return {"id": id, "role": role, "lane": lane, "s": s, "l": lane * 3.5, "v": v,
                "length": 5.0, "width": 1.8, "idm": dict(idm, v0=max(v, 1.0))}

    vehicles = [vehicle(0, "ego", 0, 20.0, 20.1), vehicle(1, "preceding", 0, 80.0, 17.9)]
    for k in range(4):
        role = "adjacent" if k == 1 else "other"
        vehicles.append(vehicle(2 + k, role, 1, 100.0 - 40.0 * k, 17.9))
    return {"dt": dt, "lanes": 2, "lane_width": 3.5, "vehicles": vehicles}


class ImposedVehicle(Vehicle):
    """The ego in highway-env: its state at each step is the one palc imposes."""

    pending: Optional[Tuple[np.ndarray, float, float]] = None

    def step(self, dt: float) -> None:
        if self.pending is not None:
            self.position, self.heading, self.speed = self.pending
            self.pending = None
        self.on_state_update()


class HighwayLaneChangeEnv(AbstractEnv):
    """A palc scene on a straight road of highway-env, stepped at palc's planning
    step. ``reset(options={"scene": scene})`` places a scene in the shape
    :meth:`palc.World.place` receives (:func:`default_scene` without one);
    ``step(ego)`` takes the ego's state in palc's coordinates (a dict ``s``, ``l``,
    ``v``, ``heading``; ``None`` leaves it where it is) and advances one step. The
    reward is 0: palc's learning loop, not a reward, drives the ego."""

    @classmethod
    def default_config(cls) -> dict:
        config = super().default_config()
        config.update(
            {
                "observation": {"type": "Kinematics"},
                "action": {"type": "ContinuousAction"},
                "simulation_frequency": 10,
                "policy_frequency": 10,
                "lanes_count": 2,
                "lane_width": 3.5,
                "screen_width": 800,
                "screen_height": 160,
                "scaling": 6.0,
                "centering_position": [0.35, 0.5],
            }
        )
        return config

    def reset(self, *, seed: Optional[int] = None, options: Optional[dict] = None) -> Any:
        self._scene = (options or {}).get("scene") or default_scene(1 / self.config["simulation_frequency"])
        dt = float(self._scene["dt"])
        frequency = round(1 / dt)
        if abs(frequency * dt - 1) > 1e-9:
            raise ValueError(f"the scene's step dt = {dt} s is not 1 / n s: highway-env steps at a whole frequency")
        config = dict((options or {}).get("config") or {})
        config.update(simulation_frequency=frequency, policy_frequency=frequency,
                      lanes_count=int(self._scene["lanes"]), lane_width=float(self._scene["lane_width"]))
        return super().reset(seed=seed, options={"config": config})

    def _reset(self) -> None:
        lanes, width = self.config["lanes_count"], self.config["lane_width"]
        network = RoadNetwork()
        for lane in range(lanes):
            y = lane * width
            lines = [LineType.CONTINUOUS_LINE if lane == 0 else LineType.STRIPED,
                     LineType.CONTINUOUS_LINE if lane == lanes - 1 else LineType.NONE]
            network.add_lane("0", "1", StraightLane([0.0, y], [ROAD_LENGTH_M, y], width=width,
                                                     line_types=lines, speed_limit=100.0))
        self.road = Road(network=network, np_random=self.np_random,
                         record_history=self.config["show_trajectories"])
        self.palc_vehicles: Dict[int, Vehicle] = {}
        self.controlled_vehicles = []
        for placed in self._scene["vehicles"]:
            x, y = to_highway(placed["s"], placed["l"], placed["length"], lanes, width)
            if placed["role"] == "ego":
                vehicle: Vehicle = ImposedVehicle(self.road, [x, y], 0.0, placed["v"])
                self.controlled_vehicles.append(vehicle)
            else:
                idm = placed["idm"]
                lane_index = ("0", "1", lanes - 1 - int(placed["lane"]))
                vehicle = IDMVehicle(self.road, [x, y], 0.0, placed["v"], target_lane_index=lane_index,
                                     target_speed=idm["v0"], enable_lane_change=False)
                vehicle.COMFORT_ACC_MAX = idm["a"]
                vehicle.COMFORT_ACC_MIN = -idm["b"]
                vehicle.TIME_WANTED = idm["t"]
                vehicle.DISTANCE_WANTED = idm["s0"] + placed["length"]
                vehicle.DELTA = idm["delta"]
            vehicle.LENGTH, vehicle.WIDTH = placed["length"], placed["width"]
            self.palc_vehicles[int(placed["id"])] = vehicle
            self.road.vehicles.append(vehicle)
        if not self.controlled_vehicles:
            raise ValueError("the scene has no vehicle with role `ego`")

    def step(self, action: Optional[Dict[str, float]]) -> Any:
        self.impose(action)
        return super().step(None)

    def impose(self, ego: Optional[Dict[str, float]]) -> None:
        """Sets the ego's state at the end of the next step (palc's coordinates)."""
        if ego is not None:
            lanes, width = self.config["lanes_count"], self.config["lane_width"]
            x, y = to_highway(ego["s"], ego["l"], self.vehicle.LENGTH, lanes, width)
            self.vehicle.pending = (np.array([x, y]), -float(ego.get("heading", 0.0)), float(ego["v"]))

    def advance(self, ego: Optional[Dict[str, float]]) -> List[Dict[str, float]]:
        """``step(ego)`` without the observation, reward and info: one step of the
        simulation, then :meth:`report`. What :class:`HighwayWorld` calls."""
        self.impose(ego)
        self.time += 1 / self.config["policy_frequency"]
        self._simulate(None)
        return self.report()

    def report(self) -> List[Dict[str, float]]:
        """Every background vehicle's state in palc's coordinates (``id``, ``s``, ``l``, ``v``)."""
        lanes, width = self.config["lanes_count"], self.config["lane_width"]
        reports = []
        for id, vehicle in self.palc_vehicles.items():
            if vehicle is self.vehicle:
                continue
            s, l = from_highway(float(vehicle.position[0]), float(vehicle.position[1]), vehicle.LENGTH, lanes, width)
            v = float(vehicle.speed * np.cos(vehicle.heading))
            reports.append({"id": id, "s": s, "l": l, "v": max(v, 0.0)})
        return reports

    def _reward(self, action: Any) -> float:
        return 0.0

    def _rewards(self, action: Any) -> Dict[str, float]:
        return {}

    def _is_terminated(self) -> bool:
        return bool(self.vehicle.crashed)

    def _is_truncated(self) -> bool:
        return False


def register() -> None:
    """Registers :data:`ENV_ID` with gymnasium (done when this module is imported)."""
    if ENV_ID not in gym.registry:
        gym.register(id=ENV_ID, entry_point="palc.highway:HighwayLaneChangeEnv")


register()


class HighwayWorld(World):
    """highway-env's traffic as the world of palc's learning loop. With ``record=True``
    it keeps the rendered frames of the last lane change in :attr:`frames`
    (``rgb_array``: highway-env draws off screen, without a display; its viewer draws
    nothing under ``SDL_VIDEODRIVER=dummy``)."""

    name = "highway-env"

    def __init__(self, record: bool = False, config: Optional[dict] = None) -> None:
        made = gym.make(ENV_ID, render_mode="rgb_array" if record else None)
        self.env = cast(HighwayLaneChangeEnv, made.unwrapped)
        self.record = record
        self.config = config or {}
        #: The frames of the last lane change placed, when recording.
        self.frames: List[np.ndarray] = []
        #: Lane changes placed, and steps driven, so far.
        self.placements = 0
        self.steps = 0

    def place(self, scene: Placement) -> None:
        self.env.reset(options={"scene": scene, "config": self.config})
        self.placements += 1
        self.frames = [cast(np.ndarray, self.env.render())] if self.record else []

    def step(self, ego: Ego) -> List[Report]:
        reports = self.env.advance(cast(Dict[str, float], ego))
        self.steps += 1
        if self.record:
            self.frames.append(cast(np.ndarray, self.env.render()))
        return cast(List[Report], reports)

    def close(self) -> None:
        """Closes highway-env's viewer."""
        self.env.close()
