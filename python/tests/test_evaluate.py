"""The evaluation from Python: a small evaluation config run into a directory,
its runs read back as rows, progress reported, the GIL released while it runs, and
a bad config refused before anything is written."""

from __future__ import annotations

import os
import signal
import threading
import time
from pathlib import Path

import pytest

import palc
from conftest import LEARN_CONFIG


def small_config(tmp_path: Path) -> Path:
    """One cell, one method, the deterministic neutral user."""
    config = tmp_path / "small.toml"
    config.write_text(
        f"""base = "{LEARN_CONFIG.as_posix()}"

[grid]
methods = ["palc"]
speed_cases = ["collector-high"]
headways_m = [40.0]
styles = ["neutral"]
seeds = [1]

[[users]]
name = "deterministic"

[transfer]
source = "next-speed-case"
users = []

[timing]
methods = ["palc"]
dts = [0.1]
horizon_margins_s = [1.0]
styles = ["neutral"]
speed_case = "collector-high"
headway_m = 40.0
seed = 1

[example]
method = "palc"
style = "neutral"
speed_case = "collector-high"
headway_m = 40.0
seed = 1

[quick]
users = ["deterministic"]

[quick.grid]
methods = ["palc"]
speed_cases = ["collector-high"]
headways_m = [40.0]
styles = ["neutral"]
seeds = [1]

[quick.timing]
methods = ["palc"]
dts = [0.1]
horizon_margins_s = [1.0]
styles = ["neutral"]
speed_case = "collector-high"
headway_m = 40.0
seed = 1
"""
    )
    return config


def test_evaluate_writes_the_report_and_read_runs_reads_it(tmp_path: Path) -> None:
    calls: list[tuple[int, int]] = []
    out = tmp_path / "out"
    outcome = palc.evaluate(
        small_config(tmp_path), out=out, jobs=1, progress=lambda done, total: calls.append((done, total))
    )
    assert Path(outcome["report"]).is_file()
    assert outcome["runs"] >= 1
    rows = palc.read_runs(out)
    assert len(rows) == outcome["runs"]
    assert rows == palc.read_runs(out / "runs.csv")
    first = rows[0]
    assert first["method"] == "palc" and first["style"] == "neutral"
    assert isinstance(first["takeovers"], int)
    # A run id is 16 hex digits, kept a string even when it reads as a number.
    assert isinstance(first["run_id"], str) and len(first["run_id"]) == 16
    assert calls[0] == (0, outcome["runs"]) and calls[-1] == (outcome["runs"], outcome["runs"])
    assert outcome["idle_experiments"] == []


def test_evaluate_in_a_thread_leaves_the_main_thread_responsive(tmp_path: Path) -> None:
    result: dict[str, object] = {}
    worker = threading.Thread(
        target=lambda: result.update(palc.evaluate(small_config(tmp_path), out=tmp_path / "out", jobs=1))
    )
    ticks = 0
    worker.start()
    while worker.is_alive():
        ticks += 1
        time.sleep(0.001)
    worker.join()
    assert result["runs"]
    assert ticks > 10


def test_a_bad_config_is_refused_and_leaves_the_previous_results(tmp_path: Path) -> None:
    out = tmp_path / "out"
    out.mkdir()
    (out / "REPORT.md").write_text("previous")
    bad = tmp_path / "bad.toml"
    bad.write_text(small_config(tmp_path).read_text().replace('methods = ["palc"]', 'methods = ["palc"]\nbogus = 1'))
    with pytest.raises(palc.ConfigError) as caught:
        palc.evaluate(bad, out=out, jobs=1)
    assert "bogus" in str(caught.value)
    assert (out / "REPORT.md").read_text() == "previous"
    for jobs in (0, 100_000):
        with pytest.raises(palc.ConfigError) as caught:
            palc.evaluate(small_config(tmp_path), out=out, jobs=jobs)
        assert caught.value.field == "jobs"
    assert (out / "REPORT.md").read_text() == "previous"


def test_an_exception_in_the_progress_callback_is_raised(tmp_path: Path) -> None:
    def progress(done: int, total: int) -> None:
        raise RuntimeError("the bar broke")

    with pytest.raises(RuntimeError, match="the bar broke"):
        palc.evaluate(small_config(tmp_path), out=tmp_path / "out", jobs=1, progress=progress)
    # The exception stopped the evaluation: nothing was written.
    assert not (tmp_path / "out").exists()


def test_ctrl_c_cancels_the_evaluation_and_writes_nothing(tmp_path: Path) -> None:
    calls: list[tuple[int, int]] = []

    def progress(done: int, total: int) -> None:
        calls.append((done, total))
        if done == 0:
            # Ctrl-C before the first run; the sleep lets the waiting thread see it
            # before any run starts.
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.5)

    with pytest.raises(KeyboardInterrupt):
        palc.evaluate(small_config(tmp_path), out=tmp_path / "out", jobs=1, progress=progress)
    assert calls == [(0, calls[0][1])], "no run finished after Ctrl-C"
    assert not (tmp_path / "out").exists()
