"""The level and pallet peaks of one chunk of a rack run in one pass over its steps (issue 21),
compiled by numba; :class:`~seisrack.analysis.peaks.PeakTracker` keeps its numpy code as the
twin used without numba (``tests/test_chunk_pass.py`` checks their parity).

Per step the rack quantities are small products with the basis coordinates (operators of
:class:`~seisrack.analysis.operators.RackOperators`, side by side in one ``(r, K)`` matrix per
coordinate): level displacement, velocity and acceleration, base shear ``K (u + a1 v)``, upright
base moments and the connection moment (the larger in magnitude of the two upright ends, as
:func:`~seisrack.analysis.peaks.connection_moment`). The numpy path forms each as an
``(n_t, k)`` array and reduces it; here nothing of that size is formed except what the caller
keeps: the absolute level accelerations (for the filtered peak) and, when every step is kept,
the histories the response reports (so they are not formed a second time).
"""

from __future__ import annotations

import numpy as np

try:  # optional accelerator; without it PeakTracker's numpy path runs
    import numba as _numba
except ImportError:  # pragma: no cover - exercised where numba is absent
    _numba = None

HAVE_NUMBA = _numba is not None


def _amax(cur: float, v: float) -> float:
    """max(cur, v), NaN-propagating as ``np.maximum``."""
    if cur != cur:
        return cur
    if v > cur or v != v:
        return v
    return cur


def _amin(cur: float, v: float) -> float:
    """min(cur, v), NaN-propagating as ``np.minimum``."""
    if cur != cur:
        return cur
    if v < cur or v != v:
        return v
    return cur


def _level_pass_py(q, qd, qdd, ag, wq, wd, wa, nl, nu, a1, smooth, h,  # noqa: ANN001, C901, PLR0912, PLR0913, PLR0915
                   v_prev, has_prev, disp, acc, acc_mag, shear, m_base, m_conn,
                   a_out, row0, vbuf, series, disp_s, accraw_s, shear_s, base_s, conn_s):
    """One chunk: ``q, qd, qdd (k, r)``, ``ag (k, nd)``; ``wq (nd·nl + nd + nd·nu +
    2 nd·nu·nl, r)`` = [level | shear | base moment | below | above] (rows: transposed
    operators), each direction after the other; ``wd (nd·nl + nd, r)`` = [level | shear];
    ``wa (nd·nl, r)`` = level. Updates the
    peaks ``disp, acc (nl, nd)``, ``acc_mag (nl)``, ``shear, m_base, m_conn (nd)``; writes the
    absolute level accelerations into ``a_out[row0 + t]`` (nl, nd) and, with ``series``, the
    histories ``disp_s, accraw_s (·, nl, nd)``, ``shear_s (·, nd)``, ``base_s (·, nu, nd)``,
    ``conn_s (·, nu, nl, nd)`` at the same rows. ``smooth``: central-difference accelerations
    from the level velocities (``vbuf (k, nd·nl)`` scratch), ``v_prev`` the velocities of the
    step before the chunk when ``has_prev``; on return ``v_prev`` holds those of the chunk's
    last step but one. Returns whether it did (a chunk of at least two steps)."""
    k, r = q.shape
    nd = ag.shape[1]
    nlev = nd * nl
    o_s = nlev
    o_b = o_s + nd
    o_be = o_b + nd * nu
    o_ab = o_be + nd * nu * nl
    kq = wq.shape[0]
    xq = np.empty(kq)
    xd = np.empty(wd.shape[0])
    xa = np.empty(nlev)
    for t in range(k):
        # one scalar sum per quantity, over the basis in order (a register, not memory)
        for j in range(kq):
            acc_j = 0.0
            for i in range(r):
                acc_j += q[t, i] * wq[j, i]
            xq[j] = acc_j
        for j in range(xd.shape[0]):
            acc_j = 0.0
            for i in range(r):
                acc_j += qd[t, i] * wd[j, i]
            xd[j] = acc_j
        for j in range(nlev):
            acc_j = 0.0
            for i in range(r):
                acc_j += qdd[t, i] * wa[j, i]
            xa[j] = acc_j
        row = row0 + t
        for d in range(nd):
            for lv in range(nl):
                c = d * nl + lv
                disp[lv, d] = _amax(disp[lv, d], abs(xq[c]))
                a_out[row, lv, d] = xa[c]  # relative, made absolute below
                if smooth:
                    vbuf[t, c] = xd[c]
                if series:
                    disp_s[row, lv, d] = xq[c]
                    accraw_s[row, lv, d] = xa[c] + ag[t, d]
            sh = xq[o_s + d] + a1 * xd[nlev + d]
            shear[d] = _amax(shear[d], abs(sh))
            for u in range(nu):
                mb = xq[o_b + d * nu + u]
                m_base[d] = _amax(m_base[d], abs(mb))
                for lv in range(nl):
                    j = d * nu * nl + u * nl + lv
                    below = xq[o_be + j]
                    above = xq[o_ab + j]
                    cm = below if abs(below) >= abs(above) else above
                    m_conn[d] = _amax(m_conn[d], abs(cm))
                    if series:
                        conn_s[row, u, lv, d] = cm
                if series:
                    base_s[row, u, d] = mb
            if series:
                shear_s[row, d] = sh
    inv = 2.0 * h
    for t in range(k):
        row = row0 + t
        for lv in range(nl):
            mag = 0.0
            for d in range(nd):
                c = d * nl + lv
                a = a_out[row, lv, d]
                if smooth and k >= 3:
                    if 0 < t < k - 1:
                        a = (vbuf[t + 1, c] - vbuf[t - 1, c]) / inv
                    elif t == 0 and has_prev:
                        a = (vbuf[1, c] - v_prev[c]) / inv
                a += ag[t, d]
                a_out[row, lv, d] = a
                acc[lv, d] = _amax(acc[lv, d], abs(a))
                mag += a * a
            acc_mag[lv] = _amax(acc_mag[lv], abs(a_out[row, lv, 0]) if nd == 1 else np.sqrt(mag))
    if smooth and k >= 2:
        for c in range(nlev):
            v_prev[c] = vbuf[k - 2, c]
        return True
    return False


