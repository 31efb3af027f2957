"""The evaluation's runs as plain Python data: :func:`read_runs` reads the
``runs.csv`` that :func:`palc.evaluate` (and ``palc eval``) writes, one dict per
run, which ``pandas.DataFrame(rows)`` or ``polars.DataFrame(rows)`` turn into a
table."""

from __future__ import annotations

import csv
import os
from pathlib import Path
from typing import Dict, List, Optional, Union

__all__ = ["read_runs"]

Value = Optional[Union[int, float, str]]

# Columns kept as text: a run id is hex digits, which may read as a number.
_TEXT = frozenset({"run_id"})


def _value(text: str) -> Value:
    """An empty cell as ``None``, a whole number as ``int``, a number as ``float``."""
    if text == "":
        return None
    try:
        return int(text)
    except ValueError:
        pass
    try:
        return float(text)
    except ValueError:
        return text


def read_runs(path: Union[str, "os.PathLike[str]"]) -> List[Dict[str, Value]]:
    """The runs of an evaluation: ``path`` is its output directory (``out`` of
    :func:`palc.evaluate`) or its ``runs.csv``. Each run is a dict of the CSV's
    columns (``experiment``, ``method``, ``user``, ``style``, ``outcome``,
    ``takeovers``, ...); an empty cell is ``None``, and ``run_id`` (a hash of
    what the run runs) stays a string."""
    file = Path(path)
    if file.is_dir():
        file = file / "runs.csv"
    with file.open(newline="", encoding="utf-8") as f:
        return [
            {key: cell if key in _TEXT else _value(cell) for key, cell in row.items()}
            for row in csv.DictReader(f)
        ]
