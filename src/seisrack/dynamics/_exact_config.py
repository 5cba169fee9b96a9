"""Contact configurations of the exact kernel (part 2 of 3): the configuration mass kept by
rank-one updates, the stick/slip decision in the structure's coordinates, and the cache of
configuration modes. Theory: ``docs/theory/stick_slip_engine.md`` §9–§10.

Source shared by the numba and pure-Python backends (executed after ``_exact_modes.py``).
"""

# ruff: noqa: N803, N806  (matrix names follow the equations)

import numpy as np

try:  # names injected by the loader
    _mode_matrices  # type: ignore[used-before-def]  # noqa: B018
except NameError:  # pragma: no cover - plain import of this file (pure-Python twin)
    from seisrack.dynamics._events import _JIT, _apply_candidates, _release_worst
    from seisrack.dynamics._exact_modes import _mode_matrices

@_JIT
def _rank1(Ms, p, c):
    """Ms += c p pᵀ (a slider of mass c sticking, or -c unsticking)."""
    r = p.shape[0]
    for i in range(r):
        pi = c * p[i]
        if pi != 0.0:
            for k in range(r):
                Ms[i, k] += pi * p[k]


@_JIT
def _cfg_mass(P, mass, key, Ms):
    """Ms = I + P_Sᵀ diag(m_S) P_S for the stuck set ``key`` (from scratch)."""
    r = P.shape[1]
    for i in range(r):
        for k in range(r):
            Ms[i, k] = 0.0
        Ms[i, i] = 1.0
    for j in range(P.shape[0]):
        if key[j]:
            _rank1(Ms, P[j], mass[j])


@_JIT
def _spd_solve(A, b, x):
    """x = A⁻¹ b for a small symmetric positive-definite A (Cholesky)."""
    r = A.shape[0]
    L = np.linalg.cholesky(A)
    for i in range(r):
        acc = b[i]
        for k in range(i):
            acc -= L[i, k] * x[k]
        x[i] = acc / L[i, i]
    for i in range(r - 1, -1, -1):
        acc = x[i]
        for k in range(i + 1, r):
            acc -= L[k, i] * x[k]
        x[i] = acc / L[i, i]


@_JIT
def _consistent_cfg(w2, cd, P, mass, mus, mud, on_struct, Ms_key, key, q, qd, ag, pext, N,
                    stuck, sig, cand, forced, qdd, wdd, lam):
    """Decide the contact state at an instant and compute consistent accelerations.

    Same decision rule as ``_consistent`` (stick every candidate, release the most overloaded
    stuck slider one at a time), solved in the structure's coordinates: the stuck sliders'
    masses join the configuration mass ``I + P_Sᵀ m_S P_S`` (rank-one changes from ``Ms_key``,
    the mass of the stuck set ``key``), so the cost is O(m r + r³), never O(m²).
    """
    r = w2.shape[0]
    m = mass.shape[0]
    base = np.empty(r)
    for i in range(r):
        base[i] = pext[i] - cd[i] * qd[i] - w2[i] * q[i]
    _apply_candidates(cand, forced, stuck)
    Mt = Ms_key.copy()
    for j in range(m):
        if on_struct[j] and stuck[j] != key[j]:
            _rank1(Mt, P[j], mass[j] if stuck[j] else -mass[j])
    rhs = np.empty(r)
    for _it in range(2 * m + 2):
        for i in range(r):
            rhs[i] = base[i]
        for j in range(m):
            if stuck[j]:
                f = -mass[j] * ag
            else:
                lam[j] = -mud[j] * N[j] * sig[j]
                f = -lam[j]
            if on_struct[j] and f != 0.0:
                for i in range(r):
                    rhs[i] += P[j, i] * f
        _spd_solve(Mt, rhs, qdd)
        for j in range(m):
            if stuck[j]:
                acc = 0.0
                if on_struct[j]:
                    for i in range(r):
                        acc += P[j, i] * qdd[i]
                lam[j] = mass[j] * (acc + ag)
        worst = _release_worst(stuck, forced, lam, mus, N, sig)
        if worst < 0:
            break
        if on_struct[worst]:
            _rank1(Mt, P[worst], -mass[worst])
    for j in range(m):
        wdd[j] = -ag + lam[j] / mass[j]


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


@_JIT
def _cfg_key(stuck, on_struct, key):
    for j in range(stuck.shape[0]):
        key[j] = stuck[j] and on_struct[j]
