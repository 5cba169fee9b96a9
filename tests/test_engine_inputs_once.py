"""The engine's inputs are checked at the boundary, once per locked matrix (issue 21): a
compiled model's read-only M, C, K pass the square / finite / symmetric checks on their first
run and are not checked again; a writable matrix is checked on every run, so a matrix edited
in place between two runs is still refused. Nested one-BLAS-thread contexts set the limit
once and restore it on leaving the outermost."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from threadpoolctl import threadpool_info

from seisrack.dynamics import _blas
from seisrack.dynamics import _inputs as chk
from seisrack.errors import InputError


def _locked_csr(a: np.ndarray) -> sp.csr_matrix:
    m = sp.csr_matrix(a)
    for part in (m.data, m.indices, m.indptr):
        part.flags.writeable = False
    return m


def test_locked_matrix_is_checked_once(monkeypatch: pytest.MonkeyPatch) -> None:
    k = _locked_csr(np.array([[2.0, -1.0], [-1.0, 1.0]]))
    calls = []
    real = chk.check_symmetric
    monkeypatch.setattr(chk, "check_symmetric", lambda n, a: (calls.append(n), real(n, a)))
    first = chk.checked_square("K", k, 2)
    chk.checked_symmetric("K", k, first)
    again = chk.checked_square("K", k, 2)
    chk.checked_symmetric("K", k, again)
    assert again is first and calls == ["K"]
    with pytest.raises(InputError, match="like M"):  # the size is still compared with M's
        chk.checked_square("K", k, 3)


def test_writable_matrix_is_checked_every_time() -> None:
    k = np.array([[2.0, -1.0], [-1.0, 1.0]])
    chk.checked_symmetric("K", k, chk.checked_square("K", k, 2))
    k[0, 1] = 5.0  # edited in place: no longer symmetric
    with pytest.raises(InputError, match="symmetric"):
        chk.checked_symmetric("K", k, chk.checked_square("K", k, 2))
    k[0, 1] = np.nan
    with pytest.raises(InputError, match="finite"):
        chk.checked_square("K", k, 2)


def test_locked_nonsymmetric_matrix_is_refused_every_time() -> None:
    k = _locked_csr(np.array([[2.0, -1.0], [0.0, 1.0]]))
    for _ in range(2):
        with pytest.raises(InputError, match="symmetric"):
            chk.checked_symmetric("K", k, chk.checked_square("K", k, 2))


def test_entry_goes_with_its_matrix() -> None:
    k = _locked_csr(np.eye(3))
    chk.checked_square("K", k, 3)
    key = id(k)
    assert key in chk._CHECKED
    del k
    assert key not in chk._CHECKED


def _blas_threads() -> list[int]:
    return [i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"]


def test_nested_one_blas_thread_restores_on_leaving_the_outermost() -> None:
    before = _blas_threads()
    with _blas.one_blas_thread():
        assert all(n == 1 for n in _blas_threads())
        with _blas.one_blas_thread():
            assert all(n == 1 for n in _blas_threads())
        assert all(n == 1 for n in _blas_threads())  # the inner context did not restore
    assert _blas_threads() == before
