"""The hand-written stubs (python/palc/_palc.pyi) match the native module:
`mypy.stubtest` compares every class, method, parameter name and default."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from conftest import ROOT


def test_the_stubs_match_the_native_module(tmp_path: Path) -> None:
    pytest.importorskip("mypy.stubtest")
    allowlist = ROOT / "python" / "stubtest-allowlist.txt"
    result = subprocess.run(
        [sys.executable, "-m", "mypy.stubtest", "palc", "--allowlist", str(allowlist)],
        cwd=tmp_path,  # mypy's cache stays out of the repository
        capture_output=True,
        text=True,
    )
    assert result.returncode == 0, result.stdout + result.stderr
