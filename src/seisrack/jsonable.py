"""Conversion of results to plain JSON values, and reading a JSON object back (shared by the
CLI, the studies and the report writers)."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np


def to_jsonable(obj: Any) -> Any:
    """Plain JSON values of nested dicts, lists, numpy arrays and scalars; non-finite floats
    become None (JSON null), paths become strings."""
    if isinstance(obj, dict):
        return {str(k): to_jsonable(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [to_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return to_jsonable(obj.tolist())
    if isinstance(obj, np.bool_):
        return bool(obj)
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, np.floating | float):
        val = float(obj)
        return val if math.isfinite(val) else None
    if isinstance(obj, Path):
        return str(obj)
    return obj


def read_json_object(path: str | Path) -> dict[str, Any] | None:
    """The JSON object (a non-empty dict) in the file ``path``, or None when the file is absent,
    unreadable, not JSON or holds something else. Python's parser also reads the ``NaN`` of
    files written before ``null`` replaced it."""
    try:
        doc = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return doc if isinstance(doc, dict) and doc else None
