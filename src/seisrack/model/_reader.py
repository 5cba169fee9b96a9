"""Typed, path-aware access to a parsed TOML table, for validation at the boundary.

A :class:`Table` wraps one TOML table with its dotted path (``pallets[2]``). Each getter checks
presence, type and finiteness and raises :class:`~seisrack.errors.InputError` naming the full
field path, the value received and what is allowed. :meth:`Table.finish` reports unknown keys.
:func:`check_number` and :func:`check_friction` validate single values outside a table.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from seisrack.errors import InputError

_MISSING = object()


def _type_name(value: Any) -> str:
    return {bool: "boolean", int: "integer", float: "number", str: "string", list: "array",
            dict: "table"}.get(type(value), type(value).__name__)


class Table:
    """A TOML table being read, remembering which keys were consumed."""

    def __init__(self, data: Any, path: str, source: str | None) -> None:
        if not isinstance(data, Mapping):
            raise InputError(path or "<root>", data, "a TOML table", source=source)
        self.data = data
        self.path = path
        self.source = source
        self._used: set[str] = set()

    def field(self, key: str) -> str:
        return f"{self.path}.{key}" if self.path else key

    def error(self, key: str, value: Any, allowed: str, hint: str | None = None) -> InputError:
        return InputError(self.field(key), value, allowed, source=self.source, hint=hint)

    def has(self, key: str) -> bool:
        return key in self.data

    def raw(self, key: str, default: Any = _MISSING) -> Any:
        self._used.add(key)
        if key not in self.data:
            if default is _MISSING:
                raise InputError(
                    self.field(key), None, "a value (this key is required)", source=self.source,
                    hint=f"Add '{key}' to {self.path or 'the top level of the file'}",
                )
            return default
        return self.data[key]

    def table(self, key: str, default: Any = _MISSING) -> Table:
        value = self.raw(key, default)
        return Table(value, self.field(key), self.source)

    def number(self, key: str, default: Any = _MISSING, *, positive: bool = False,
               nonnegative: bool = False, unit: str = "") -> float:
        value = self.raw(key, default)
        return check_number(value, self.field(key), positive=positive, nonnegative=nonnegative,
                            unit=unit, source=self.source)

    def integer(self, key: str, default: Any = _MISSING, *, minimum: int | None = None) -> int:
        value = self.raw(key, default)
        allowed = "an integer" + (f" >= {minimum}" if minimum is not None else "")
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.error(key, value, allowed + f" (got a {_type_name(value)})")
        if minimum is not None and value < minimum:
            raise self.error(key, value, allowed)
        return int(value)

    def string(self, key: str, default: Any = _MISSING) -> str:
        value = self.raw(key, default)
        if not isinstance(value, str):
            raise self.error(key, value, f"a string (got a {_type_name(value)})")
        return value

    def array(self, key: str, default: Any = _MISSING, *, min_len: int = 0) -> list[Any]:
        value = self.raw(key, default)
        if not isinstance(value, list):
            raise self.error(key, value, f"an array (got a {_type_name(value)})")
        if len(value) < min_len:
            raise self.error(key, value, f"an array with at least {min_len} element(s)")
        return value

    def finish(self, allowed_keys: tuple[str, ...] | None = None) -> None:
        """Raise on the first key that was never read (an unknown key)."""
        for key in self.data:
            if key not in self._used:
                known = ", ".join(sorted(allowed_keys or tuple(self._used))) or "none"
                raise InputError(self.field(key), self.data[key], f"known keys: {known}",
                                 source=self.source, hint="Check the spelling of the key")


def check_number(value: Any, field: str, *, positive: bool = False, nonnegative: bool = False,
                 unit: str = "", source: str | None = None) -> float:
    """Validate one real number (int or float, not bool, finite) and return it as float."""
    what = "a finite number"
    if positive:
        what = "a finite number > 0"
    elif nonnegative:
        what = "a finite number >= 0"
    if unit:
        what += f" [{unit}]"
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise InputError(field, value, f"{what} (got a {_type_name(value)})", source=source)
    x = float(value)
    if not math.isfinite(x):
        raise InputError(field, value, what, source=source)
    if positive and not x > 0.0:
        raise InputError(field, value, what, source=source)
    if nonnegative and not x >= 0.0:
        raise InputError(field, value, what, source=source)
    return x


def check_friction(f_static: str, mu_s: Any, f_dynamic: str, mu_d: Any,
                   source: str | None = None) -> tuple[float, float]:
    """Validate a (static, dynamic) friction pair: both >= 0 and dynamic <= static."""
    s = check_number(mu_s, f_static, nonnegative=True, source=source)
    k = check_number(mu_d, f_dynamic, nonnegative=True, source=source)
    if k > s:
        raise InputError(f_dynamic, mu_d, f"a value <= {f_static} ({s:g})", source=source,
                         hint="The dynamic friction coefficient cannot exceed the static one")
    return s, k
