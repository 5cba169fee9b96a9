"""The nonlinear hinges of the planar stick–slip kernel outside its Newton iteration: their
moments at a state, their commit at an accepted sub-step (with the work of their corrections),
and the modal load with their corrections moved over (source shared by the numba and
pure-Python backends; theory: ``docs/theory/planar_friction.md`` §7). The laws are
``_hysteresis.py``'s; the iteration is ``_planar_step.py``'s.
"""

# ruff: noqa: N803, N806  (matrix names follow the equations)

import numpy as np

try:  # names injected by the loader when executed after ``_hysteresis.py``
    _hyst_trial_at  # type: ignore[used-before-def]  # noqa: B018
except NameError:  # pragma: no cover - plain import of this file (pure-Python twin)
    from seisrack.dynamics._events import _JIT
    from seisrack.dynamics._hysteresis import HYST_S_M, HYST_S_THETA, _hyst_trial_at


@_JIT
def _hinge_eval(Q, hth0, hk, hlaw, hpar, hst_c, hst_t, q, hM, hz):
    """Trial moments ``hM`` and corrections ``hz = M − k θ`` of the hinges at ``q`` (basis
    coordinates), from their committed states ``hst_c``; trial states into ``hst_t``."""
    for i in range(hk.shape[0]):
        th = hth0[i] + np.dot(Q[i], q)
        mi, _kt = _hyst_trial_at(hlaw[i], hpar, hst_c, i, th, hst_t)
        hM[i] = mi
        hz[i] = mi - hk[i] * th


@_JIT
def _hinge_commit_at(Q, hth0, hk, hlaw, hpar, hst_c, hst_t, q, hM, hz):
    """Commit the hinges at the accepted state ``q``; returns the work of their corrections
    over the sub-step, ∫ z dθ, by the trapezoid (Newmark's energy identity needs the forces at
    the two ends). ``hM``, ``hz``: the committed moments and corrections, updated."""
    work = 0.0
    for i in range(hk.shape[0]):
        th = hth0[i] + np.dot(Q[i], q)
        mi, _kt = _hyst_trial_at(hlaw[i], hpar, hst_c, i, th, hst_t)
        zi = mi - hk[i] * th
        work += 0.5 * (hz[i] + zi) * (th - hst_c[i, HYST_S_THETA])
        for c in range(hst_c.shape[1]):
            hst_c[i, c] = hst_t[i, c]
        hM[i] = mi
        hz[i] = zi
    return work


@_JIT
def _hinge_committed(hst_c, hk, hM, hz):
    """Moments and corrections of the committed hinge states."""
    for i in range(hk.shape[0]):
        hM[i] = hst_c[i, HYST_S_M]
        hz[i] = hM[i] - hk[i] * hst_c[i, HYST_S_THETA]


@_JIT
def _minus_qtz(pe, Q, hz, out):
    """out = pe − Qᵀ z: the modal load with the hinges' correction forces moved over."""
    out[:] = pe
    for i in range(hz.shape[0]):
        zi = hz[i]
        if zi != 0.0:
            for k in range(out.shape[0]):
                out[k] -= Q[i, k] * zi
