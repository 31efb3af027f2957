"""The cost of the Python binding: `Planner.plan` timed from Python next to the
time the planner itself measured (build and solve of the QP) for the same plan,
at K = 120 steps.

Run from the repository root after `pip install .`:

    python examples/python/bench_plan.py
"""

from __future__ import annotations

import sys
import time

import numpy as np

import palc


def problem(k: int) -> palc.Problem:
    s = 20.0 * 0.1 * np.arange(k)
    return palc.Problem(
        initial=[0.0, 20.0, 0.0, 0.0],
        reference_speed=np.full(k, 20.0),
        weights={"l_squared": 0.01, "l": 1.0, "phi_squared": 1.0, "delta_squared": 200.0},
        preceding=np.column_stack([s + 60.0, np.zeros(k)]),
        adjacent=np.column_stack([s - 40.0, np.full(k, 3.5)]),
        terminal_v=20.0,
        terminal_l=3.5,
    )


def main() -> int:
    k = 120
    planner = palc.Planner(horizon=k)
    task = problem(k)
    planner.plan(task)  # the first plan builds the QP's structure
    python, rust = [], []
    for _ in range(500):
        start = time.perf_counter()
        plan = planner.plan(task)
        python.append(time.perf_counter() - start)
        rust.append(plan.stats["build_seconds"] + plan.stats["solve_seconds"])
    py_us, rust_us = 1e6 * np.median(python), 1e6 * np.median(rust)
    print(f"K = {k}: Planner.plan from Python {py_us:.1f} us, in Rust {rust_us:.1f} us "
          f"(median of 500); the binding adds {py_us - rust_us:.1f} us")
    return 0


if __name__ == "__main__":
    sys.exit(main())
