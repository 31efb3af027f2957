"""Drivers written in Python: subclass :class:`User` and pass it to
:func:`palc.learn` or :class:`palc.LearningLoop`.

The loop shows the driver each scene as a :class:`Scene` dict (NumPy arrays over
the steps of the search window) and asks for the lane change it expects, a
:class:`LaneChange` dict. The expected states keep the lane-keeping motion of the
scene and move laterally along a quintic (minimum-jerk) profile; the driver takes
over when a plan strays further than the run's ``planning.takeover_threshold_m``
from them, or by its own rule if it overrides :meth:`User.takes_over`. An exception raised by the driver stops the run and reaches the caller
as itself, with its traceback.
"""

from __future__ import annotations

import sys
from typing import Dict

import numpy as np
import numpy.typing as npt

if sys.version_info >= (3, 11):
    from typing import NotRequired, TypedDict
else:  # pragma: no cover - Python < 3.11
    from typing_extensions import NotRequired, TypedDict

__all__ = ["LaneChange", "Scene", "User"]


class Scene(TypedDict):
    """What the driver sees, step by step over the search window (step ``dt``)."""

    #: Step (s).
    dt: float
    #: The ego's set speed (m/s).
    set_speed: float
    #: Lateral position of the target lane's centre (m); the current lane's is 0.
    target_l: float
    #: ``[s - s0, v]`` per step of the ego keeping its lane, shape (n, 2).
    lane_keeping: npt.NDArray[np.float64]
    #: Per step, shape (n,): ``time_headway_s``, ``preceding_gap_m``,
    #: ``preceding_speed``, ``target_lead_gap_m``, ``target_lag_gap_m``,
    #: ``ego_speed``, ``target_lead_speed``, ``target_lag_speed`` (NaN where there is
    #: no such vehicle).
    situations: Dict[str, npt.NDArray[np.float64]]


class LaneChange(TypedDict):
    """The lane change a driver expects; times from the start of the scene (s)."""

    #: When the lateral move starts (s).
    start_s: float
    #: How long the lateral move takes (s).
    duration_s: float
    #: When the driver decided (s); the start by default.
    decision_s: NotRequired[float]
    #: Lateral position before the move (m); 0 by default.
    from_l: NotRequired[float]
    #: Lateral position after the move (m); the target lane's centre by default.
    to_l: NotRequired[float]


class User:
    """A driver written in Python. Override :meth:`nominal` (and :meth:`next` for a
    driver whose lane changes vary)::

        class Early(palc.User):
            def nominal(self, scene):
                headway = scene["situations"]["time_headway_s"]
                start = int(np.argmax(headway < 2.0))
                return {"start_s": start * scene["dt"], "duration_s": 4.0}
    """

    #: The driver's name in messages and records.
    name: str = "python"

    def nominal(self, scene: Scene) -> LaneChange:
        """The lane change the driver expects in ``scene`` with its usual habits."""
        raise NotImplementedError(f"{type(self).__name__} does not define nominal(scene)")

    def next(self, scene: Scene) -> LaneChange:
        """The lane change of the next drive; the nominal one unless overridden."""
        return self.nominal(scene)

    def takes_over(
        self, step: int, ego: Dict[str, float], expected_l: float, seen: Dict[str, float]
    ) -> bool:
        """Whether the driver takes over at ``step`` of a drive, the ego at ``ego``
        (``s``, ``v``, ``l``, ``phi``) where it expected ``expected_l``, seeing
        ``seen`` (the keys of ``Scene["situations"]`` at this step). Called only when
        a subclass overrides it; otherwise the loop applies the run's deviation rule
        (``planning.takeover_threshold_m``) itself, and this default answers no."""
        return False

    def acceleration_after_takeover(self, step: int, speed: float, acc: float) -> float:
        """The driver's longitudinal acceleration (m/s²) at ``step`` after it took
        over, driving at ``speed`` (m/s), when the ego's ACC would command ``acc``
        (which keeps the distance to whatever is ahead). Called only when a subclass
        overrides it, and bounded by the ego's limits as the built-in users' is;
        otherwise the loop applies the built-in rule (the ACC's command), which is
        what this default returns. A value that is not a finite number raises
        ``ValueError`` to the caller of the run."""
        return acc
