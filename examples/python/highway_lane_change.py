"""Teach palc a driver in highway-env's traffic, and save the learned lane change as
an animated GIF rendered headless.

Run from the repository root after `pip install .[highway]`:

    python examples/python/highway_lane_change.py [OUT.gif] [STYLE]

The learning loop is palc's (plans, the simulated user judging at 0.3 m, lessons,
safety measures); the background vehicles are highway-env's `IDMVehicle`s with the
scene's IDM parameters, stepped at 10 Hz. The GIF shows the last lane change of the
run, the one the user accepted.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

from PIL import Image

import palc
from palc.highway import HighwayWorld

ROOT = Path(__file__).resolve().parents[2]


def main() -> None:
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "target" / "highway" / "lane-change.gif"
    style = sys.argv[2] if len(sys.argv) > 2 else "cautious"
    text = (ROOT / "configs" / "learn.toml").read_text()
    config = palc.LearnConfig.from_toml_str(text.replace('style = "neutral"', f'style = "{style}"'))

    world = HighwayWorld(record=True)
    started = time.perf_counter()
    learning = palc.LearningLoop(config, world=world)
    for record in learning:
        verdict = "takeover" if record["takeover"] else "accepted"
        print(f"lane change {record['index']}: {verdict}, max deviation {record['max_deviation_m']:.2f} m")
    result = learning.result()
    elapsed = time.perf_counter() - started
    print(f"{style} user in highway-env: {result.outcome} after {result.counted_takeovers} takeovers")
    print(f"{world.steps} highway-env steps in {elapsed:.2f} s ({1e3 * elapsed / world.steps:.2f} ms per step, planning included)")

    out.parent.mkdir(parents=True, exist_ok=True)
    frames = [Image.fromarray(frame) for frame in world.frames]
    temporary = out.with_name(f".{out.name}.tmp")
    frames[0].save(temporary, format="GIF", save_all=True, append_images=frames[1:], duration=100, loop=0)
    temporary.replace(out)  # written whole or not at all
    print(f"{len(frames)} frames of the learned lane change -> {out}")
    world.close()


if __name__ == "__main__":
    main()
