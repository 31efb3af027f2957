"""Teach palc a driver written in Python, lane change by lane change.

Run from the repository root after `pip install .`:

    python examples/python/teach_a_driver.py
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import palc

ROOT = Path(__file__).resolve().parents[2]


class Patient(palc.User):
    """Waits until the time headway to the car ahead falls to 1.5 s, then moves over
    in 3 s."""

    name = "patient"

    def nominal(self, scene: palc.Scene) -> palc.LaneChange:
        headway = scene["situations"]["time_headway_s"]
        start = int(np.argmax(headway <= 1.5))
        return {"start_s": start * scene["dt"], "duration_s": 3.0}


def main() -> int:
    config = palc.LearnConfig.from_toml(ROOT / "configs" / "learn.toml")
    learning = palc.LearningLoop(config, user=Patient())
    for record in learning:
        gap = np.abs(record["planned_l"] - record["expected_l"]).max()
        taken = "taken over" if record["takeover"] else "accepted"
        print(f"lane change {record['index'] + 1}: {taken}, largest |planned - expected| {gap:.3f} m")
    result = learning.result()
    print(f"{result.outcome} after {result.takeovers} takeovers")
    return 0


if __name__ == "__main__":
    sys.exit(main())
