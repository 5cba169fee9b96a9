"""Three inner kernels of the local engine, each against an independent reference, in the
numba build and in the pure-Python twin (docs/theory/local_engine.md §4.8, where they were
rewritten for speed):

- ``_btd_matvec`` (column sweeps, the diagonal blocks read as symmetric) against the dense
  product (numpy);
- ``_assemble_H`` (lower triangles, both directions of a pallet in one sweep) against the
  dense ``A + Σ_p P_pᵀ D_p P_p`` with ``D_p`` symmetrised (numpy);
- ``_return_map`` (Newton on ``(Σ d_i²/(σ + κw_i)²)^(−1/2) = 1``) against a bracketing root
  finder on the same scalar equation (``scipy.optimize.brentq``) and against the sub-step's
  own equation ``σ ŝ + κ W ŝ = z`` (eq. 4.2's return map), including equal compliances
  (where the first guess is the root), strongly unequal ones and a stop inside the disc.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from btd_inputs import random_btd
from seisrack.dynamics.local import _btd, _kernel, _pallet


def _numba():
    from seisrack.dynamics.local import _numba

    return _numba


BUILDS = {"python": lambda: (_btd, _kernel, _pallet), "numba": lambda: (_numba(),) * 3}


def _random_btd(sizes, seed):
    A, Ad, Ao, sz, off = random_btd(sizes, seed)
    return A, Ad, Ao, sz, off[:-1].astype(np.int64)


@pytest.mark.parametrize("build", list(BUILDS))
def test_block_product_is_the_dense_product(build):
    btd = BUILDS[build]()[0]
    rng = np.random.default_rng(3)
    A, Ad, Ao, sizes, offsets = _random_btd([3, 7, 5, 1, 6, 4], 3)
    x = rng.standard_normal(A.shape[0])
    x[4] = 0.0  # a zero entry is skipped, not mis-added
    out = rng.standard_normal(A.shape[0])
    want = out - 0.7 * (A @ x)
    btd._btd_matvec(Ad, Ao, sizes, offsets, x, out, -0.7)
    np.testing.assert_allclose(out, want, rtol=0, atol=1e-12 * np.abs(want).max())


@pytest.mark.parametrize("build", list(BUILDS))
@pytest.mark.parametrize("nd", [1, 2])
def test_newton_matrix_is_the_dense_sum(build, nd):
    kernel = BUILDS[build]()[1]
    rng = np.random.default_rng(5)
    sizes_l = [4, 6, 5]
    A, Ad, Ao, sizes, offsets = _random_btd(sizes_l, 5)
    bmax = Ad.shape[1]
    m = 5
    ps = np.array([0, 1, 1, 2, 2], dtype=np.int64)
    P = np.zeros((m, 2, bmax))
    for p in range(m):
        P[p, :nd, :sizes[ps[p]]] = rng.standard_normal((nd, sizes[ps[p]]))
    Dp = rng.standard_normal((m, 4))
    Dp[3] = 0.0  # a pallet with nothing to add
    want = A.copy()
    for p in range(m):
        D = Dp[p].reshape(2, 2)[:nd, :nd]
        Ds = 0.5 * (D + D.T)
        rows = slice(offsets[ps[p]], offsets[ps[p]] + sizes[ps[p]])
        Pp = P[p, :nd, :sizes[ps[p]]]
        want[rows, rows] += Pp.T @ Ds @ Pp
    Hd = np.full_like(Ad, np.nan)  # the upper triangles are not written
    Ho = np.zeros_like(Ao)
    kernel._assemble_H(Ad, Ao, Hd, Ho, sizes, P, ps, Dp, nd)
    for s, b in enumerate(sizes_l):
        blk = want[offsets[s]:offsets[s] + b, offsets[s]:offsets[s] + b]
        np.testing.assert_allclose(np.tril(Hd[s, :b, :b]), np.tril(blk), atol=1e-12)
        if s + 1 < len(sizes_l):
            bn = sizes_l[s + 1]
            np.testing.assert_array_equal(Ho[s, :b, :bn],
                                          want[offsets[s]:offsets[s] + b,
                                               offsets[s + 1]:offsets[s + 1] + bn])


def _cases():
    rng = np.random.default_rng(11)
    out = []
    for ratio in (1.0, 1.0 + 1e-9, 1.3, 10.0, 1e3):
        for _ in range(40):
            m = rng.uniform(200.0, 1000.0)
            wb = 1.0 / m
            wa = wb * ratio
            ang = rng.uniform(0.0, np.pi)
            kap = 0.5 * 1.25e-3 * 0.3 * 9.81 * m * rng.uniform(0.2, 1.0)
            speed = 10.0 ** rng.uniform(-5.0, 0.0)
            th = rng.uniform(0.0, 2.0 * np.pi)
            out.append((speed * np.cos(th), speed * np.sin(th), kap, wa, wb, np.cos(ang),
                        np.sin(ang)))
    return out


@pytest.mark.parametrize("build", list(BUILDS))
def test_return_map_solves_the_sub_step(build):
    pallet = BUILDS[build]()[2]
    slid = stopped = 0
    for zx, zz, kap, wa, wb, ca, sa in _cases():
        sig, ex, ez, slides = pallet._return_map(zx, zz, kap, wa, wb, ca, sa)
        da, db = ca * zx + sa * zz, -sa * zx + ca * zz
        ka, kb = kap * wa, kap * wb
        assert abs(np.hypot(ex, ez) - 1.0) < 1e-13
        if (da / ka) ** 2 + (db / kb) ** 2 <= 1.0:
            assert not slides and sig == 0.0  # it stops inside the sub-step
            stopped += 1
            continue
        slid += 1
        assert slides

        def secular(s, da=da, db=db, ka=ka, kb=kb):
            return (da / (s + ka)) ** 2 + (db / (s + kb)) ** 2 - 1.0

        ref = brentq(secular, 0.0, np.hypot(zx, zz), xtol=1e-300, rtol=1e-15, maxiter=500)
        scale = np.hypot(zx, zz) + ka + kb
        assert abs(sig - ref) <= 4e-15 * scale
        # the sub-step's equation: σ ŝ + κ W ŝ = z with W = R diag(wa, wb) Rᵀ
        w11 = wa * ca * ca + wb * sa * sa
        w12 = (wa - wb) * ca * sa
        w22 = wa * sa * sa + wb * ca * ca
        rx = sig * ex + kap * (w11 * ex + w12 * ez) - zx
        rz = sig * ez + kap * (w12 * ex + w22 * ez) - zz
        assert np.hypot(rx, rz) <= 1e-13 * scale
    assert slid > 100 and stopped > 5  # both branches taken
