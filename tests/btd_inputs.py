"""A random symmetric positive definite block-tridiagonal matrix, dense and in the local
engine's block storage (``dynamics/local/_btd.py``), for the tests of its block algebra."""

from __future__ import annotations

import numpy as np


def random_btd(sizes, seed=0):
    """(A dense, Hd, Ho, sizes, offsets with the total last) for blocks of ``sizes``."""
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
