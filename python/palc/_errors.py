"""The exceptions of palc: one class per kind of error of the Rust crates.

Every error raised by palc is a `PalcError`. Where the Rust error names a field,
a value and a bound, they are the attributes `field`, `value` and `bound`
(otherwise `None`); the Rust error's causes are chained as `__cause__`.
"""

from __future__ import annotations

from typing import Optional, Union

__all__ = [
    "PalcError",
    "ConfigError",
    "PlanError",
    "SolverFailed",
    "ScenarioRefused",
    "ZoneError",
    "ShapeError",
    "SimulatorError",
    "SimulatorMissing",
]


class PalcError(Exception):
    """Any error of palc, and a panic of its Rust code (which the libraries avoid)."""

    #: Dotted path of the input field at fault (e.g. ``loop.max_takeovers``), if known.
    field: Optional[str] = None
    #: The value found in that field, if the error carries it.
    value: Optional[Union[float, str]] = None
    #: The bound the value violates, in words, if the error carries it.
    bound: Optional[str] = None


class ConfigError(PalcError, ValueError):
    """A config or input that does not parse or is out of its bound."""


class PlanError(PalcError):
    """The planner refused a problem (infeasible, non-convex, invalid input)."""


class SolverFailed(PlanError):
    """The planner's QP solver stopped without a solution."""


class ScenarioRefused(PalcError):
    """A scenario that does not fit the planning set-up; `kind` names the check."""

    #: The refusal's kind, as counted in the evaluation (e.g. ``standard-never-starts``).
    kind: Optional[str] = None


class ZoneError(PalcError):
    """The zone filter refused a fit, an update or a query."""


class ShapeError(PalcError, ValueError):
    """An array argument of the wrong shape, or not convertible to float64; `field`
    names the argument."""


class SimulatorError(PalcError):
    """The simulator a lane change was driven in failed (it died, lost a vehicle, or
    reported a state out of range); the run ends with this error."""


class SimulatorMissing(PalcError, ImportError):
    """A simulator bridge whose simulator is not installed; the message names the
    missing package and the ``pip install palc[...]`` line that installs it."""

    #: The missing package, e.g. ``highway-env``.
    package: Optional[str] = None
    #: The extra that installs it, e.g. ``highway``.
    extra: Optional[str] = None

    def __init__(self, package: str, extra: str) -> None:
        super().__init__(
            f"this bridge needs the Python package `{package}`, which is not installed: "
            f"`pip install palc[{extra}]` installs it"
        )
        self.package = package
        self.extra = extra
