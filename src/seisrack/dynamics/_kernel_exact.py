"""Exact-propagator stick–slip kernel (source shared by the numba and pure-Python backends).

Loaded after ``_events.py`` and ``_kernel.py`` in the same namespace (see
:mod:`seisrack.dynamics.kernels`), so it reuses ``_mv`` from the latter and the event core
(detection, location, transitions, output) from the former.

Between two contact events the system is linear and time-invariant: the structure plus the
masses of the sliders that are stuck on it (they move with their support node), loaded by
excitations that are linear in time inside a step and by the known friction forces of the
sliding sliders. For each contact configuration the kernel computes the modes of that
constrained system once (generalised symmetric eigenproblem of ``diag(omega²)`` against
``I + P_S^T diag(m_S) P_S`` in the structure's modal coordinates) and propagates each mode in
closed form over the step (homogeneous 2x2 exponential plus the particular solution of a
linear-in-time load). This is exact for classical damping in every configuration, which the
engine checks before choosing this kernel (no damping, stiffness-proportional damping, or no
slider resting on the structure). The only discretisation errors left are the linear
interpolation of the excitation between samples and the tolerance of the event location.
See ``docs/theory/stick_slip_engine.md`` §9.
"""

# ruff: noqa: N803, N806  (matrix names follow the equations)

import numpy as np

try:  # names injected by the loader when executed after ``_kernel.py``
    _consistent  # type: ignore[used-before-def]  # noqa: B018
except NameError:  # pragma: no cover - plain import of this file (pure-Python twin)
    from seisrack.dynamics._events import (
        _JIT,
        STATUS_OK,
        STATUS_SUBSTEP_LIMIT,
        _accept_trial,
        _apply_candidates,
        _bracket_end,
        _bracket_start,
        _classify,
        _detect,
        _event_buffers,
        _finish,
        _init_sliders,
        _propose,
        _record_events,
        _release_worst,
        _sample,
        _substep_end,
        _write_output,
    )
    from seisrack.dynamics._kernel import _mv

#: Gauss–Legendre 3-point nodes and weights on [0, 1] (energy quadrature)
_GL_X = np.array([0.5 - 0.1 * np.sqrt(15.0), 0.5, 0.5 + 0.1 * np.sqrt(15.0)])
_GL_W = np.array([5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0])


@_JIT
def _mode_matrix(nu2, c, h, E):
    """Homogeneous propagator of y'' + c y' + nu2 y = 0 over h: E = (E00, E01, E10, E11).

    One formula for every damping regime: with a = c/2 and b² = nu2 - a², the solution is
    e^{-a t} (C(t) y0 + S(t) (y0' + a y0)) with C = cos/cosh/1 and S = sin(bt)/b, sinh/b or t.
    Overdamped stiff modes are evaluated as sums of decaying exponentials (no overflow).
    """
    a = 0.5 * c
    b2 = nu2 - a * a
    x = b2 * h * h
    if abs(x) < 1e-3:
        # series in b² h² (cos / cosh and sin/b / sinh/b share it)
        eC = 1.0 - x / 2.0 + x * x / 24.0 - x * x * x / 720.0
        eS = h * (1.0 - x / 6.0 + x * x / 120.0 - x * x * x / 5040.0)
        ea = np.exp(-a * h)
        eC *= ea
        eS *= ea
    elif b2 > 0.0:
        b = np.sqrt(b2)
        ea = np.exp(-a * h)
        eC = ea * np.cos(b * h)
        eS = ea * np.sin(b * h) / b
    else:
        b = np.sqrt(-b2)
        # a - b >= 0 computed without cancellation: (a - b) = nu2 / (a + b)
        slow = nu2 / (a + b)
        e1 = np.exp(-slow * h)
        e2 = np.exp(-(a + b) * h)
        eC = 0.5 * (e1 + e2)
        eS = 0.5 * (e1 - e2) / b
    E[0] = eC + a * eS
    E[1] = eS
    E[2] = -nu2 * eS
    E[3] = eC - a * eS


@_JIT
def _mode_matrices(nu2, cc, h, E):
    for k in range(nu2.shape[0]):
        _mode_matrix(nu2[k], cc[k], h, E[k])


