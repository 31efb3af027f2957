"""Simulators written in Python: subclass :class:`World` and pass it to
:func:`palc.learn` or :class:`palc.LearningLoop` as ``world=``.

The learning loop then drives every lane change in that simulator's traffic
instead of palc's own: at the start of each lane change it calls
:meth:`World.place` with the scene at the trigger (the ego, its preceding vehicle
and the target-lane platoon, in palc's coordinates: ``s`` is a vehicle's front
bumper along the road, ``l`` its centre line, positive to the left of the ego
lane's centre), then :meth:`World.step` once per step with the ego's state at the
end of the step. Plans, the user's judgement at 0.3 m, lessons and the safety
measures are palc's, on the states the simulator reports; predictions roll out
palc's IDM from them. :mod:`palc.highway` and :mod:`palc.sumo` implement it on
highway-env and on SUMO.
"""

from __future__ import annotations

import sys
from typing import Dict, List

if sys.version_info >= (3, 11):
    from typing import TypedDict
else:  # pragma: no cover - Python < 3.11
    from typing_extensions import TypedDict

__all__ = ["Ego", "Placement", "Report", "World", "WorldVehicle"]


class WorldVehicle(TypedDict):
    """One vehicle of a placed scene."""

    #: Identifier, reported back by :meth:`World.step`; the ego's is 0.
    id: int
    #: ``ego``, ``preceding``, ``adjacent`` (the target-lane vehicle the ego will
    #: follow) or ``other``.
    role: str
    #: palc's lane index: 0 is the ego's lane, 1 the target lane on its left.
    lane: int
    #: Front bumper along the road (m).
    s: float
    #: Centre line, positive to the left of lane 0's centre (m).
    l: float
    #: Speed (m/s).
    v: float
    #: Length and width (m).
    length: float
    width: float
    #: IDM parameters in palc's traffic: ``v0``, ``t``, ``s0``, ``a``, ``b``, ``delta``.
    idm: Dict[str, float]


class Placement(TypedDict):
    """The scene at the trigger, as :meth:`World.place` receives it."""

    #: Step (s).
    dt: float
    #: Number of lanes and their width (m).
    lanes: int
    lane_width: float
    #: Every vehicle, the ego first.
    vehicles: List[WorldVehicle]


class Ego(TypedDict):
    """The ego's state at the end of a step."""

    s: float
    l: float
    v: float
    heading: float


class Report(TypedDict):
    """One background vehicle's state after a step."""

    id: int
    s: float
    l: float
    v: float


class World:
    """A simulator the learning loop drives its lane changes in. Override
    :meth:`place` and :meth:`step`; raise an exception when the simulator fails
    (the run ends with it, and :class:`palc.SimulatorError` names the world)."""

    #: The world's name in messages.
    name: str = "python"

    def place(self, scene: Placement) -> None:
        """Replaces what the simulator holds by ``scene`` (the start of a lane change)."""
        raise NotImplementedError(f"{type(self).__name__} does not define place(scene)")

    def step(self, ego: Ego) -> List[Report]:
        """Moves the ego to ``ego``, advances one step and reports every other vehicle."""
        raise NotImplementedError(f"{type(self).__name__} does not define step(ego)")
