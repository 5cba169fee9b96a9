"""The planar kernel's in-place Cholesky factorisation (``_lapack.py``): LAPACK
``dpotrf`` and BLAS ``dsyrk`` called from compiled code, and the numpy twins of the pure-Python
backend. Reference: numpy's ``cholesky`` and ``G.T @ G`` (LAPACK / BLAS through numpy, an
independent call path), on the lower triangle; the strict upper triangle must stay as it was.
"""

from __future__ import annotations

import numpy as np
import pytest

from seisrack.dynamics import _lapack as twin


def _backends():
    from seisrack.dynamics import _planar_numba as compiled

    return [pytest.param(compiled, id="numba"), pytest.param(twin, id="python")]


def _spd(r: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    B = rng.standard_normal((r, r))
    return B @ B.T + r * np.eye(r)


@pytest.mark.parametrize("mod", _backends())
@pytest.mark.parametrize("r", [1, 7, 101])
def test_syrk_then_cholesky_equals_numpy(mod, r):
    rng = np.random.default_rng(r)
    A0 = _spd(r, r)
    G = rng.standard_normal((2 * r + 3, r))
    ng = r + 2  # only the first ng rows of G count
    A = A0.copy()
    A[np.triu_indices(r, 1)] = 7.0  # the strict upper triangle is never read nor written
    mod._syrk_lower(A, G, ng)
    assert mod._chol(A)
    L = np.linalg.cholesky(A0 + G[:ng].T @ G[:ng])
    low = np.tril_indices(r)
    assert np.abs(A[low] - L[low]).max() <= 1e-12 * np.abs(L).max()
    assert np.all(A[np.triu_indices(r, 1)] == 7.0)


@pytest.mark.parametrize("mod", _backends())
def test_no_rows_adds_nothing(mod):
    A = _spd(5, 1)
    before = A.copy()
    mod._syrk_lower(A, np.ones((4, 5)), 0)
    assert np.array_equal(A, before)


@pytest.mark.parametrize("mod", _backends())
@pytest.mark.parametrize(("i", "k", "value"), [
    (3, 3, -1.0),  # indefinite
    (2, 2, np.nan), (4, 1, np.nan), (5, 0, np.nan),  # on and below the diagonal
    (2, 2, np.inf), (4, 1, np.inf),
])
def test_not_positive_definite_is_reported(mod, i, k, value):
    A = _spd(6, 2)
    A[i, k] = value
    assert not mod._chol(A)