@_JIT
def _propagate(nu2, cc, E, eta0, etad0, g0, g1, h, eta1, etad1):
    """Exact modal step: loads g linear from g0 to g1 over h; E from ``_mode_matrices(h)``."""
    for k in range(nu2.shape[0]):
        s = (g1[k] - g0[k]) / h
        B = s / nu2[k]
        A = (g0[k] - cc[k] * B) / nu2[k]
        y = eta0[k] - A
        yd = etad0[k] - B
        eta1[k] = A + B * h + E[k, 0] * y + E[k, 1] * yd
        etad1[k] = B + E[k, 2] * y + E[k, 3] * yd


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
def _slider_load(P, series_t, ag_t, N_t, mass, mud, stuck, sig, on_struct, fq):
    """Structure-coordinate load of the sliders: -P_Sᵀ m_S a_g - P_Fᵀ λ_F."""
    r = fq.shape[0]
    for i in range(r):
        fq[i] = 0.0
    for j in range(mass.shape[0]):
        if not on_struct[j]:
            continue
        if stuck[j]:
            f = -mass[j] * ag_t
        else:
            f = mud[j] * N_t[j] * sig[j]  # -λ_j with λ_j = -mu_d N σ
        if f != 0.0:
            for i in range(r):
                fq[i] += P[j, i] * f


@_JIT
def _loads(psi, gpat, P, series_t, ag_t, N_t, mass, mud, stuck, sig, on_struct, fq, out):
    """Constrained modal load at one instant: Ψᵀ(p - P_Sᵀ m_S a_g - P_Fᵀ λ_F)."""
    n = out.shape[0]
    npat = series_t.shape[0]
    _slider_load(P, series_t, ag_t, N_t, mass, mud, stuck, sig, on_struct, fq)
    for k in range(n):
        acc = 0.0
        for c in range(npat):
            acc += gpat[k, c] * series_t[c]
        for i in range(n):
            acc += psi[i, k] * fq[i]
        out[k] = acc


@_JIT
def _trial_exact(h, Eh, psi, nu2, cc, P, gpat, mass, mud, on_struct, stuck, sig,
                 eta0, etad0, w0, wd0, ser0, ser1, ag0, ag1, N0, N1, g0, g1,
                 eta1, etad1, w1, wd1, lam1, s1, etadd, x0, x1, xd1, xdd, fq):
    """Exact step of length h in a fixed contact state (E = propagator for h)."""
    n = nu2.shape[0]
    m = mass.shape[0]
    _loads(psi, gpat, P, ser0, ag0, N0, mass, mud, stuck, sig, on_struct, fq, g0)
    _loads(psi, gpat, P, ser1, ag1, N1, mass, mud, stuck, sig, on_struct, fq, g1)
    _propagate(nu2, cc, Eh, eta0, etad0, g0, g1, h, eta1, etad1)
    for k in range(n):
        etadd[k] = g1[k] - cc[k] * etad1[k] - nu2[k] * eta1[k]
    _mv(psi, eta0, x0)
    _mv(psi, eta1, x1)
    _mv(psi, etad1, xd1)
    _mv(psi, etadd, xdd)
    for j in range(m):
        if stuck[j]:
            d0 = 0.0
            d1 = 0.0
            v1 = 0.0
            a1_ = 0.0
            if on_struct[j]:
                for i in range(n):
                    p = P[j, i]
                    d0 += p * x0[i]
                    d1 += p * x1[i]
                    v1 += p * xd1[i]
                    a1_ += p * xdd[i]
            w1[j] = w0[j] + (d1 - d0)
            wd1[j] = v1
            lam1[j] = mass[j] * (a1_ + ag1)
            s1[j] = 0.0
        else:
            lam0 = -mud[j] * N0[j] * sig[j]
            lam1[j] = -mud[j] * N1[j] * sig[j]
            a0 = -ag0 + lam0 / mass[j]
            a1_ = -ag1 + lam1[j] / mass[j]
            wd1[j] = wd0[j] + 0.5 * h * (a0 + a1_)
            w1[j] = w0[j] + h * wd0[j] + h * h * (2.0 * a0 + a1_) / 6.0
            v1 = 0.0
            if on_struct[j]:
                for i in range(n):
                    v1 += P[j, i] * xd1[i]
            s1[j] = wd1[j] - v1


