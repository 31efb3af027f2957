"""Types of the native module `palc._palc` (crates/palc-py); import `palc` instead."""

from __future__ import annotations

import os
from typing import Any, Mapping, Optional, Tuple, Union, final

import numpy as np
import numpy.typing as npt

_ArrayLike = npt.ArrayLike
_Float = npt.NDArray[np.float64]
_Int = npt.NDArray[np.int64]
_Path = Union[str, "os.PathLike[str]"]

__all__ = [
    "Experience",
    "LearnConfig",
    "LearnResult",
    "LearningLoop",
    "Plan",
    "Planner",
    "Problem",
    "STAGE_WEIGHT_NAMES",
    "ZoneModel",
    "__version__",
    "evaluate",
    "learn",
]

__version__: str
STAGE_WEIGHT_NAMES: Tuple[str, ...]

@final
class Problem:
    """One lane change to plan: the input of `palc plan`."""

    def __new__(
        cls,
        initial: _ArrayLike,
        reference_speed: _ArrayLike,
        weights: Union[_ArrayLike, Mapping[str, float]],
        preceding: _ArrayLike,
        adjacent: _ArrayLike,
        terminal_v: float,
        terminal_l: float,
        *,
        terminal_s: Optional[float] = None,
        lateral_bounds: Optional[_ArrayLike] = None,
        curvature: float = 0.0,
    ) -> Problem: ...
    @staticmethod
    def from_json(text: str) -> Problem: ...
    @staticmethod
    def load(path: _Path) -> Problem: ...
    def to_json(self) -> str: ...
    @property
    def config(self) -> Optional[dict[str, Any]]: ...
    @property
    def weights(self) -> _Float: ...
    @property
    def horizon(self) -> int: ...

@final
class Planner:
    """The lane-change MPC; keyword arguments are the fields of `PlannerConfig`."""

    def __new__(cls, **config: Any) -> Planner: ...
    def plan(self, problem: Problem) -> Plan: ...
    def replan(self, problem: Problem, previous: Plan) -> Plan: ...
    @property
    def config(self) -> dict[str, Any]: ...

@final
class Plan:
    """An optimal lane change."""

    @property
    def states(self) -> _Float: ...
    @property
    def controls(self) -> _Float: ...
    @property
    def features(self) -> _Float: ...
    @property
    def lateral_violation(self) -> _Float: ...
    @property
    def objective(self) -> float: ...
    @property
    def learned_cost(self) -> float: ...
    @property
    def extras(self) -> dict[str, float]: ...
    @property
    def stats(self) -> dict[str, Any]: ...
    def to_json(self) -> str: ...

@final
class ZoneModel:
    """The GDA model of the perceived safe zone, under scikit-learn's names."""

    def __new__(cls, **config: Any) -> ZoneModel: ...
    def fit(self, X: _ArrayLike, y: _ArrayLike) -> ZoneModel: ...
    def update(self, X: _ArrayLike, y: _ArrayLike) -> ZoneModel: ...
    def predict_proba(self, X: _ArrayLike) -> _Float: ...
    def predict(self, X: _ArrayLike) -> _Int: ...
    def decision_function(self, X: _ArrayLike) -> _Float: ...
    def lateral_bounds(
        self,
        ego_s: _ArrayLike,
        reference_l: _ArrayLike,
        ego_speed: _ArrayLike,
        preceding: _ArrayLike,
        adjacent: _ArrayLike,
        **config: Any,
    ) -> _Float: ...
    @property
    def classes_(self) -> _Int: ...
    @property
    def n_features_in_(self) -> int: ...
    @property
    def is_informative(self) -> bool: ...
    @property
    def config(self) -> dict[str, Any]: ...
    def to_json(self) -> str: ...
    @staticmethod
    def from_json(text: str) -> ZoneModel: ...

@final
class LearnConfig:
    """The config of one learning run, as `palc learn --config` reads it."""

    def __new__(cls) -> LearnConfig: ...
    @staticmethod
    def from_toml(path: _Path) -> LearnConfig: ...
    @staticmethod
    def from_toml_str(text: str) -> LearnConfig: ...
    @staticmethod
    def from_dict(d: Mapping[str, Any]) -> LearnConfig: ...
    def to_dict(self) -> dict[str, Any]: ...
    @property
    def label(self) -> str: ...
    @property
    def method(self) -> str: ...

@final
class Experience:
    """What a learning run learned: weights, zone model and onsets."""

    @staticmethod
    def load(path: _Path) -> Experience: ...
    def save(self, path: _Path) -> None: ...

@final
class LearnResult:
    """Everything a learning run produced."""

    @property
    def outcome(self) -> str: ...
    @property
    def takeovers(self) -> int: ...
    @property
    def counted_takeovers(self) -> int: ...
    @property
    def lane_changes(self) -> int: ...
    @property
    def summary(self) -> dict[str, Any]: ...
    @property
    def records(self) -> list[dict[str, Any]]: ...
    @property
    def label(self) -> str: ...
    @property
    def horizon(self) -> int: ...
    @property
    def dt(self) -> float: ...
    @property
    def experience(self) -> Experience: ...
    def to_json(self) -> str: ...

@final
class LearningLoop:
    """The lesson-learning loop, lane change by lane change."""

    def __new__(
        cls,
        config: LearnConfig,
        user: Optional[Any] = None,
        experience: Optional[Experience] = None,
        world: Optional[Any] = None,
    ) -> LearningLoop: ...
    def __iter__(self) -> LearningLoop: ...
    def __next__(self) -> dict[str, Any]: ...
    @property
    def outcome(self) -> Optional[str]: ...
    def driver_estimate(self) -> Optional[str]: ...
    def gap_acceptance(self) -> Optional[str]: ...
    def result(self) -> LearnResult: ...

def learn(
    config: LearnConfig,
    experience: Optional[Experience] = None,
    user: Optional[Any] = None,
    world: Optional[Any] = None,
) -> LearnResult: ...


def evaluate(
    config: _Path = ...,
    *,
    out: _Path = ...,
    quick: bool = False,
    jobs: Optional[int] = None,
    progress: Optional[Any] = None,
) -> dict[str, Any]: ...
