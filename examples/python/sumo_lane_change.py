"""Teach palc a driver among SUMO's traffic, seeded and headless, and print the
bridge's overhead per step.

Run from the repository root after `pip install .[sumo]`:

    python examples/python/sumo_lane_change.py [OUT_DIR] [STYLE]

The background vehicles follow SUMO's IDM with the scene's parameters; the ego is
moved where palc drives it with `moveToXY(..., keepRoute=2)`. OUT_DIR
(`target/sumo/` by default) receives the road (plain XML and the net netconvert
built), each lane change's route file and FCD output (Parquet), and palc's record
of the run (`record.json`).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import palc
from palc.sumo import SumoWorld

ROOT = Path(__file__).resolve().parents[2]


def main() -> None:
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "target" / "sumo"
    style = sys.argv[2] if len(sys.argv) > 2 else "neutral"
    text = (ROOT / "configs" / "learn.toml").read_text()
    config = palc.LearnConfig.from_toml_str(text.replace('style = "neutral"', f'style = "{style}"'))

    with SumoWorld(out=out, seed=1) as world:
        started = time.perf_counter()
        result = palc.learn(config, world=world)
        elapsed = time.perf_counter() - started
    for record in result.records:
        verdict = "takeover" if record["takeover"] else "accepted"
        print(f"lane change {record['index']}: {verdict}, smallest gap to the target lane's lag "
              f"{record['safety']['min_gap_target_lag_m'] or float('nan'):.1f} m")
    print(f"{style} user in SUMO: {result.outcome} after {result.counted_takeovers} takeovers")
    print(f"{world.steps} SUMO steps: bridge (moveToXY and reading the vehicles) {world.overhead_ms():.3f} ms per step, "
          f"SUMO's step {1e3 * world.sumo_s / world.steps:.3f} ms, the whole run {elapsed:.2f} s with palc's planning")
    record = out / "record.json"
    temporary = record.with_name(f".{record.name}.tmp")
    temporary.write_text(result.to_json())
    temporary.replace(record)  # written whole or not at all
    print(f"FCD output and palc's record in {out}")


if __name__ == "__main__":
    main()