@_JIT
def _to_physical(psi, eta, etad, q, qd):
    n = psi.shape[0]
    for i in range(n):
        a = 0.0
        b = 0.0
        for k in range(n):
            a += psi[i, k] * eta[k]
            b += psi[i, k] * etad[k]
        q[i] = a
        qd[i] = b


@_JIT
def _to_modal(psitm, q, qd, eta, etad):
    _to_physical(psitm, q, qd, eta, etad)


@_JIT
def _equilibrium_qdd(w2, cd, P, pext_t, q, qd, lam, qdd):
    n = w2.shape[0]
    m = P.shape[0]
    for i in range(n):
        acc = pext_t[i] - cd[i] * qd[i] - w2[i] * q[i]
        for j in range(m):
            acc -= P[j, i] * lam[j]
        qdd[i] = acc


@_JIT
def _energy_substep(h, Eh, psi, nu2, cc, P, eta0, etad0, g0, g1, mass, mud, on_struct, stuck,
                    sig, w0, wd0, ag0, ag1, N0, N1, out, fq, f0, fs):
    """Input, damping and friction work over a sub-step, in closed form.

    Per mode (η̈ + c η̇ + ν² η = g0 + s τ, particular part A + B τ, homogeneous part y):
    ∫ (l0 + l1 τ) η̇ dτ = l0 Δη + l1 (h η(h) - ∫η), with ∫y = -(Δẏ + c Δy)/ν² from the mode
    equation, and c ∫ η̇² = c B² h + 2 c B Δy + x0ᵀ (c W) x0, where W is the 2x2 Gramian
    ∫ e^{Jᵀτ} e2 e2ᵀ e^{Jτ} dτ solved from its Lyapunov equation (written for c W, so that an
    undamped mode gives 0 without dividing by c). Slider terms are polynomials in τ
    (3-point Gauss–Legendre is exact for them). Powers: gᵀη̇ is the structural input (it
    includes the stuck sliders' inertia); the sliding forces inside g are moved to friction.
    """
    n = nu2.shape[0]
    m = mass.shape[0]
    e_in = 0.0
    e_d = 0.0
    e_f = 0.0
    # sliding forces on the structure, λ_j(τ) = l0_j + ls_j τ, as modal loads f0 + fs τ
    r_ = fq.shape[0]
    for i in range(r_):
        fq[i] = 0.0
    for j in range(m):
        if on_struct[j] and not stuck[j]:
            l0 = -mud[j] * N0[j] * sig[j]
            for i in range(r_):
                fq[i] += P[j, i] * l0
    for k in range(n):
        acc = 0.0
        for i in range(r_):
            acc += psi[i, k] * fq[i]
        f0[k] = acc
    for i in range(r_):
        fq[i] = 0.0
    for j in range(m):
        if on_struct[j] and not stuck[j]:
            ls = -mud[j] * (N1[j] - N0[j]) * sig[j] / h
            for i in range(r_):
                fq[i] += P[j, i] * ls
    for k in range(n):
        acc = 0.0
        for i in range(r_):
            acc += psi[i, k] * fq[i]
        fs[k] = acc
    for k in range(n):
        c = cc[k]
        w = nu2[k]
        s = (g1[k] - g0[k]) / h
        B = s / w
        A = (g0[k] - c * B) / w
        y0 = eta0[k] - A
        yd0 = etad0[k] - B
        y1 = Eh[k, 0] * y0 + Eh[k, 1] * yd0
        yd1 = Eh[k, 2] * y0 + Eh[k, 3] * yd0
        eta_h = A + B * h + y1
        d_eta = eta_h - eta0[k]
        int_y = -((yd1 - yd0) + c * (y1 - y0)) / w
        int_eta = A * h + 0.5 * B * h * h + int_y
        mom = h * eta_h - int_eta  # ∫ τ η̇ dτ
        e_in += g0[k] * d_eta + s * mom
        # damping: c ∫ η̇² = c B² h + 2 c B (y1 - y0) + x0ᵀ (cW) x0
        if c != 0.0:
            R11 = Eh[k, 2] * Eh[k, 2]
            R12 = Eh[k, 2] * Eh[k, 3]
            R22 = Eh[k, 3] * Eh[k, 3] - 1.0
            w12 = -R11 / (2.0 * w)
            cw22 = w12 - 0.5 * R22
            cw12 = c * w12
            cw11 = c * R12 + w * cw22 + c * c * w12
            e_d += (c * B * B * h + 2.0 * c * B * (y1 - y0)
                    + cw11 * y0 * y0 + 2.0 * cw12 * y0 * yd0 + cw22 * yd0 * yd0)
        # sliding forces on the structure: their power leaves the input, enters friction
        work = f0[k] * d_eta + fs[k] * mom  # Σ_j ∫ λ_j v_support dτ
        e_in += work
        e_f += work
    for j in range(m):
        if stuck[j]:
            continue  # stuck on the structure: inside g; stuck on the ground: no motion
        l0 = -mud[j] * N0[j] * sig[j]
        l1 = -mud[j] * N1[j] * sig[j]
        a0 = -ag0 + l0 / mass[j]
        for p in range(3):
            x = _GL_X[p]
            tau = x * h
            wgt = _GL_W[p] * h
            ag_t = ag0 + x * (ag1 - ag0)
            lam_t = l0 + x * (l1 - l0)
            wd_t = wd0[j] + 0.5 * tau * (a0 + (-ag_t + lam_t / mass[j]))
            e_in -= wgt * mass[j] * ag_t * wd_t
            e_f -= wgt * lam_t * wd_t
    out[0] = e_in
    out[1] = e_d
    out[2] = e_f


