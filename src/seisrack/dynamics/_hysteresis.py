"""Moment–rotation hysteresis laws of the rotational hinges (beam-to-upright connectors, base
plates): elastic, elastic–perfectly plastic, bilinear kinematic hardening, and the pinched
four-point multilinear law of Lowes & Altoontash (2003) without damage.

Loaded first into the numba namespace by :mod:`seisrack.dynamics._kernel_numba` and imported
directly as the pure-Python twin. Every law is *rate independent* and written in the
"trial from the committed state" form of OpenSees' ``setTrialStrain`` / ``commitState``:

* ``_hyst_init(law, par, st)`` fills the virgin state row (θ = 0, M = 0);
* ``_hyst_trial(law, par, st_c, theta, st_t)`` reads the committed row ``st_c`` (never writes
  it), writes the trial row ``st_t`` and returns ``(M, dM/dθ)``; the result depends only on
  ``st_c`` and ``theta`` (any number of Newton iterations per step);
* the caller commits by ``st_c[:] = st_t``.

Parameter row ``par`` (float64[HYST_NPAR]) — built by :meth:`seisrack.model.hinge_law.HingeLaw.pack`
or :func:`_hyst_pack_pinching`:

====  =====================================================================================
0     initial stiffness k0 [N·m/rad] (all laws; pinching: slope of the envelope at θ = 0)
1     yield moment My [N·m] (EPP, bilinear)
2     hardening ratio b [-] (bilinear; 0 for EPP)
3-8   pinching: positive envelope rotations u0..u5 [rad] (u0 = 1e-4·max θ1, u1..u4 = θ1..θ4,
      u5 = 1e6·θ4)
9-14  pinching: positive envelope moments f0..f5 [N·m]
15-20 pinching: negative envelope rotations (negative numbers)
21-26 pinching: negative envelope moments (negative numbers)
27,28 pinching: elastic (unloading) stiffness of the positive / negative side, M1/θ1
29-31 pinching: rDispP, rForceP, uForceP
32-34 pinching: rDispN, rForceN, uForceN
====  =====================================================================================

State row ``st`` (float64[HYST_NSTATE]): 0 θ, 1 M, 2 tangent, 3 hysteretic work ∫M dθ
(trapezoidal per step); pinching only: 4 branch (0 elastic, 1 positive envelope, 2 negative
envelope, 3 unload/reload towards negative, 4 towards positive), 5-8 the branch's low
(θ, M) and high (θ, M) end points, 9 / 10 minimum / maximum rotation demand, 11 last non-zero
committed increment, 12-15 / 16-19 the four (θ, M) points of the current unload–reload path.

See ``docs/theory/hysteresis.md`` for the equations and what is (not) modelled.
"""

import numpy as np

try:  # names injected by the loader when executed after ``_hyst_base.py``, ``_hyst_pinching.py``
    _hyst_pinching  # type: ignore[used-before-def]  # noqa: B018
except NameError:  # pragma: no cover - plain import of this file (pure-Python twin)
    from seisrack.dynamics._hyst_base import (  # noqa: F401  (re-exported: the laws' API)
        _HYST_DBL_EPS,
        _HYST_DSTRAIN_ZERO,
        _JIT,
        HYST_BILINEAR,
        HYST_ELASTIC,
        HYST_EPP,
        HYST_NPAR,
        HYST_NSTATE,
        HYST_P_KNEG,
        HYST_P_KPOS,
        HYST_P_NEG_F,
        HYST_P_NEG_U,
        HYST_P_PINCH,
        HYST_P_POS_F,
        HYST_P_POS_U,
        HYST_PINCHING,
        HYST_S_BRANCH,
        HYST_S_KT,
        HYST_S_M,
        HYST_S_THETA,
        HYST_S_WORK,
        _hyst_bilinear,
        _hyst_div,
        _hyst_init,
        _hyst_k0,
    )
    from seisrack.dynamics._hyst_pinching import (  # noqa: F401
        _hyst_pack_pinching,
        _hyst_pinching,
    )


@_JIT
def _hyst_trial(law, par, st_c, theta, st_t):
    """Trial state at total rotation ``theta`` from the committed row ``st_c`` (unchanged):
    writes ``st_t`` and returns (moment, consistent tangent dM/dθ)."""
    return _hyst_trial_at(law, par.reshape((1, par.shape[0])), st_c.reshape((1, st_c.shape[0])),
                          0, theta, st_t.reshape((1, st_t.shape[0])))


