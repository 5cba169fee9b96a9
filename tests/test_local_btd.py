"""Block-tridiagonal algebra of the local engine (``dynamics/local/_btd.py``).

Reference: the dense inverse of the same matrix (numpy), for the numba build and the
pure-Python twin. The pallets' compliance
``G = P (H⁻¹)_ss Pᵀ`` (docs/theory/local_engine.md §4.1) needs the diagonal blocks of the
inverse, i.e. slice s's block with the slices on both sides condensed, not only those on its
left (the forward factor's ``L_ss L_ssᵀ``, which holds the right side fixed: on the 10-bay
example that under-estimated a pallet's down-aisle compliance by factors 1.5 to 9).
"""

from __future__ import annotations

import numpy as np
import pytest

from btd_inputs import random_btd as _random_btd
from seisrack.dynamics.local import _btd


def _build(name):
    if name == "numba":
        from seisrack.dynamics.local import _numba

        return _numba
    return _btd


@pytest.mark.parametrize("build", ["python", "numba"])
@pytest.mark.parametrize("sizes", [[3, 5, 2, 4, 4], [6], [2, 7]])
def test_condensed_blocks_are_the_inverse_diagonal_blocks(sizes, build):
    btd = _build(build)
    A, Hd, Ho, sz, off = _random_btd(sizes)
    Ld, X = np.zeros_like(Hd), np.zeros_like(Ho)
    Rb, Yb, Le = np.zeros_like(Hd), np.zeros_like(Hd), np.zeros_like(Hd)
    assert btd._btd_factor(Hd, Ho, sz, Ld, X)
    assert btd._btd_condensed(Hd, Ho, sz, X, Rb, Yb, Le)
    Ai = np.linalg.inv(A)
    for s, b in enumerate(sizes):
        L = np.tril(Le[s, :b, :b])
        ref = Ai[off[s]:off[s + 1], off[s]:off[s + 1]]
        assert np.allclose(np.linalg.inv(L @ L.T), ref, rtol=1e-10, atol=1e-14)
    # the forward factor's own block differs wherever the slice has a right neighbour
    L0 = np.tril(Ld[0, :sizes[0], :sizes[0]])
    if len(sizes) > 1:
        assert not np.allclose(np.linalg.inv(L0 @ L0.T), Ai[:sizes[0], :sizes[0]])


@pytest.mark.parametrize("build", ["python", "numba"])
def test_condensed_refuses_an_indefinite_matrix(build):
    btd = _build(build)
    A, Hd, Ho, sz, off = _random_btd([3, 3, 3], seed=1)
    Hd[1] -= 1e3 * np.eye(Hd.shape[1])
    Ld, X = np.zeros_like(Hd), np.zeros_like(Ho)
    btd._btd_factor(Hd, Ho, sz, Ld, X)
    assert not btd._btd_condensed(Hd, Ho, sz, X, np.zeros_like(Hd), np.zeros_like(Hd),
                                   np.zeros_like(Hd))
