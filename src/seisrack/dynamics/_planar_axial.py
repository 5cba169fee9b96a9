"""The P-Δ of the members' axial-force change inside the planar kernel (source shared by the
numba and pure-Python backends; the operators: :mod:`seisrack.dynamics.axial`).

The internal force ``f(q) = Gᵀ (s ∘ (A q)[o] ∘ (c + G q))`` is not part of the step's Newton
matrix (it changes with q and is not the gradient of a potential, so the step's line search on
the potential could not hold it). ``_trial_ax`` solves the step with ``f`` moved to the load,
``pext1 − f(q1)``, by a fixed-point iteration on ``f``: each pass is an ordinary trial (its own
Newton iteration, warm-started from the previous pass), until ``f`` at its end state stops
changing. The contraction is the ratio of the P-Δ stiffness change to the step matrix
K + 2C/h + 4M/h² (a few hundredths on a rack, below 0.3 even for members whose axial force
doubles), so a handful of passes reach round-off.
"""

# ruff: noqa: N803, N806  (matrix names follow the equations)

import numpy as np

try:  # names injected by the loader when executed after ``_planar_step.py``
    _trial  # type: ignore[used-before-def]  # noqa: B018
except NameError:  # pragma: no cover - plain import of this file (pure-Python twin)
    from seisrack.dynamics._events import _JIT
    from seisrack.dynamics._planar_step import _trial

#: fixed-point passes of one trial before it is reported as not converged
_AXIAL_MAX = 40
#: a pass is the last when f moves by less than this fraction of its size (or of the load's)
_AXIAL_TOL = 1e-11


@_JIT
def _axial_force(AA, AG, Ao, As, Ac, q, dn, gw, out):
    """out = f(q) (r,): the P-Δ force of the axial forces' change at ``q``; ``dn`` (n_m,) and
    ``gw`` (n_g,) are scratch. Zero when there are no factors."""
    if AG.shape[0] == 0:
        out[:] = 0.0
        return
    dn[:] = np.dot(AA, q)
    gw[:] = np.dot(AG, q)
    for g in range(AG.shape[0]):
        gw[g] = As[g] * dn[Ao[g]] * (Ac[g] + gw[g])
    out[:] = np.dot(gw, AG)


@_JIT
def _trial_ax(h, kq, kw, kd, cd, Co, P, mass, mus, mud, S, T0, N0, stuck, dirn, ag1,
              pext1, N1, T1, S1, e, tolF, dt, W, A, G, PF, stats, dq_start, warm, fac,
              Q, hth0, hk, hlaw, hpar, hst_c, hst_t, hz_c, hM, hz, HW,
              AA, AG, Ao, As, Ac, AXW, dn, gw):
    """``_trial`` (same arguments and returns) with the P-Δ of the current axial forces:
    the fixed point of the module docstring; returns 3 when it does not settle within
    ``_AXIAL_MAX`` passes. ``AXW`` (4, r) is scratch. Without factors: one plain trial."""
    if AG.shape[0] == 0:
        return _trial(h, kq, kw, kd, cd, Co, P, mass, mus, mud, S, T0, N0, stuck, dirn,
                      ag1, pext1, N1, T1, S1, e, tolF, dt, W, A, G, PF, stats, dq_start, warm,
                      fac, Q, hth0, hk, hlaw, hpar, hst_c, hst_t, hz_c, hM, hz, HW)
    r = kd.shape[0]
    f, fn, pe, dqs = AXW[0], AXW[1], AXW[2], AXW[3]
    for i in range(r):  # the first guess of the end state: the caller's prediction
        dqs[i] = T0[0, i] + (dq_start[i] if warm else 0.0)
    _axial_force(AA, AG, Ao, As, Ac, dqs, dn, gw, f)
    for i in range(r):
        dqs[i] = dq_start[i]
    pmax = 0.0
    for i in range(r):
        pmax = max(pmax, abs(pext1[i]))
    w = warm
    for _it in range(_AXIAL_MAX):
        for i in range(r):
            pe[i] = pext1[i] - f[i]
        ok = _trial(h, kq, kw, kd, cd, Co, P, mass, mus, mud, S, T0, N0, stuck, dirn, ag1,
                    pe, N1, T1, S1, e, tolF, dt, W, A, G, PF, stats, dqs, w, fac,
                    Q, hth0, hk, hlaw, hpar, hst_c, hst_t, hz_c, hM, hz, HW)
        if ok != 0:
            return ok
        _axial_force(AA, AG, Ao, As, Ac, T1[0], dn, gw, fn)
        diff = 0.0
        size = 0.0
        for i in range(r):
            diff = max(diff, abs(fn[i] - f[i]))
            size = max(size, abs(fn[i]))
            f[i] = fn[i]
            dqs[i] = T1[0, i] - T0[0, i]
        if diff <= _AXIAL_TOL * max(size, 1e-3 * pmax) or diff == 0.0:
            return 0
        w = True
    return 3
