"""Contact-state decisions of the Newmark kernel at an instant, and the end of a Newmark step
(source shared by both backends).

``_consistent`` decides which sliders stick or slide at an instant (start of the run, or a
located event) and computes the consistent accelerations; ``_accel_fixed`` recomputes the
accelerations from equilibrium for given slider forces; ``_newmark_end`` completes a trial
step (linear ``_trial`` and nonlinear ``_nl_trial``) once its generalized forces are known.
Loaded before ``_kernel_hinge.py`` and ``_kernel.py`` into the numba namespace (see
``_kernel_numba.py``); ``docs/theory/stick_slip_engine.md`` §3 and §5.
"""

# ruff: noqa: N803, N806  (matrix names follow the equations)

import numpy as np

try:  # names injected by the loader when executed after ``_events.py`` and ``_linalg.py``
    _release_worst  # type: ignore[used-before-def]  # noqa: B018
except NameError:  # pragma: no cover - plain import of this file (pure-Python twin)
    from seisrack.dynamics._events import _JIT, _apply_candidates, _release_worst
    from seisrack.dynamics._linalg import _damp_mul, _mv, _solve


@_JIT
def _stuck_index(stuck, n_stuck):
    """Indices of the ``n_stuck`` stuck sliders."""
    idx = np.empty(n_stuck, dtype=np.int64)
    k = 0
    for j in range(stuck.shape[0]):
        if stuck[j]:
            idx[k] = j
            k += 1
    return idx


@_JIT
def _newmark_end(h, HYt, y, qhat, q0, qd0, qdd0, P, mass, ag1, lam1, w0, wd0, wdd0, stuck,
                 q1, qd1, qdd1, w1, wd1, wdd1, s1, f, vn):
    """End state of an average-acceleration step of length ``h``: Δq = q̂ − HYt·y (``y``: the
    slider forces, then any hinge corrections; ``HYt`` = K̂⁻¹ [P; Q]ᵀ), the Newmark updates of
    q̇, q̈, and the sliders' (w, ẇ, ẅ) under the forces ``lam1``; a stuck slider gets exactly
    its support's velocity (removes round-off drift). ``f`` (n,), ``vn`` (m,) are scratch."""
    n = q0.shape[0]
    c0 = 4.0 / (h * h)
    c1 = 4.0 / h
    c2 = 2.0 / h
    _mv(HYt, y, f)
    for i in range(n):
        dq = qhat[i] - f[i]
        q1[i] = q0[i] + dq
        qd1[i] = c2 * dq - qd0[i]
        qdd1[i] = c0 * dq - c1 * qd0[i] - qdd0[i]
    _mv(P, qd1, vn)
    for j in range(mass.shape[0]):
        wdd1[j] = -ag1 + lam1[j] / mass[j]
        wd1[j] = wd0[j] + 0.5 * h * (wdd0[j] + wdd1[j])
        w1[j] = w0[j] + h * wd0[j] + 0.25 * h * h * (wdd0[j] + wdd1[j])
        if stuck[j]:
            wd1[j] = vn[j]
        s1[j] = wd1[j] - vn[j]


@_JIT
def _accel_fixed(kd, cd, Cq, diag, P, mass, q, qd, ag, pext, lam, qdd, wdd):
    """Accelerations from equilibrium for given slider forces ``lam``."""
    n = kd.shape[0]
    m = mass.shape[0]
    _damp_mul(cd, Cq, diag, qd, qdd)
    for i in range(n):
        acc = pext[i] - qdd[i] - kd[i] * q[i]
        for j in range(m):
            acc -= P[j, i] * lam[j]
        qdd[i] = acc
    for j in range(m):
        wdd[j] = -ag + lam[j] / mass[j]


@_JIT
def _consistent(kd, cd, Cq, diag, P, B, mass, mus, mud, q, qd, ag, pext, N, stuck, sig,
                cand, forced, qdd, wdd, lam):
    """Decide the contact state at an instant and compute consistent accelerations.

    ``cand``: sliders at zero relative velocity whose state must be decided (stick if the force
    needed to keep them stuck is within mu_s N, else slide opposite to that force).
    ``forced``: sliders that must slide with the given ``sig`` (slip onset just located).
    Updates ``stuck`` and ``sig`` in place; writes accelerations ``qdd``, ``wdd`` and ``lam``.
    """
    n = kd.shape[0]
    m = mass.shape[0]
    tmp = np.empty(n)
    _damp_mul(cd, Cq, diag, qd, tmp)
    base = np.empty(n)  # structural acceleration without slider forces
    for i in range(n):
        base[i] = pext[i] - tmp[i] - kd[i] * q[i]
    pb = np.empty(m)
    _mv(P, base, pb)
    sdot0 = np.empty(m)
    for j in range(m):
        sdot0[j] = -ag - pb[j]
    _apply_candidates(cand, forced, stuck)
    for _it in range(2 * m + 2):
        n_stuck = 0
        for j in range(m):
            if stuck[j]:
                n_stuck += 1
            else:
                lam[j] = -mud[j] * N[j] * sig[j]
        if n_stuck > 0:
            idx = _stuck_index(stuck, n_stuck)
            Bss = np.empty((n_stuck, n_stuck))
            r = np.empty(n_stuck)
            for a in range(n_stuck):
                acc = sdot0[idx[a]]
                for j in range(m):
                    if not stuck[j]:
                        acc += B[idx[a], j] * lam[j]
                r[a] = -acc
                for c in range(n_stuck):
                    Bss[a, c] = B[idx[a], idx[c]]
            x = _solve(Bss, r.reshape((n_stuck, 1)))[:, 0]
            for a in range(n_stuck):
                lam[idx[a]] = x[a]
        # release the most overloaded stuck slider, one at a time
        if _release_worst(stuck, forced, lam, mus, N, sig) < 0:
            break
    ptl = np.empty(n)
    _mv(np.ascontiguousarray(P.T), lam, ptl)
    for i in range(n):
        qdd[i] = base[i] - ptl[i]
    for j in range(m):
        wdd[j] = -ag + lam[j] / mass[j]
