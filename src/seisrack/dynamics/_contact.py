"""Contact-state decisions of the Newmark kernel at an instant, and the end of a Newmark step
(source shared by both backends).

``_consistent`` decides which sliders stick or slide at an instant (start of the run, or a
located event) and computes the consistent accelerations, in the structure's coordinates with
the stuck sliders' configuration mass (shared with the exact kernel); ``_accel_fixed``
recomputes the accelerations from equilibrium for given slider forces; ``_step_end``
completes a trial step (``_nl_trial``) once its generalized forces are known. Loaded before
``_kernel_hinge.py`` and ``_kernel.py`` into the numba namespace (see ``_kernel_numba.py``);
``docs/theory/stick_slip_engine.md`` §3 and §5.
"""

# ruff: noqa: N803, N806  (matrix names follow the equations)

import numpy as np

try:  # names injected by the loader when executed after ``_events.py`` and ``_linalg.py``
    _release_worst  # type: ignore[used-before-def]  # noqa: B018
except NameError:  # pragma: no cover - plain import of this file (pure-Python twin)
    from seisrack.dynamics._events import _JIT, _apply_candidates, _release_worst
    from seisrack.dynamics._lapack import _chol, _chol_solve
    from seisrack.dynamics._linalg import _damp_mul, _mtv, _mv


@_JIT
def _step_end(sc, kq, kw, DH, y, qhat, q0, P, mass, ag1, lam1, stuck,
              q1, qd1, qdd1, w1, wd1, wdd1, s1, f, vn):
    """End state of an implicit (sub)step once its generalized forces are known: Δq = q̂ −
    (DH)ᵀ y (``y``: the slider forces, then any hinge corrections; ``DH`` = [P; Q] K̂⁻¹), the
    step's relations ``q̈₁ = a Δq + A``, ``q̇₁ = v Δq + V`` (``sc`` = [a, v, β, κ], ``kq`` =
    [A; V], ``_kernel_stage.py``), and the sliders' ``ẅ₁ = λ₁/m − a_g``, ``ẇ₁ = β λ₁/m + W``,
    ``w₁ = X + κ ẇ₁`` (``kw`` = [W; X]); a stuck slider gets exactly its support's velocity
    (removes round-off drift). ``f`` (n,), ``vn`` (m,) are scratch."""
    n = q0.shape[0]
    a = sc[0]
    v = sc[1]
    _mtv(DH, y, f)
    for i in range(n):
        dq = qhat[i] - f[i]
        q1[i] = q0[i] + dq
        qd1[i] = v * dq + kq[1, i]
        qdd1[i] = a * dq + kq[0, i]
    _mv(P, qd1, vn)
    for j in range(mass.shape[0]):
        r = lam1[j] / mass[j]
        wdd1[j] = r - ag1
        wd1[j] = sc[2] * r + kw[0, j]
        w1[j] = kw[1, j] + sc[3] * wd1[j]
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
def _free_accel(kd, cd, Cq, diag, q, qd, pext, base):
    """base = pext − C q̇ − K q: the structure's acceleration without slider forces."""
    _damp_mul(cd, Cq, diag, qd, base)
    for i in range(kd.shape[0]):
        base[i] = pext[i] - base[i] - kd[i] * q[i]


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
def _cfg_key(stuck, on_struct, key):
    for j in range(stuck.shape[0]):
        key[j] = stuck[j] and on_struct[j]


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
def _cfg_update(P, mass, stuck, on_struct, key, Ms_key, n_rank1):
    """Bring the configuration mass ``Ms_key`` of the stuck set ``key`` to ``stuck`` by
    rank-one changes (rebuilt after 1000 of them, which bounds their round-off). Returns
    (whether the set changed, the rank-one count since the last rebuild)."""
    changed = False
    for j in range(stuck.shape[0]):
        now = stuck[j] and on_struct[j]
        if now != key[j]:
            _rank1(Ms_key, P[j], mass[j] if now else -mass[j])
            n_rank1 += 1
            key[j] = now
            changed = True
    if n_rank1 > 1000:
        _cfg_mass(P, mass, key, Ms_key)
        n_rank1 = 0
    return changed, n_rank1


@_JIT
def _consistent(P, mass, mus, mud, on_struct, Ms_key, key, base, ag, N, stuck, sig, cand,
                forced, qdd, wdd, lam):
    """Decide the contact state at an instant and compute consistent accelerations.

    ``base``: the structure's acceleration without slider forces (``_free_accel``).
    ``cand``: sliders at zero relative velocity whose state must be decided (stick if the force
    needed to keep them stuck is within mu_s N, else slide opposite to that force).
    ``forced``: sliders that must slide with the given ``sig`` (slip onset just located).
    Stick every candidate, then release the most overloaded stuck slider one at a time. Solved
    in the structure's coordinates: the stuck sliders' masses join the configuration mass
    ``I + P_Sᵀ m_S P_S`` (rank-one changes from ``Ms_key``, the mass of the stuck set ``key``),
    so the cost is O(m r + r³), never O(m²). Updates ``stuck`` and ``sig`` in place; writes
    accelerations ``qdd``, ``wdd`` and ``lam``.
    """
    r = base.shape[0]
    m = mass.shape[0]
    _apply_candidates(cand, forced, stuck)
    Mt = Ms_key.copy()
    for j in range(m):
        if on_struct[j] and stuck[j] != key[j]:
            _rank1(Mt, P[j], mass[j] if stuck[j] else -mass[j])
    L = np.empty((r, r))
    f = np.empty(m)
    rhs = np.empty(r)
    acc = np.empty(m)
    for _it in range(2 * m + 2):
        for j in range(m):
            if stuck[j]:
                f[j] = mass[j] * ag
            else:
                lam[j] = -mud[j] * N[j] * sig[j]
                f[j] = lam[j]
            if not on_struct[j]:
                f[j] = 0.0
        _mtv(P, f, rhs)
        for i in range(r):
            rhs[i] = base[i] - rhs[i]
        L[:, :] = Mt
        if not _chol(L):  # not reached: the configuration mass is positive definite
            lam[:] = np.nan
            break
        _chol_solve(L, rhs)
        qdd[:] = rhs
        _mv(P, qdd, acc)
        for j in range(m):
            if stuck[j]:
                lam[j] = mass[j] * ((acc[j] if on_struct[j] else 0.0) + ag)
        worst = _release_worst(stuck, forced, lam, mus, N, sig)
        if worst < 0:
            break
        if on_struct[worst]:
            _rank1(Mt, P[worst], -mass[worst])
    for j in range(m):
        wdd[j] = -ag + lam[j] / mass[j]
