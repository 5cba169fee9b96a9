"""The design peaks of one chunk of a rack run in one pass over time (issue 21).

For every analysis step the design quantities are ``x = q @ D`` (``D``: the (r, Σk) operators
of :class:`~seisrack.analysis.operators.DesignOps`, side by side); the pass keeps the largest and
smallest value of each, and, per upright section, the (N, M) pair of gravity + seismic at the
first step of the largest |N| and at the first step of the largest |M|. Two builds give the same
numbers up to round-off: a loop compiled by numba (no ``(Σk, n_t)`` array is formed: on this
machine a fresh array costs its page faults, about 1 ms per MB) and a numpy twin used without
numba (``tests/test_design_pass.py`` checks their parity).
"""

from __future__ import annotations

import numpy as np

try:  # optional accelerator; without it the numpy twin runs
    import numba as _numba
except ImportError:  # pragma: no cover - exercised where numba is absent
    _numba = None


def _design_pass_py(q: np.ndarray, dop: np.ndarray, dmax: np.ndarray, dmin: np.ndarray,
                    ia: int, im: int, static_n: np.ndarray, static_m: np.ndarray,
                    at_n: np.ndarray, at_m: np.ndarray) -> None:
    """Loop over the steps of ``q: (n_t, r)``; ``dop: (r, Σk)``; updates ``dmax``, ``dmin``
    (Σk,), ``at_n``, ``at_m`` (2, ns) in place. ``ia``, ``im``: first column of the axial
    forces and of the section moments in ``dop`` (ns columns each); ``static_n``, ``static_m``
    (ns,) their gravity state."""
    n_t, r = q.shape
    nk = dop.shape[1]
    ns = static_n.shape[0]
    x = np.empty(nk)
    for t in range(n_t):
        for j in range(nk):
            x[j] = 0.0
        for i in range(r):
            qi = q[t, i]
            for j in range(nk):
                x[j] += qi * dop[i, j]
        for j in range(nk):
            v = x[j]
            # NaN-propagating, as numpy's max and min
            if v > dmax[j] or v != v:
                if dmax[j] == dmax[j]:
                    dmax[j] = v
            if v < dmin[j] or v != v:
                if dmin[j] == dmin[j]:
                    dmin[j] = v
        for s in range(ns):
            n = x[ia + s] + static_n[s]
            m = x[im + s] + static_m[s]
            # strictly larger: the first step of the largest magnitude wins, as np.argmax
            if abs(n) > abs(at_n[0, s]):
                at_n[0, s] = n
                at_n[1, s] = m
            if abs(m) > abs(at_m[1, s]):
                at_m[0, s] = n
                at_m[1, s] = m


def _design_pass_np(q: np.ndarray, dop: np.ndarray, dmax: np.ndarray, dmin: np.ndarray,
                    ia: int, im: int, static_n: np.ndarray, static_m: np.ndarray,
                    at_n: np.ndarray, at_m: np.ndarray) -> None:
    # (Σk, n_t): the reductions run along contiguous rows
    xt = np.ascontiguousarray(dop.T) @ q.T
    np.maximum(dmax, xt.max(axis=1, initial=-np.inf), out=dmax)
    np.minimum(dmin, xt.min(axis=1, initial=np.inf), out=dmin)
    ns = static_n.shape[0]
    if not (ns and xt.shape[1]):
        return
    n = xt[ia:ia + ns] + static_n[:, None]
    m = xt[im:im + ns] + static_m[:, None]
    rows = np.arange(ns)
    for rows_at, x, c in ((at_n, n, 0), (at_m, m, 1)):
        k = np.argmax(np.abs(x), axis=1)
        better = np.abs(x[rows, k]) > np.abs(rows_at[c])
        rows_at[0, better] = n[rows, k][better]
        rows_at[1, better] = m[rows, k][better]


HAVE_NUMBA = _numba is not None
_design_pass_nb = (_numba.njit(cache=True, error_model="numpy")(_design_pass_py)
                   if HAVE_NUMBA else None)


def design_pass(q: np.ndarray, dop: np.ndarray, dmax: np.ndarray, dmin: np.ndarray,
                ia: int, im: int, static_n: np.ndarray, static_m: np.ndarray,
                at_n: np.ndarray, at_m: np.ndarray, backend: str = "auto") -> None:
    """Accumulate the design peaks of the steps ``q: (n_t, r)`` (see :func:`_design_pass_py`
    for the arguments) with numba when installed (``backend`` "auto"), or "numba" / "numpy"."""
    if backend == "numpy" or (backend == "auto" and not HAVE_NUMBA):
        _design_pass_np(q, dop, dmax, dmin, ia, im, static_n, static_m, at_n, at_m)
        return
    _design_pass_nb(np.ascontiguousarray(q), dop, dmax, dmin, int(ia), int(im), static_n,
                    static_m, at_n, at_m)