def _pallet_pass_py(fr, s, lv, force, total, smax, smin, smag, fsum):  # noqa: ANN001, ANN201
    """One chunk of the pallets: friction ``fr`` and sliding ``s`` (k, m, nd), pallet levels
    ``lv (m,)``; updates the peaks of the level sums of friction ``force (nl, nd)`` (added in
    pallet order, as :func:`~seisrack.analysis.peaks.level_sum`), of the total ``total (nd)``,
    and of the sliding ``smax, smin (m, nd)``, ``smag (m)``; ``fsum (nl, nd)`` scratch."""
    k, m, nd = fr.shape
    nl = fsum.shape[0]
    for t in range(k):
        for lvl in range(nl):
            for d in range(nd):
                fsum[lvl, d] = 0.0
        for d in range(nd):
            tot = 0.0
            for j in range(m):
                f = fr[t, j, d]
                fsum[lv[j], d] += f
                tot += f
            total[d] = _amax(total[d], abs(tot))
        for lvl in range(nl):
            for d in range(nd):
                force[lvl, d] = _amax(force[lvl, d], abs(fsum[lvl, d]))
        for j in range(m):
            mag = 0.0
            for d in range(nd):
                x = s[t, j, d]
                smax[j, d] = _amax(smax[j, d], x)
                smin[j, d] = _amin(smin[j, d], x)
                mag += x * x
            smag[j] = _amax(smag[j], np.sqrt(mag))


if HAVE_NUMBA:
    _jit = _numba.njit(cache=True, error_model="numpy")
    _amax = _jit(_amax)
    _amin = _jit(_amin)
    level_pass = _jit(_level_pass_py)
    pallet_pass = _jit(_pallet_pass_py)
else:  # pragma: no cover - exercised where numba is absent
    level_pass = pallet_pass = None
