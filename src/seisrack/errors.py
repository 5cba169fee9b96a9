"""Exception hierarchy.

Every error a user can trigger derives from :class:`SeisrackError`. Input problems are
:class:`InputError` (also a ``ValueError``) and carry the offending field, the value received
and what is allowed, so the CLI can print one readable paragraph instead of a traceback.
"""

from __future__ import annotations

from typing import Any


class SeisrackError(Exception):
    """Base class of all seisrack errors."""


class InputError(SeisrackError, ValueError):
    """Bad user input: names the field, the value received and what is allowed."""

    def __init__(
        self,
        field: str,
        value: Any = None,
        allowed: str = "",
        *,
        source: str | None = None,
        hint: str | None = None,
    ) -> None:
        self.field = field
        self.value = value
        self.allowed = allowed
        self.source = source
        self.hint = hint
        where = f"{source}: " if source else ""
        msg = f"{where}invalid value for '{field}': got {value!r}"
        if allowed:
            msg += f"; allowed: {allowed}"
        if hint:
            msg += f". {hint}"
        super().__init__(msg)


class FileFormatError(InputError):
    """A file could not be parsed (reports the line number when known)."""

    def __init__(self, path: str, message: str, line: int | None = None) -> None:
        loc = f"{path}, line {line}" if line is not None else str(path)
        self.path = path
        self.line = line
        SeisrackError.__init__(self, f"{loc}: {message}")
        self.field = "file"
        self.value = path
        self.allowed = ""
        self.source = path
        self.hint = None


class SolverError(SeisrackError, RuntimeError):
    """A numerical procedure failed (reported as a status when ``throw=False``)."""


def require(condition: bool, field: str, value: Any, allowed: str, **kw: Any) -> None:
    """Raise :class:`InputError` unless ``condition`` holds."""
    if not condition:
        raise InputError(field, value, allowed, **kw)