@_JIT
def _hyst_trial_at(law, par, st_c, i, theta, st_t):
    """:func:`_hyst_trial` on row ``i`` of 2D parameter / state arrays (n_h, ·): the kernels'
    form, which indexes in place instead of creating three array views per call (each view
    costs numba an atomic reference count, per hinge and Newton iteration)."""
    for c in range(st_t.shape[1]):
        st_t[i, c] = st_c[i, c]
    if law == HYST_ELASTIC:
        kt = par[i, 0]
        m = kt * theta
    elif law == HYST_PINCHING:
        m, kt = _hyst_pinching(par[i], st_c[i], theta, st_t[i])
    else:
        m, kt = _hyst_bilinear(par, st_c, i, theta)
    st_t[i, HYST_S_WORK] = st_c[i, HYST_S_WORK] + 0.5 * (m + st_c[i, HYST_S_M]) * (
        theta - st_c[i, HYST_S_THETA])
    st_t[i, HYST_S_THETA] = theta
    st_t[i, HYST_S_M] = m
    st_t[i, HYST_S_KT] = kt
    return m, kt


@_JIT
def _hyst_drive(law, par, thetas, m_out, k_out):
    """Drive a law through a rotation history, committing after every sample (a test and
    report helper): moments into ``m_out``, tangents into ``k_out``; returns the final work."""
    n = HYST_NSTATE
    st_c = np.empty(n)
    st_t = np.empty(n)
    _hyst_init(law, par, st_c)
    for i in range(thetas.shape[0]):
        m, kt = _hyst_trial(law, par, st_c, thetas[i], st_t)
        m_out[i] = m
        k_out[i] = kt
        for j in range(n):
            st_c[j] = st_t[j]
    return st_c[HYST_S_WORK]


@_JIT
def _hyst_zwork(law, par, st_c, i, k, ta, dt_, st_t):
    """``∫ (M(θ) − k θ) dθ`` from ``ta`` to ``ta + dt_`` along the trial from the committed row
    ``i`` (the work of a hinge's correction force ``z = M − k θ`` over a trial rotation; the
    planar step's line search needs it exactly). ``M(θ)`` is piecewise linear: a piece is
    integrated by the trapezoid once both its ends lie on one line (the tangents and
    intercepts that :func:`_hyst_trial_at` returns); otherwise it is split where the two end
    lines meet when the law passes through that point (one kink), else in the middle. On one
    line the increment ``dt_`` is used as given (``ta + dt_ − ta`` loses it when it is far
    below the rotation's last digit). ``st_t`` is scratch."""
    if dt_ == 0.0:
        return 0.0
    tb = ta + dt_
    ma, ka = _hyst_trial_at(law, par, st_c, i, ta, st_t)
    mb, kb = _hyst_trial_at(law, par, st_c, i, tb, st_t)
    ca = ma - ka * ta
    cb = mb - kb * tb
    scale = abs(ma) + abs(mb) + abs(ka * ta) + abs(kb * tb) + 1e-300
    if abs(ka - kb) <= 1e-12 * (abs(ka) + abs(kb)) and abs(ca - cb) <= 1e-12 * scale:
        return dt_ * ((ma - k * ta) + 0.5 * (ka - k) * dt_)
    sgn = 1.0
    lo, hi = ta, tb
    if lo > hi:
        lo, hi = tb, ta
        sgn = -1.0
    stack = np.empty((48, 2))
    stack[0, 0] = lo
    stack[0, 1] = hi
    top = 1
    total = 0.0
    for _ in range(200):
        if top == 0:
            break
        top -= 1
        a = stack[top, 0]
        b = stack[top, 1]
        ma, ka = _hyst_trial_at(law, par, st_c, i, a, st_t)
        mb, kb = _hyst_trial_at(law, par, st_c, i, b, st_t)
        ca = ma - ka * a
        cb = mb - kb * b
        scale = abs(ma) + abs(mb) + abs(ka * a) + abs(kb * b) + 1e-300
        if (abs(ka - kb) <= 1e-12 * (abs(ka) + abs(kb)) and abs(ca - cb) <= 1e-12 * scale) \
                or b - a <= 1e-14 * (abs(a) + abs(b)) or top >= 46:
            total += 0.5 * ((ma - k * a) + (mb - k * b)) * (b - a)
            continue
        if ka != kb:
            x = (cb - ca) / (ka - kb)
            if a < x < b:
                mx, _kx = _hyst_trial_at(law, par, st_c, i, x, st_t)
                if abs(mx - (ka * x + ca)) <= 1e-12 * scale:
                    total += 0.5 * ((ma - k * a) + (mx - k * x)) * (x - a)
                    total += 0.5 * ((mx - k * x) + (mb - k * b)) * (b - x)
                    continue
        mid = 0.5 * (a + b)
        stack[top, 0] = a
        stack[top, 1] = mid
        stack[top + 1, 0] = mid
        stack[top + 1, 1] = b
        top += 2
    for t in range(top):  # not reached in practice: the trapezoid on what is left
        a = stack[t, 0]
        b = stack[t, 1]
        ma, _ka = _hyst_trial_at(law, par, st_c, i, a, st_t)
        mb, _kb = _hyst_trial_at(law, par, st_c, i, b, st_t)
        total += 0.5 * ((ma - k * a) + (mb - k * b)) * (b - a)
    return sgn * total
