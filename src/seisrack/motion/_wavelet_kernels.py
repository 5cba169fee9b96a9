"""Compiled kernels of the time-domain wavelet stage of :mod:`seisrack.motion.synth`.

Each kernel has a ``_py`` version (compiled by numba when installed) and a numpy twin ``_np``
used without numba; ``tests/test_motion_synth.py`` checks their parity. See synth.py for the
method (Lilhanand & Tseng 1988; Al Atik & Abrahamson 2010).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import NamedTuple

import numpy as np

try:  # optional accelerator; without it the numpy twins run
    import numba as _numba
    from numba import prange
except ImportError:  # pragma: no cover - exercised where numba is absent
    _numba = None
    prange = range


def _responses_py(p: np.ndarray, coef: np.ndarray, out: np.ndarray) -> None:
    """out (n_osc, length): u of each oscillator at samples 0… under p (n,), then p = 0; p_0 = 0."""
    n = p.shape[0]
    nosc = coef.shape[1]
    a11, a12, a21, a22 = coef[0], coef[1], coef[2], coef[3]
    b10, b11, b20, b21 = coef[4], coef[5], coef[6], coef[7]
    # oscillators are independent: one recurrence per oscillator, spread over the cores
    for i in prange(nosc):
        ui = 0.0
        vi = 0.0
        out[i, 0] = 0.0
        for k in range(out.shape[1] - 1):
            p0 = p[k] if k < n else 0.0
            p1 = p[k + 1] if k + 1 < n else 0.0
            u1 = a11[i] * ui + a12[i] * vi + b10[i] * p0 + b11[i] * p1
            vi = a21[i] * ui + a22[i] * vi + b20[i] * p0 + b21[i] * p1
            ui = u1
            out[i, k + 1] = u1


def _responses_np(p: np.ndarray, coef: np.ndarray, out: np.ndarray) -> None:
    a11, a12, a21, a22, b10, b11, b20, b21 = coef
    pp = np.zeros(out.shape[1])
    pp[: p.size] = p
    u = np.zeros(coef.shape[1])
    v = np.zeros(coef.shape[1])
    out[:, 0] = 0.0
    for k in range(out.shape[1] - 1):
        u, v = (a11 * u + a12 * v + b10 * pp[k] + b11 * pp[k + 1],
                a21 * u + a22 * v + b20 * pp[k] + b21 * pp[k + 1])
        out[:, k + 1] = u


def _peaks_py(u: np.ndarray, m_end: np.ndarray, half: np.ndarray, out: np.ndarray) -> None:
    """out (n_osc, n_peaks): sample of the largest |u[i, :m_end_i + 1]|, then of the largest
    outside ±half_i of those already found (0 when none is left)."""
    au = np.empty(u.shape[1])
    for i in range(u.shape[0]):
        me = m_end[i]
        for m in range(me + 1):
            au[m] = abs(u[i, m])
        for q in range(out.shape[1]):
            best = 0
            bv = au[0]
            for m in range(1, me + 1):
                if au[m] > bv:
                    bv = au[m]
                    best = m
            out[i, q] = best
            for m in range(max(best - half[i], 0), min(best + half[i], me) + 1):
                au[m] = 0.0


def _peaks_np(u: np.ndarray, m_end: np.ndarray, half: np.ndarray, out: np.ndarray) -> None:
    au = np.abs(u[:, : m_end.max() + 1])
    for row, me in enumerate(m_end):
        au[row, me + 1:] = 0.0
    for q in range(out.shape[1]):
        out[:, q] = np.argmax(au, axis=1)
        for row, (mr, h) in enumerate(zip(out[:, q], half, strict=True)):
            au[row, max(mr - h, 0): mr + h + 1] = 0.0


def _wavelets_py(
    Gwr: np.ndarray, lw: np.ndarray, osc: np.ndarray, mpk: np.ndarray, taper: np.ndarray,
    project: np.ndarray, F: np.ndarray, fs: np.ndarray, fe: np.ndarray, cF: np.ndarray,
) -> None:
    """Wavelet j (oscillator osc_j, peak at sample mpk_j) into F[j, fs_j:fe_j + 1] (F zero
    elsewhere), and its baseline coefficients ``cF[:, j] = project @ F[j]``."""
    L = Gwr.shape[1]
    n = F.shape[1]
    for j in range(osc.shape[0]):
        i = osc[j]
        m = mpk[j]
        s = max(0, m - lw[i] + 1)
        e = min(m, n - 1)
        fs[j] = s
        fe[j] = e
        c0 = 0.0
        c1 = 0.0
        for k in range(s, e + 1):
            f = Gwr[i, L - 1 - m + k] * taper[k]
            F[j, k] = f
            c0 += project[0, k] * f
            c1 += project[1, k] * f
        cF[0, j] = c0
        cF[1, j] = c1


def _wavelets_np(
    Gwr: np.ndarray, lw: np.ndarray, osc: np.ndarray, mpk: np.ndarray, taper: np.ndarray,
    project: np.ndarray, F: np.ndarray, fs: np.ndarray, fe: np.ndarray, cF: np.ndarray,
) -> None:
    L = Gwr.shape[1]
    fs[:] = np.maximum(0, mpk - lw[osc] + 1)
    fe[:] = np.minimum(mpk, F.shape[1] - 1)
    for j, (i, m, s, e) in enumerate(zip(osc, mpk, fs, fe, strict=True)):
        F[j, s:e + 1] = Gwr[i, L - 1 - m + s: L - m + e] * taper[s:e + 1]
    cF[:] = project @ F.T


def _dots_py(
    Gr: np.ndarray, lg: np.ndarray, F: np.ndarray, fs: np.ndarray, fe: np.ndarray,
    osc: np.ndarray, m: np.ndarray, out: np.ndarray,
) -> None:
    """out[r, j] = Σ_k G_{osc_r}[m_r - k] F[j, k]: oscillator osc_r's u at sample m_r under
    wavelet j (zero when the wavelet starts after m_r; G_i is zero from lg_i on)."""
    L = Gr.shape[1]
    for r in prange(osc.shape[0]):  # rows are independent: spread over the cores
        g = Gr[osc[r]]
        off = L - 1 - m[r]
        k0 = m[r] - lg[osc[r]] + 1
        for j in range(fs.shape[0]):
            lo = max(fs[j], k0)
            hi = min(fe[j], m[r])
            s = 0.0
            if hi >= lo:  # contiguous slices: the loop compiles to SIMD
                gs = g[off + lo: off + hi + 1]
                f = F[j, lo: hi + 1]
                for t in range(gs.shape[0]):
                    s += gs[t] * f[t]
            out[r, j] = s


def _dots_np(
    Gr: np.ndarray, lg: np.ndarray, F: np.ndarray, fs: np.ndarray, fe: np.ndarray,
    osc: np.ndarray, m: np.ndarray, out: np.ndarray,
) -> None:
    L, n = Gr.shape[1], F.shape[1]
    W = np.zeros((osc.size, n))
    for row, (i, mr) in enumerate(zip(osc, m, strict=True)):
        j = min(int(mr), n - 1)
        W[row, : j + 1] = Gr[i, L - 1 - mr: L - mr + j]
    out[:] = W @ F.T


def _lsq_py(A: np.ndarray, rhs: np.ndarray, ridge: float, out: np.ndarray) -> None:
    """out = (AᵀA + ridge I)⁻¹ Aᵀ rhs: normal equations, Cholesky AᵀA + ridge I = UᵀU."""
    R, K = A.shape
    N = np.zeros((K, K))
    y = np.zeros(K)
    At = np.ascontiguousarray(A.T)
    for i in range(K):  # AᵀA and Aᵀ rhs: contiguous dot products (SIMD)
        ai = At[i]
        s = 0.0
        for r in range(R):
            s += ai[r] * rhs[r]
        y[i] = s
        for j in range(i, K):
            aj = At[j]
            s = 0.0
            for r in range(R):
                s += ai[r] * aj[r]
            N[i, j] = s
    for i in range(K):
        N[i, i] += ridge
    for j in range(K):  # right-looking Cholesky on the upper triangle
        d = math.sqrt(N[j, j])
        for i in range(j, K):
            N[j, i] /= d
        for i in range(j + 1, K):
            nji = N[j, i]
            Ni = N[i, i:]
            Nj = N[j, i:]
            for l2 in range(Ni.shape[0]):
                Ni[l2] -= nji * Nj[l2]
    for k in range(K):  # Uᵀ z = y
        y[k] /= N[k, k]
        for i in range(k + 1, K):
            y[i] -= N[k, i] * y[k]
    for i in range(K - 1, -1, -1):  # U x = z
        s = y[i]
        for l2 in range(i + 1, K):
            s -= N[i, l2] * out[l2]
        out[i] = s / N[i, i]


def _lsq_np(A: np.ndarray, rhs: np.ndarray, ridge: float, out: np.ndarray) -> None:
    out[:] = np.linalg.solve(A.T @ A + ridge * np.eye(A.shape[1]), A.T @ rhs)


def _add_py(
    a: np.ndarray, F: np.ndarray, fs: np.ndarray, fe: np.ndarray, c: np.ndarray,
    basis: np.ndarray, cF: np.ndarray, out: np.ndarray,
) -> None:
    """out = a + Σ_j c_j (F_j - cF_j · basis): the baseline-corrected wavelets added."""
    g0 = 0.0
    g1 = 0.0
    out[:] = a
    for j in range(fs.shape[0]):
        cj = c[j]
        g0 += cj * cF[0, j]
        g1 += cj * cF[1, j]
        for k in range(fs[j], fe[j] + 1):
            out[k] += cj * F[j, k]
    for k in range(out.shape[0]):
        out[k] -= g0 * basis[0, k] + g1 * basis[1, k]


def _add_np(
    a: np.ndarray, F: np.ndarray, fs: np.ndarray, fe: np.ndarray, c: np.ndarray,
    basis: np.ndarray, cF: np.ndarray, out: np.ndarray,
) -> None:
    out[:] = a + c @ F - (cF @ c) @ basis


class _Ops(NamedTuple):
    responses: Callable[..., None]
    peaks: Callable[..., None]
    wavelets: Callable[..., None]
    dots: Callable[..., None]
    lsq: Callable[..., None]
    add: Callable[..., None]


OPS_NUMPY = _Ops(_responses_np, _peaks_np, _wavelets_np, _dots_np, _lsq_np, _add_np)
if _numba is not None:
    _jit = _numba.njit(cache=True)
    OPS_NUMBA: _Ops | None = _Ops(
        _numba.njit(cache=True, parallel=True)(_responses_py), _jit(_peaks_py),
        _jit(_wavelets_py),
        # the two kernels whose sums are left to the compiler to order (SIMD dot products)
        _numba.njit(cache=True, parallel=True, fastmath={"reassoc", "contract", "nsz"})(
            _dots_py
        ),
        _numba.njit(cache=True, fastmath={"reassoc", "contract", "nsz"})(_lsq_py),
        _jit(_add_py),
    )
else:  # pragma: no cover
    OPS_NUMBA = None
