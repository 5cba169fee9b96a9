"""Contact configurations of the exact kernel (part 2 of 3): the stick/slip decision with its
modal operators (the decision itself and the configuration mass kept by rank-one updates are
``_contact.py``'s, shared with the Newmark kernel), and the cache of configuration modes.
Theory: ``docs/theory/stick_slip_engine.md`` §9–§10.

Source shared by the numba and pure-Python backends (executed after ``_exact_modes.py``).
"""

# ruff: noqa: N803, N806  (matrix names follow the equations)

import numpy as np

try:  # names injected by the loader
    _mode_matrices  # type: ignore[used-before-def]  # noqa: B018
except NameError:  # pragma: no cover - plain import of this file (pure-Python twin)
    from seisrack.dynamics._contact import _consistent
    from seisrack.dynamics._events import _JIT
    from seisrack.dynamics._exact_modes import _mode_matrices

@_JIT
def _consistent_cfg(w2, cd, P, mass, mus, mud, on_struct, Ms_key, key, q, qd, ag, pext, N,
                    stuck, sig, cand, forced, qdd, wdd, lam):
    """``_consistent`` (``_contact.py``) with the modal stiffness ``w2`` and damping ``cd``."""
    base = np.empty(w2.shape[0])
    for i in range(w2.shape[0]):
        base[i] = pext[i] - cd[i] * qd[i] - w2[i] * q[i]
    _consistent(P, mass, mus, mud, on_struct, Ms_key, key, base, ag, N, stuck, sig, cand,
                forced, qdd, wdd, lam)


@_JIT
def _build_config(slot, key, Ms, w2, cd, a1, fixed, pat, dt,
                  c_psi, c_psitm, c_nu2, c_cc, c_gpat, c_E):
    """Modes of the structure with the sliders of ``key`` stuck on it (configuration mass
    ``Ms``), and the operators derived from them. Cost O(r³), independent of the slider count."""
    n = w2.shape[0]
    any_stuck = False
    for j in range(key.shape[0]):
        if key[j]:
            any_stuck = True
    if fixed or not any_stuck:
        psi = np.eye(n)
        nu2 = w2.copy()
        cc = cd.copy()
        psitm = np.eye(n)
    else:
        L = np.linalg.cholesky(Ms)
        Linv = np.linalg.inv(L)
        A = (Linv * w2) @ Linv.T
        A = 0.5 * (A + A.T)
        nu2, Y = np.linalg.eigh(A)
        psi = Linv.T @ Y
        cc = a1 * nu2
        psitm = psi.T @ Ms
    scale = max(np.max(np.abs(nu2)), 1e-300)
    for k in range(n):
        if nu2[k] < 1e-14 * scale:
            nu2[k] = 1e-14 * scale
    c_psi[slot] = psi
    c_psitm[slot] = psitm
    c_nu2[slot] = nu2
    c_cc[slot] = cc
    c_gpat[slot] = psi.T @ pat.T
    _mode_matrices(nu2, cc, dt, c_E[slot])


@_JIT
def _find_config(key, Ms, cfg_key, cfg_valid, cfg_stamp, stamp, w2, cd, a1, fixed, pat, dt,
                 c_psi, c_psitm, c_nu2, c_cc, c_gpat, c_E):
    """Slot of the configuration ``key`` in the cache (built on a miss; LRU eviction)."""
    cap = cfg_key.shape[0]
    m = key.shape[0]
    for s in range(cap):
        if cfg_valid[s]:
            same = True
            for j in range(m):
                if cfg_key[s, j] != key[j]:
                    same = False
                    break
            if same:
                cfg_stamp[s] = stamp
                return s, False
    slot = 0
    oldest = cfg_stamp[0] if cfg_valid[0] else -1
    for s in range(cap):
        if not cfg_valid[s]:
            slot = s
            break
        if cfg_stamp[s] < oldest:
            oldest = cfg_stamp[s]
            slot = s
    _build_config(slot, key, Ms, w2, cd, a1, fixed, pat, dt,
                  c_psi, c_psitm, c_nu2, c_cc, c_gpat, c_E)
    for j in range(m):
        cfg_key[slot, j] = key[j]
    cfg_valid[slot] = True
    cfg_stamp[slot] = stamp
    return slot, True
