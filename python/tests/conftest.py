"""Shared fixtures of the palc package's tests: the repository's example inputs and
the `palc` binary that the CLI comparisons run (`PALC_BIN`, set by `cargo xtask test`)."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PLAN_PROBLEM = ROOT / "configs" / "examples" / "plan-problem.json"
ZONE_SAMPLES = ROOT / "configs" / "examples" / "zone-samples.csv"
LEARN_CONFIG = ROOT / "configs" / "learn.toml"


@pytest.fixture(scope="session")
def palc_bin() -> Path:
    """The `palc` command line, or a skip when it is not built."""
    given = os.environ.get("PALC_BIN")
    candidates = [Path(given)] if given else []
    candidates.append(ROOT / "target" / "release" / "palc")
    found = shutil.which("palc")
    if found:
        candidates.append(Path(found))
    for candidate in candidates:
        if candidate.is_file():
            return candidate
    pytest.skip("the palc binary is not built (cargo build --release -p palc-cli, or set PALC_BIN)")
