"""Validation of the engine's array inputs (dense or scipy sparse), at the boundary."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from seisrack.errors import InputError


def square(name: str, mat: object, n: int | None):  # noqa: ANN201
    """A finite square matrix, dense ``ndarray`` or CSR; ``n`` fixes its size."""
    if sp.issparse(mat):
        a = sp.csr_matrix(mat, dtype=float)
        data = a.data
    else:
        a = np.asarray(mat, dtype=float)
        if a.ndim == 0 and n == 1:
            a = a.reshape(1, 1)
        data = a
    if a.ndim != 2 or a.shape[0] != a.shape[1]:
        raise InputError(name, f"array of shape {a.shape}", "a square matrix")
    if n is not None and a.shape[0] != n:
        raise InputError(name, f"shape {a.shape}", f"shape ({n}, {n}) like M")
    if not np.all(np.isfinite(data)):
        raise InputError(name, "non-finite entries", "finite numbers")
    return a


def check_symmetric(name: str, a) -> None:  # noqa: ANN001
    if sp.issparse(a) and a.shape[0] <= 300:  # small: dense is exact and ~50x faster
        a = a.toarray()
    scale = max(float(abs(a).max()) if a.shape[0] else 0.0, 1e-300)
    if sp.issparse(a):
        asym = float(abs(a - a.T).max()) if a.nnz else 0.0
        ok = asym <= 1e-10 * scale
    else:
        ok = np.allclose(a, a.T, rtol=1e-10, atol=1e-12 * scale)
    if not ok:
        raise InputError(name, "non-symmetric matrix", "a symmetric matrix")


def series(name: str, val: object, shape: tuple[int, ...]) -> np.ndarray:
    a = np.asarray(val, dtype=float)
    if a.shape != shape:
        raise InputError(name, f"array of shape {a.shape}", f"shape {shape}")
    if not np.all(np.isfinite(a)):
        bad = int(np.argmax(~np.isfinite(a.ravel())))
        raise InputError(name, f"non-finite value at flat index {bad}", "finite numbers")
    return a


def positive_int(name: str, value: object) -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < 1:
        raise InputError(name, value, "an integer >= 1")
    return int(value)


def writable(a: np.ndarray) -> np.ndarray:
    """A C-contiguous, writable float array: numba compiles a separate specialisation for
    read-only arrays (a compiled model's arrays are locked), so the kernel always gets these."""
    a = np.ascontiguousarray(a)
    return a if a.flags.writeable else a.copy()
