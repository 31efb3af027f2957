"""Measure palc's learning loop in palc's own traffic, in highway-env and in SUMO:
the paper's three styles in its four speed cases (every adjacent headway and seed of
`configs/learn.toml`'s test bed), takeovers to personalization, and the experience
carried from the next speed case.

Run from the repository root after `pip install .[highway,sumo]`:

    python examples/python/measure_simulators.py [OUT_DIR] [learn.toml | learn-safe.toml]

Prints the tables of docs/experiments/0069 and writes every run to
`OUT_DIR/runs.json` (`target/simulators/` by default). The base config is the
paper's set-up (`configs/learn.toml`) or the safe one (`configs/learn-safe.toml`:
the ego's ACC, the safety layer, users who wait for gaps at the RSS distance).
"""

from __future__ import annotations

import json
import statistics
import sys
import time
from pathlib import Path
from typing import Any, Callable, Dict, List, Optional

import palc

ROOT = Path(__file__).resolve().parents[2]
STYLES = ["aggressive", "neutral", "cautious"]
SPEED_CASES = ["collector-high", "collector-slow", "arterial-high", "arterial-slow"]
HEADWAYS = [50.0, 45.0, 40.0, 35.0, 30.0]
SEEDS = [1, 2]


BASE = "learn.toml"


def config(style: str, speed_case: str, headway: float, seed: int) -> palc.LearnConfig:
    text = (ROOT / "configs" / BASE).read_text()
    text = text.replace('style = "neutral"', f'style = "{style}"')
    text = text.replace('speed_case = "collector-high"', f'speed_case = "{speed_case}"')
    text = text.replace("headway_m = 40.0", f"headway_m = {headway}")
    text = text.replace("seed = 1\n", f"seed = {seed}\n", 1)
    return palc.LearnConfig.from_toml_str(text)


def run(cfg: palc.LearnConfig, world: Optional[palc.World], experience: Optional[palc.Experience] = None) -> Dict[str, Any]:
    try:
        result = palc.learn(cfg, experience=experience, world=world)
    except palc.ScenarioRefused as refused:
        return {"refused": refused.kind}
    gaps = ["min_gap_preceding_m", "min_gap_target_lead_m", "min_gap_target_lag_m"]
    return {"outcome": result.outcome, "takeovers": result.counted_takeovers,
            "lane_changes": result.lane_changes, "experience": result.experience,
            "collisions": sum(bool(r["safety"]["collision"]) for r in result.records),
            "rss_violations": sum(r["safety"]["rss_violations"] for r in result.records),
            "gaps": [[r["safety"][g] for g in gaps] for r in result.records]}


def worlds() -> Dict[str, Callable[[], Optional[palc.World]]]:
    made: Dict[str, Callable[[], Optional[palc.World]]] = {"palc": lambda: None}
    try:
        from palc.highway import HighwayWorld

        made["highway-env"] = HighwayWorld
    except palc.SimulatorMissing as missing:
        print(f"skipping highway-env: {missing}")
    try:
        from palc.sumo import SumoWorld

        sumo = SumoWorld(fcd=False, seed=1)
        made["sumo"] = lambda: sumo
    except palc.SimulatorMissing as missing:
        print(f"skipping SUMO: {missing}")
    return made


def gap_differences(rows: List[Dict[str, Any]], name: str) -> List[float]:
    """Per gap kind (preceding, target lead, target lag), the mean |difference| of the
    smallest gap of each lane change from palc's own traffic's in the same run (m)."""
    own = {(r["style"], r["speed_case"], r["headway_m"], r["seed"]): r["scratch"] for r in rows if r["world"] == "palc"}
    differences: List[List[float]] = [[], [], []]
    for r in rows:
        base = own.get((r["style"], r["speed_case"], r["headway_m"], r["seed"]))
        if r["world"] != name or not base or "gaps" not in r["scratch"] or "gaps" not in base:
            continue
        for there, here in zip(r["scratch"]["gaps"], base["gaps"]):
            for k in range(3):
                if there[k] is not None and here[k] is not None:
                    differences[k].append(abs(there[k] - here[k]))
    return [statistics.mean(d) if d else float("nan") for d in differences]


