"""Small helpers shared by the CLI sub-commands."""

from __future__ import annotations

import json
import sys
from typing import Any

from seisrack.jsonable import to_jsonable as _to_jsonable


def print_json(obj: Any) -> None:
    """Print one JSON object on stdout (non-finite floats become null)."""
    json.dump(_to_jsonable(obj), sys.stdout, indent=2, allow_nan=False)
    sys.stdout.write("\n")


def float_list(text: str) -> list[float]:
    """Parse ``"0.1,0.2,0.5"`` into floats (used as an argparse ``type``)."""
    import argparse

    try:
        vals = [float(t) for t in text.split(",") if t.strip()]
    except ValueError as exc:
        raise argparse.ArgumentTypeError(f"expected comma-separated numbers, got {text!r}") from exc
    if not vals:
        raise argparse.ArgumentTypeError("expected at least one number")
    return vals


def error_object(exc: BaseException | None = None, *, message: str | None = None,
                 field: str | None = None, value: Any = None, allowed: str | None = None
                 ) -> dict[str, Any]:
    """``{"error": {"field", "value", "allowed", "message"}}`` for ``--json`` (issue #14).

    From an :class:`~seisrack.errors.InputError` the fields are its own; other errors give
    ``null`` for what they do not know. ``value`` is made JSON-able (``repr`` as a last resort).
    """
    if exc is not None:
        field = getattr(exc, "field", field)
        value = getattr(exc, "value", value)
        allowed = getattr(exc, "allowed", allowed) or allowed
        message = message or str(exc)
    val = _to_jsonable(value)
    try:
        json.dumps(val, allow_nan=False)
    except (TypeError, ValueError):
        val = repr(value)
    return {"error": {"field": field, "value": val, "allowed": allowed or None,
                      "message": message or ""}}


def print_json_error(obj: dict[str, Any]) -> None:
    """Print the JSON error object on stdout (the exit code is the caller's: 2)."""
    json.dump(obj, sys.stdout, indent=2, allow_nan=False)
    sys.stdout.write("\n")