@_JIT
def _cfg_key(stuck, on_struct, key):
    for j in range(stuck.shape[0]):
        key[j] = stuck[j] and on_struct[j]


@_JIT
def run_kernel_exact(
    w2, cd, a1, fixed, P, mass, mus, mud, dt, ag, pext, pat, series, N, q_init, qd_init,
    resume, w_state, wd_state, stuck_state, sig_state, e_state, t_offset,
    track_energy, max_events, max_substeps, cache_size,
    out_q, out_qd, out_qdd, out_w, out_wd, out_lam, out_stuck, out_energy,
    ev_time, ev_slider, ev_kind,
):
    """Integrate ``n_steps = ag.shape[0] - 1`` steps with exact modal propagators.

    Same interface and outputs as ``run_kernel`` (Newmark) except: ``a1`` (C = a1 K) or
    ``fixed`` (no slider on the structure: the basis never changes), the load split
    ``pext = series @ pat`` ((n_t, npat) time series of (npat, n) modal load patterns; ``pext``
    itself is used for the accelerations), and ``cache_size`` (contact configurations kept).
    Returns (status, n_events, n_substeps, n_configs_built).
    """
    n = w2.shape[0]
    m = mass.shape[0]
    n_t = ag.shape[0]
    npat = pat.shape[0]
    on_struct = np.zeros(m, dtype=np.bool_)
    for j in range(m):
        for i in range(n):
            if P[j, i] != 0.0:
                on_struct[j] = True
    # configuration cache
    cap = max(cache_size, 1)
    cfg_key = np.zeros((cap, m), dtype=np.bool_)
    cfg_valid = np.zeros(cap, dtype=np.bool_)
    cfg_stamp = np.zeros(cap, dtype=np.int64)
    c_psi = np.zeros((cap, n, n))
    c_psitm = np.zeros((cap, n, n))
    c_nu2 = np.zeros((cap, n))
    c_cc = np.zeros((cap, n))
    c_gpat = np.zeros((cap, n, npat))
    c_E = np.zeros((cap, n, 4))
    n_built = 0
    stamp = 0
    key = np.zeros(m, dtype=np.bool_)
    # state
    q = q_init.copy()
    qd = qd_init.copy()
    qdd = np.zeros(n)
    wdd = np.zeros(m)
    # slider state at the start of the (sub)step: S0 rows w, wd, lam, s
    S0, stuck, sig, cand, forced, E_in, E_damp, E_fric = _init_sliders(
        4, resume, P, q, qd, w_state, wd_state, stuck_state, sig_state, e_state)
    w, wd, lam, s = S0[0], S0[1], S0[2], S0[3]
    # configuration mass of the stuck set ``key``, kept up to date by rank-one changes
    Ms_key = np.empty((n, n))
    _cfg_key(stuck, on_struct, key)
    _cfg_mass(P, mass, key, Ms_key)
    n_rank1 = 0
    _consistent_cfg(w2, cd, P, mass, mus, mud, on_struct, Ms_key, key, q, qd, ag[0], pext[0],
                    N[0], stuck, sig, cand, forced, qdd, wdd, lam)
    n_ev = _record_events(cand, sig, stuck, sig, t_offset, 0, max_events,
                          ev_time, ev_slider, ev_kind)
    status = STATUS_OK
    _cfg_key(stuck, on_struct, key)
    _cfg_mass(P, mass, key, Ms_key)
    slot, built = _find_config(key, Ms_key, cfg_key, cfg_valid, cfg_stamp, stamp, w2, cd, a1,
                               fixed, pat, dt, c_psi, c_psitm, c_nu2, c_cc, c_gpat, c_E)
    n_built += 1
    T0 = np.empty((3, n))  # eta, etad, g0 (modal loads at the start of a trial)
    eta, etad, g0 = T0[0], T0[1], T0[2]
    _to_modal(c_psitm[slot], q, qd, eta, etad)
    # trial end state and its copy at the bracket's hi end
    T1, S1, Tb, Sb, br, e_lo, e_hi, e_try, tolF, old_stuck, old_sig = _event_buffers(3, n, 4, m)
    eta1, etad1, g1 = T1[0], T1[1], T1[2]
    w1, wd1, lam1, s1 = S1[0], S1[1], S1[2], S1[3]
    etadd = np.empty(n)
    Esub = np.empty((n, 4))
    ework = np.zeros(3)
    Wp = np.empty((3, npat))  # scratch
    ser0, ser1, sere = Wp[0], Wp[1], Wp[2]
    Wn = np.empty((8, n))
    pe_t, x0, x1, xd1, xdd, fq, f0, fs = Wn[0], Wn[1], Wn[2], Wn[3], Wn[4], Wn[5], Wn[6], Wn[7]
    Wm = np.empty((3, m))
    vn, N0, N_e = Wm[0], Wm[1], Wm[2]
    n_sub_total = 0
    _mv(P, qd, vn)
    for j in range(m):
        s[j] = wd[j] - vn[j]

    _write_output(0, q, qd, qdd, w, wd, lam, stuck, mass, w2, track_energy, E_in, E_damp,
                  E_fric, out_q, out_qd, out_qdd, out_w, out_wd, out_lam, out_stuck, out_energy)
    for step in range(n_t - 1):
        tau = 0.0
        n_sub = 0
        while True:
            nu2 = c_nu2[slot]
            cc = c_cc[slot]
            psi = c_psi[slot]
            gpat = c_gpat[slot]
            if n_sub >= max_substeps:
                status = STATUS_SUBSTEP_LIMIT
                break
            full = tau == 0.0
            hrem = (1.0 - tau) * dt
            ag0 = _sample(ag, series, N, step, tau, ser0, N0)
            for c in range(npat):
                ser1[c] = series[step + 1, c]
            ag1 = ag[step + 1]
            if full:
                Eh = c_E[slot]
            else:
                _mode_matrices(nu2, cc, hrem, Esub)
                Eh = Esub
            _trial_exact(hrem, Eh, psi, nu2, cc, P, gpat, mass, mud, on_struct,
                         stuck, sig, eta, etad, w, wd, ser0, ser1, ag0, ag1, N0, N[step + 1],
                         g0, g1, eta1, etad1, w1, wd1, lam1, s1, etadd, x0, x1, xd1, xdd, fq)
            any_ev = _detect(stuck, sig, mus, mud, mass, N[step], N[step + 1], lam1, wd1, s1,
                             dt, tolF, e_hi)
            theta_hi = 1.0
            if any_ev:
                _bracket_start(br, stuck, sig, lam, N0, s, mus, e_lo, T1, S1, Tb, Sb)
                for _it in range(100):
                    th = _propose(br, stuck, e_lo, e_hi, tolF, mus, N[step + 1], hrem, dt)
                    if th < 0.0:
                        break
                    hsub = th * hrem
                    _mode_matrices(nu2, cc, hsub, Esub)
                    ag_e = _sample(ag, series, N, step, tau + th * (1.0 - tau), sere, N_e)
                    _trial_exact(hsub, Esub, psi, nu2, cc, P, gpat, mass, mud,
                                 on_struct, stuck, sig, eta, etad, w, wd, ser0, sere, ag0, ag_e,
                                 N0, N_e, g0, g1, eta1, etad1, w1, wd1, lam1, s1, etadd,
                                 x0, x1, xd1, xdd, fq)
                    _accept_trial(br, th, stuck, sig, lam1, N_e, s1, mus, tolF, e_try,
                                  e_lo, e_hi, T1, S1, Tb, Sb)
                # g0 was overwritten by identical values (same start state) in every trial
                theta_hi = _bracket_end(br, T1, S1, Tb, Sb)
            tau_end = _substep_end(tau, theta_hi, any_ev)
            h_acc = (tau_end - tau) * dt
            n_sub += 1
            n_sub_total += 1
            if track_energy:
                if full and tau_end >= 1.0:
                    Eacc = c_E[slot]
                else:
                    _mode_matrices(nu2, cc, h_acc, Esub)
                    Eacc = Esub
                ag_b = _sample(ag, pext, N, step, tau_end, pe_t, N_e)
                _energy_substep(h_acc, Eacc, psi, nu2, cc, P, eta, etad, g0, g1, mass, mud,
                                on_struct, stuck, sig, w, wd, ag0, ag_b, N0, N_e, ework,
                                fq, f0, fs)
                E_in += ework[0]
                E_damp += ework[1]
                E_fric += ework[2]
            T0[:] = T1  # g0 <- g1: harmless, every trial recomputes g0
            S0[:] = S1
            if tau_end >= 1.0:
                break
            # --- transition at t_e = (step + tau_end) dt (§5)
            ag_e = _sample(ag, pext, N, step, tau_end, pe_t, N_e)
            _to_physical(c_psi[slot], eta, etad, q, qd)
            _mv(P, qd, vn)
            _classify(stuck, sig, lam, s, wd, vn, mus, N_e, tolF, e_try, old_stuck, old_sig,
                      cand, forced)
            _consistent_cfg(w2, cd, P, mass, mus, mud, on_struct, Ms_key, key, q, qd, ag_e,
                            pe_t, N_e, stuck, sig, cand, forced, qdd, wdd, lam)
            for j in range(m):
                s[j] = wd[j] - vn[j]
            n_ev = _record_events(old_stuck, old_sig, stuck, sig,
                                  t_offset + (step + tau_end) * dt, n_ev, max_events,
                                  ev_time, ev_slider, ev_kind)
            changed = False
            for j in range(m):
                if on_struct[j] and stuck[j] != old_stuck[j]:
                    changed = True
            if changed:
                stamp += 1
                for j in range(m):
                    now = stuck[j] and on_struct[j]
                    if now != key[j]:
                        _rank1(Ms_key, P[j], mass[j] if now else -mass[j])
                        n_rank1 += 1
                        key[j] = now
                if n_rank1 > 1000:  # bound the round-off of many rank-one updates
                    _cfg_mass(P, mass, key, Ms_key)
                    n_rank1 = 0
                slot, built = _find_config(key, Ms_key, cfg_key, cfg_valid, cfg_stamp, stamp,
                                           w2, cd, a1, fixed, pat, dt, c_psi, c_psitm, c_nu2,
                                           c_cc, c_gpat, c_E)
                if built:
                    n_built += 1
                _to_modal(c_psitm[slot], q, qd, eta, etad)
            tau = tau_end
        if status != STATUS_OK:
            break
        k = step + 1
        _to_physical(c_psi[slot], eta, etad, q, qd)
        for i in range(n):
            pe_t[i] = pext[k, i]
        _equilibrium_qdd(w2, cd, P, pe_t, q, qd, lam, qdd)
        status = _write_output(k, q, qd, qdd, w, wd, lam, stuck, mass, w2, track_energy, E_in,
                               E_damp, E_fric, out_q, out_qd, out_qdd, out_w, out_wd, out_lam,
                               out_stuck, out_energy)
        if status != STATUS_OK:
            break
    status = _finish(status, n_ev, max_events, w, wd, stuck, sig, E_in, E_damp, E_fric,
                     w_state, wd_state, stuck_state, sig_state, e_state)
    return status, n_ev, n_sub_total, n_built
