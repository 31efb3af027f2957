"""Fit the perceived safe zone on labelled samples, then run one lesson-learning loop
with a built-in simulated user and save what it learned.

Run from the repository root after `pip install .`:

    python examples/python/zone_and_learning.py
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

import palc

ROOT = Path(__file__).resolve().parents[2]


def main() -> int:
    data = np.loadtxt(ROOT / "configs" / "examples" / "zone-samples.csv", delimiter=",", skiprows=1)
    X, y = data[:, :6], data[:, 6]
    zone = palc.ZoneModel().fit(X, y)
    accuracy = np.mean(zone.predict(X) == y)
    print(f"zone model on {len(X)} samples: training accuracy {accuracy:.3f}")

    config = palc.LearnConfig.from_toml(ROOT / "configs" / "learn.toml")
    result = palc.learn(config)
    print(f"{result.label} ({config.method}): {result.outcome}, "
          f"{result.takeovers} takeovers in {result.lane_changes} lane changes")
    for record in result.records:
        gap = np.abs(record["planned_l"] - record["expected_l"]).max()
        print(f"  lane change {record['index'] + 1}: largest |planned - expected| = {gap:.3f} m")

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "experience.json"
        result.experience.save(path)
        again = palc.learn(config, experience=palc.Experience.load(path))
        print(f"with that experience: {again.takeovers} takeovers")

    try:
        palc.LearnConfig.from_dict({"loop": {"max_takeovers": 0}})
    except palc.ConfigError as error:
        print(f"a bad config names its field: {error.field} = {error.value!r} ({error.bound})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
