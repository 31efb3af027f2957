"""Run the quick evaluation from Python and read its runs as a table.

Run from the repository root after `pip install .` (about two minutes on two
cores; pandas and tqdm are used if installed):

    python examples/python/evaluate_to_dataframe.py
"""

from __future__ import annotations

import sys
from collections import Counter

import palc


def main() -> int:
    try:
        from tqdm import tqdm

        progress = tqdm(unit="run")
    except ImportError:
        progress = lambda done, total: print(f"\r{done}/{total} runs", end="", flush=True)  # noqa: E731
    outcome = palc.evaluate("configs/reproduce.toml", out="target/py-eval", quick=True, progress=progress)
    print(f"\n{outcome['runs']} runs in {outcome['wall_s']:.0f} s; report: {outcome['report']}")
    rows = palc.read_runs("target/py-eval")
    try:
        import pandas as pd
    except ImportError:
        print(Counter((row["method"], row["outcome"]) for row in rows))
        return 0
    frame = pd.DataFrame(rows)
    print(frame.groupby(["experiment", "method"])["takeovers"].describe())
    return 0


if __name__ == "__main__":
    sys.exit(main())
