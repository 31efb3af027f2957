"""The lesson-learning loop from Python: the same run as `palc learn`, configs from
TOML and dicts, and experience saved and loaded."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import numpy as np
import pytest

import palc
from conftest import LEARN_CONFIG


def test_a_config_from_a_dict_equals_the_same_config_from_toml() -> None:
    tomllib = pytest.importorskip("tomllib")
    from_file = palc.LearnConfig.from_toml(LEARN_CONFIG)
    with LEARN_CONFIG.open("rb") as f:
        from_dict = palc.LearnConfig.from_dict(tomllib.load(f))
    assert from_file.to_dict() == from_dict.to_dict()
    assert from_file.label == from_dict.label
    assert from_file.method == "palc"


def test_learn_gives_the_command_lines_summary(palc_bin: Path, tmp_path: Path) -> None:
    record = tmp_path / "record.json"
    subprocess.run(
        [str(palc_bin), "learn", "--config", str(LEARN_CONFIG), "--record", str(record)],
        check=True,
        stdout=subprocess.DEVNULL,
    )
    cli = json.loads(record.read_text())
    result = palc.learn(palc.LearnConfig.from_toml(LEARN_CONFIG))
    assert result.summary == cli["summary"]
    assert result.lane_changes == len(result.records) == len(cli["records"])
    for mine, theirs in zip(result.records, cli["records"]):
        assert np.array_equal(mine["planned_l"], np.array(theirs["planned_l"]))
        assert np.array_equal(mine["driven_l"], np.array(theirs["driven_l"]))


def test_experience_carries_into_the_next_run(tmp_path: Path) -> None:
    config = palc.LearnConfig.from_toml(LEARN_CONFIG)
    first = palc.learn(config)
    assert first.outcome == "personalized"
    path = tmp_path / "experience.json"
    first.experience.save(path)
    loaded = palc.Experience.load(path)
    second = palc.learn(config, experience=loaded)
    assert second.takeovers <= first.takeovers
    record = second.records[0]
    k = second.horizon
    assert record["planned_l"].shape == (k + 1,)
