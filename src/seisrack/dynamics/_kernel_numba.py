"""numba-compiled build of ``_kernel.py`` (the same source, executed with ``_JIT = njit``)."""

from pathlib import Path

import numba

_JIT = numba.njit(cache=True)
_SRC = Path(__file__).with_name("_kernel.py")
exec(compile(_SRC.read_text(encoding="utf-8"), str(_SRC), "exec"))  # noqa: S102
