"""Block-tridiagonal algebra of the local engine (``dynamics/local/_btd.py``).

Reference: the dense inverse of the same matrix (numpy). The pallets' compliance
``G = P (H⁻¹)_ss Pᵀ`` (docs/theory/local_engine.md §4.1) needs the diagonal blocks of the
inverse, i.e. slice s's block with the slices on both sides condensed, not only those on its
left (the forward factor's ``L_ss L_ssᵀ``, which holds the right side fixed: on the 10-bay
example that under-estimated a pallet's down-aisle compliance by factors 1.5 to 9).
"""

from __future__ import annotations

import numpy as np
import pytest

from seisrack.dynamics.local import _btd


def _random_btd(sizes, seed=0):
    rng = np.random.default_rng(seed)
    ns, bmax = len(sizes), max(sizes)
    off = np.concatenate([[0], np.cumsum(sizes)])
    n = off[-1]
    B = rng.standard_normal((n, n))
    # a block-tridiagonal SPD matrix: mask a random one to the block pattern, then shift
    mask = np.zeros((n, n), dtype=bool)
    for s in range(ns):
        lo = off[max(s - 1, 0)]
        hi = off[min(s + 2, ns)]
        mask[off[s]:off[s + 1], lo:hi] = True
    A = np.where(mask, B + B.T, 0.0)
    A += (np.abs(A).sum(axis=1).max() + 1.0) * np.eye(n)
    Hd = np.zeros((ns, bmax, bmax))
    Ho = np.zeros((max(ns - 1, 1), bmax, bmax))
    for s in range(ns):
        b = sizes[s]
        Hd[s, :b, :b] = A[off[s]:off[s + 1], off[s]:off[s + 1]]
        if s + 1 < ns:
            Ho[s, :b, :sizes[s + 1]] = A[off[s]:off[s + 1], off[s + 1]:off[s + 2]]
    return A, Hd, Ho, np.asarray(sizes, dtype=np.int64), off


@pytest.mark.parametrize("sizes", [[3, 5, 2, 4, 4], [6], [2, 7]])
def test_condensed_blocks_are_the_inverse_diagonal_blocks(sizes):
    A, Hd, Ho, sz, off = _random_btd(sizes)
    Ld, X = np.zeros_like(Hd), np.zeros_like(Ho)
    Rb, Yb, Le = np.zeros_like(Hd), np.zeros_like(Hd), np.zeros_like(Hd)
    assert _btd._btd_factor(Hd, Ho, sz, Ld, X)
    assert _btd._btd_condensed(Hd, Ho, sz, X, Rb, Yb, Le)
    Ai = np.linalg.inv(A)
    for s, b in enumerate(sizes):
        L = np.tril(Le[s, :b, :b])
        ref = Ai[off[s]:off[s + 1], off[s]:off[s + 1]]
        assert np.allclose(np.linalg.inv(L @ L.T), ref, rtol=1e-10, atol=1e-14)
    # the forward factor's own block differs wherever the slice has a right neighbour
    L0 = np.tril(Ld[0, :sizes[0], :sizes[0]])
    if len(sizes) > 1:
        assert not np.allclose(np.linalg.inv(L0 @ L0.T), Ai[:sizes[0], :sizes[0]])


def test_condensed_refuses_an_indefinite_matrix():
    A, Hd, Ho, sz, off = _random_btd([3, 3, 3], seed=1)
    Hd[1] -= 1e3 * np.eye(Hd.shape[1])
    Ld, X = np.zeros_like(Hd), np.zeros_like(Ho)
    _btd._btd_factor(Hd, Ho, sz, Ld, X)
    assert not _btd._btd_condensed(Hd, Ho, sz, X, np.zeros_like(Hd), np.zeros_like(Hd),
                                   np.zeros_like(Hd))
