"""numba-compiled build of ``_events.py``, ``_linalg.py``, ``_kernel.py``, ``_exact_modes.py``,
``_exact_config.py`` and ``_kernel_exact.py`` (the same sources, executed in this order with
``_JIT = njit`` in one namespace)."""

from pathlib import Path

import numba

_JIT = numba.njit(cache=True)
for _name in ("_events.py", "_linalg.py", "_kernel.py", "_exact_modes.py",
              "_exact_config.py", "_kernel_exact.py"):
    _SRC = Path(__file__).with_name(_name)
    exec(compile(_SRC.read_text(encoding="utf-8"), str(_SRC), "exec"))  # noqa: S102
