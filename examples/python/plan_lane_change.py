"""Plan one lane change with palc and plot it (with matplotlib, if installed).

Run from the repository root after `pip install .`:

    python examples/python/plan_lane_change.py

The problem is the example input of `palc plan` (configs/examples/plan-problem.json);
the plan is the same as `palc plan --problem configs/examples/plan-problem.json`.
"""

from __future__ import annotations

import sys
from pathlib import Path

import palc

ROOT = Path(__file__).resolve().parents[2]


def main() -> int:
    problem = palc.Problem.load(ROOT / "configs" / "examples" / "plan-problem.json")
    planner = palc.Planner(**(problem.config or {}))
    plan = planner.plan(problem)

    s, v, l, phi = plan.states.T
    a, delta = plan.controls.T
    print(f"horizon K = {problem.horizon}, objective = {plan.objective:.6g}")
    print(f"solver: {plan.stats['status']} in {plan.stats['iterations']} iterations")
    print(f"lateral position: {l[0]:.2f} m -> {l[-1]:.2f} m over {s[-1] - s[0]:.1f} m of road")
    print(f"largest steering angle {abs(delta).max():.4f} rad, largest |a| {abs(a).max():.3f} m/s^2")
    for name, row in zip(palc.STAGE_WEIGHT_NAMES, plan.features):
        print(f"  feature {name:>15}: {row.sum():12.4f}")

    try:
        import matplotlib.pyplot as plt
    except ImportError:
        print("(install matplotlib to see the plot)")
        return 0
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(8, 5), sharex=True)
    top.plot(s, l, label="planned l")
    top.axhline(1.75, color="grey", linestyle="--", linewidth=0.8, label="lane marking")
    top.set_ylabel("l (m)")
    top.legend()
    bottom.plot(s[:-1], delta, label="steering angle")
    bottom.set_xlabel("s (m)")
    bottom.set_ylabel("delta (rad)")
    fig.tight_layout()
    plt.show()
    return 0


if __name__ == "__main__":
    sys.exit(main())