def main() -> None:
    global BASE
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "target" / "simulators"
    BASE = sys.argv[2] if len(sys.argv) > 2 else BASE
    rows: List[Dict[str, Any]] = []
    for name, make in worlds().items():
        world = make()
        started = time.perf_counter()
        for style in STYLES:
            for i, case in enumerate(SPEED_CASES):
                source_case = SPEED_CASES[(i + 1) % len(SPEED_CASES)]
                for headway in HEADWAYS:
                    for seed in SEEDS:
                        scratch = run(config(style, case, headway, seed), world)
                        source = run(config(style, source_case, headway, seed), world)
                        carried = None
                        if "experience" in source and "refused" not in scratch:
                            carried = run(config(style, case, headway, seed), world, source["experience"])
                        row = {"world": name, "style": style, "speed_case": case, "headway_m": headway, "seed": seed,
                               "scratch": {k: v for k, v in scratch.items() if k != "experience"},
                               "carried": None if carried is None else {k: v for k, v in carried.items() if k != "experience"}}
                        rows.append(row)
        print(f"{name}: {time.perf_counter() - started:.1f} s")

    print("\n| world | style | speed case | runs (refused) | personalized | mean takeovers | carried from the next speed case | reduction |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    for name in dict.fromkeys(r["world"] for r in rows):
        for style in STYLES + ["all"]:
            for case in SPEED_CASES + ["all"]:
                if (style == "all") != (case == "all"):
                    continue
                chosen = [r for r in rows if r["world"] == name and style in ("all", r["style"]) and case in ("all", r["speed_case"])]
                counted = [r for r in chosen if "refused" not in r["scratch"]]
                pairs = [r for r in counted if r["carried"] and "refused" not in r["carried"]]
                if not counted:
                    continue
                success = sum(r["scratch"]["outcome"] == "personalized" for r in counted)
                mean = statistics.mean(r["scratch"]["takeovers"] for r in counted)
                scratch_pairs = statistics.mean(r["scratch"]["takeovers"] for r in pairs) if pairs else float("nan")
                carried = statistics.mean(r["carried"]["takeovers"] for r in pairs) if pairs else float("nan")
                reduction = 100 * (1 - carried / scratch_pairs) if scratch_pairs else float("nan")
                print(f"| {name} | {style} | {case} | {len(counted)} ({len(chosen) - len(counted)}) | {success}/{len(counted)} "
                      f"| {mean:.2f} | {scratch_pairs:.2f} -> {carried:.2f} | {reduction:.0f} % |")
    collisions = {name: sum(r["scratch"].get("collisions", 0) + ((r["carried"] or {}).get("collisions", 0)) for r in rows if r["world"] == name)
                  for name in dict.fromkeys(r["world"] for r in rows)}
    print(f"\nlane changes with a collision in the steps the system drove, by world: {collisions}")
    rss = {name: sum(r["scratch"].get("rss_violations", 0) for r in rows if r["world"] == name)
           for name in dict.fromkeys(r["world"] for r in rows)}
    print(f"steps below the RSS safe distance in the runs from scratch, by world: {rss}")
    for name in dict.fromkeys(r["world"] for r in rows):
        if name != "palc":
            lead, ahead, lag = gap_differences(rows, name)
            print(f"{name}: smallest gaps' mean |difference| from palc's traffic: preceding {lead:.2f} m, "
                  f"target lead {ahead:.2f} m, target lag {lag:.2f} m")
    out.mkdir(parents=True, exist_ok=True)
    temporary = out / ".runs.json.tmp"
    temporary.write_text(json.dumps(rows, indent=1))
    temporary.replace(out / "runs.json")  # written whole or not at all
    print(f"every run -> {out / 'runs.json'}")


if __name__ == "__main__":
    main()
