"""Backends of the stick–slip kernel: the same source compiled by numba or run by CPython.

``_kernel.py`` (Newmark) and ``_kernel_exact.py`` (exact propagators) are the pure-Python twins;
both take their event detection, location, transitions and output from ``_events.py``, the one
event core every integrator shares. ``_kernel_numba.py`` executes the very same sources with
``_JIT = numba.njit``, so the two backends cannot drift apart (pystrata keeps such a twin to run
the same validation under both). numba is optional; without it the Python backend is used.
"""

from __future__ import annotations

import importlib
import importlib.util
import logging
from types import ModuleType

import numpy as np

from seisrack.errors import InputError

_LOG = logging.getLogger(__name__)


def numba_available() -> bool:
    return importlib.util.find_spec("numba") is not None


def get_kernel(backend: str = "auto", method: str = "newmark") -> ModuleType:
    """Return the kernel module for ``backend`` in {"auto", "numba", "python"}.

    The numba module holds both ``run_kernel`` (Newmark) and ``run_kernel_exact``; the Python
    twins are ``_kernel`` and ``_kernel_exact``.
    """
    if backend == "auto":
        backend = "numba" if numba_available() else "python"
    if backend == "python":
        name = "_kernel_exact" if method == "exact" else "_kernel"
        return importlib.import_module(f"seisrack.dynamics.{name}")
    if backend == "numba":
        if not numba_available():
            raise InputError(
                "backend", backend, '"python" (numba is not installed)',
                hint="Install the 'fast' extra: pip install 'seisrack[fast]'",
            )
        return importlib.import_module("seisrack.dynamics._kernel_numba")
    raise InputError("backend", backend, '"auto", "numba" or "python"')


def scheme_kernel(backend: str, numba_module: str, python_module: str
                  ) -> tuple[ModuleType, str]:
    """(module, backend used) of a scheme whose numba build and pure-Python twin are the
    modules ``numba_module`` and ``python_module`` (dotted names); ``backend`` as for
    :func:`get_kernel`."""
    if backend == "auto":
        backend = "numba" if numba_available() else "python"
    if backend == "numba":
        if not numba_available():
            raise InputError("backend", backend, '"python" (numba is not installed)')
        return importlib.import_module(numba_module), backend
    if backend == "python":
        return importlib.import_module(python_module), backend
    raise InputError("backend", backend, '"auto", "numba" or "python"')


def writable(a: np.ndarray) -> np.ndarray:
    """A C-contiguous, writable float array: numba compiles a separate specialisation for
    read-only arrays (a compiled model's arrays are locked), so the kernel always gets these."""
    a = np.ascontiguousarray(a)
    return a if a.flags.writeable else a.copy()


def writable_all(*arrays: np.ndarray) -> tuple[np.ndarray, ...]:
    """:func:`writable` of each of a kernel's inputs, in one call."""
    return tuple(writable(a) for a in arrays)
