"""palc: personalized automated lane change from Python.

The lane-change planner (a convex MPC), the perceived safe zone (a Gaussian
discriminant analysis model under scikit-learn's names) and the lesson-learning
loop of Hu et al., implemented in Rust and called with NumPy arrays::

    import palc

    problem = palc.Problem.from_json(open("configs/examples/plan-problem.json").read())
    plan = palc.Planner(**problem.config).plan(problem)
    plan.states      # (K+1, 4): s, v, l, phi
    plan.controls    # (K, 2): a, delta

Every error is a :class:`PalcError`; see :mod:`palc._errors` for its subclasses.
"""

from __future__ import annotations

from palc._errors import (
    ConfigError,
    PalcError,
    PlanError,
    ScenarioRefused,
    ShapeError,
    SimulatorError,
    SimulatorMissing,
    SolverFailed,
    ZoneError,
)
from palc._palc import (
    STAGE_WEIGHT_NAMES,
    Experience,
    LearnConfig,
    LearningLoop,
    LearnResult,
    Plan,
    Planner,
    Problem,
    ZoneModel,
    __version__,
    evaluate,
    learn,
)
from palc._runs import read_runs
from palc._user import LaneChange, Scene, User
from palc._world import World

__all__ = [
    "STAGE_WEIGHT_NAMES",
    "ConfigError",
    "Experience",
    "LearnConfig",
    "LearnResult",
    "LaneChange",
    "LearningLoop",
    "PalcError",
    "Plan",
    "PlanError",
    "Planner",
    "Problem",
    "ScenarioRefused",
    "Scene",
    "ShapeError",
    "SimulatorError",
    "SimulatorMissing",
    "SolverFailed",
    "User",
    "World",
    "ZoneError",
    "ZoneModel",
    "__version__",
    "evaluate",
    "learn",
    "read_runs",
]
