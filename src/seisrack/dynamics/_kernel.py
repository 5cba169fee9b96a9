"""Stick–slip time-stepping kernel (source shared by the numba and pure-Python backends).

This file is loaded twice by :mod:`seisrack.dynamics.kernels`: once with ``_JIT`` bound to
``numba.njit`` and once with the identity, so the compiled kernel and its pure-Python twin are
the *same source*. Only numpy operations supported by numba's nopython mode are used.

Formulation (see ``docs/theory/stick_slip_engine.md``):

* The structure is written in mass-normalised modal coordinates ``q`` (``u = Φ q``), so its mass
  matrix is the identity; stiffness ``kd`` and (classical) damping ``cd`` are diagonal. A dense
  damping matrix ``Cq`` is supported when damping is not classical.
* Slider ``j`` rests on physical DOF ``dof_j``; ``P = Φ[dof, :]`` maps modal coordinates to the
  support displacement, ``P.T @ lam`` maps slider forces back.
* Newmark average acceleration (β = 1/4, γ = 1/2). Within one (sub)step the contact state is
  fixed: stuck sliders satisfy zero relative velocity at the end of the step, sliding sliders carry
  ``lam = -mu_d N sign(s)``. The stuck forces solve a small SPD system ``A_SS lam_S = -b_S``.
* Transitions are located *inside* the step: an event function per slider (``|lam| - mu_s N`` for
  stuck sliders, ``-sigma s`` for sliding ones) is driven to zero by Illinois regula falsi
  (bisection safeguard) on the sub-step length, the step is split there, and the new contact
  state is decided at the acceleration level (active set on ``B = diag(1/m) + P P^T``).
"""

# ruff: noqa: N803, N806  (matrix names follow the equations)

import numpy as np

try:  # injected by the loader; identity when this file is imported directly
    _JIT  # type: ignore[used-before-def]  # noqa: B018
except NameError:  # pragma: no cover

    def _JIT(f):  # type: ignore[no-redef]
        return f


KIND_SLIP = 0
KIND_STICK = 1
KIND_REVERSE = 2

STATUS_OK = 0
STATUS_EVENT_OVERFLOW = 1
STATUS_SUBSTEP_LIMIT = 2
STATUS_NONFINITE = 3


@_JIT
def _solve(A, B):
    """Solve A X = B by Gaussian elimination with partial pivoting; A (k, k), B (k, r).

    Hand-written (instead of np.linalg) to keep numba compile times short; k is small here
    (number of stuck sliders) or the modal size for non-classical damping only.
    """
    k = A.shape[0]
    r = B.shape[1]
    a = A.copy()
    x = B.copy()
    for c in range(k):
        piv = c
        big = abs(a[c, c])
        for i in range(c + 1, k):
            if abs(a[i, c]) > big:
                big = abs(a[i, c])
                piv = i
        if piv != c:
            for j in range(k):
                tmp = a[c, j]
                a[c, j] = a[piv, j]
                a[piv, j] = tmp
            for j in range(r):
                tmp = x[c, j]
                x[c, j] = x[piv, j]
                x[piv, j] = tmp
        d = a[c, c]
        for i in range(c + 1, k):
            f = a[i, c] / d
            if f != 0.0:
                for j in range(c, k):
                    a[i, j] -= f * a[c, j]
                for j in range(r):
                    x[i, j] -= f * x[c, j]
    for c in range(k - 1, -1, -1):
        for j in range(r):
            acc = x[c, j]
            for i in range(c + 1, k):
                acc -= a[c, i] * x[i, j]
            x[c, j] = acc / a[c, c]
    return x


@_JIT
def _mm_pt(A, P):
    """A @ P.T for A (k, n), P (m, n): shape (k, m)."""
    k = A.shape[0]
    m = P.shape[0]
    n = P.shape[1]
    out = np.empty((k, m))
    for i in range(k):
        for j in range(m):
            acc = 0.0
            for t in range(n):
                acc += A[i, t] * P[j, t]
            out[i, j] = acc
    return out


@_JIT
def _interp(x0, x1, theta):
    return x0 + theta * (x1 - x0)


@_JIT
def _modal_solve(kd, cd, Cq, diag, h, rhs, out):
    """Solve (K + 2/h C + 4/h^2 I) x = rhs for x (mass is identity in modal coordinates)."""
    n = kd.shape[0]
    if diag:
        for i in range(n):
            out[i] = rhs[i] / (kd[i] + 2.0 / h * cd[i] + 4.0 / (h * h))
    else:
        Kh = (2.0 / h) * Cq.copy()
        for i in range(n):
            Kh[i, i] += kd[i] + 4.0 / (h * h)
        x = _solve(Kh, rhs.reshape((n, 1)))
        for i in range(n):
            out[i] = x[i, 0]


@_JIT
def _hmat_pt(kd, cd, Cq, diag, h, P):
    """Return H P^T, with H = (K + 2/h C + 4/h^2 I)^-1: shape (n, m)."""
    n = kd.shape[0]
    m = P.shape[0]
    if diag:
        HPt = np.empty((n, m))
        for i in range(n):
            hi = 1.0 / (kd[i] + 2.0 / h * cd[i] + 4.0 / (h * h))
            for j in range(m):
                HPt[i, j] = hi * P[j, i]
        return HPt
    Kh = (2.0 / h) * Cq.copy()
    for i in range(n):
        Kh[i, i] += kd[i] + 4.0 / (h * h)
    return _solve(Kh, np.ascontiguousarray(P.T))


@_JIT
def _damp_mul(cd, Cq, diag, x, out):
    if diag:
        for i in range(x.shape[0]):
            out[i] = cd[i] * x[i]
    else:
        _mv(Cq, x, out)


@_JIT
def _mv(A, x, out):
    """out = A @ x with explicit loops (faster than BLAS for the small sizes used per step)."""
    for i in range(A.shape[0]):
        acc = 0.0
        for k in range(A.shape[1]):
            acc += A[i, k] * x[k]
        out[i] = acc


@_JIT
def _trial(
    h, kd, cd, Cq, diag, P, HPt, G, mass, mud, q0, qd0, qdd0, w0, wd0, wdd0,
    ag1, pext1, N1, stuck, sig, Ainv_cache, cache_ok,
    q1, qd1, qdd1, w1, wd1, wdd1, lam1, s1, tmp, rhs, qhat, vnode, b, f,
):
    """One Newmark step of length h with a fixed contact state; writes the end state.

    ``HPt`` (n, m) and ``G = P H P^T`` (m, m) must correspond to ``h``. When ``cache_ok`` is true,
    ``Ainv_cache`` holds the inverse of the stuck-stuck block of A for the current stuck set.
    Returns True when it (re)computed the inverse into ``Ainv_cache``.
    """
    n = kd.shape[0]
    m = mass.shape[0]
    c0 = 4.0 / (h * h)
    c1 = 4.0 / h
    c2 = 2.0 / h
    # incremental form: K_hat dq = p1 - K q0 + C qd0 + (4/h) qd0 + qdd0 (no cancellation for
    # short sub-steps, where 4/h^2 would amplify the round-off of q0)
    _damp_mul(cd, Cq, diag, qd0, rhs)
    for i in range(n):
        rhs[i] += pext1[i] - kd[i] * q0[i] + c1 * qd0[i] + qdd0[i]
    _modal_solve(kd, cd, Cq, diag, h, rhs, qhat)  # qhat holds the free increment
    # support velocity of the "free" (lam = 0) prediction
    for i in range(n):
        tmp[i] = c2 * qhat[i] - qd0[i]
    _mv(P, tmp, vnode)
    for j in range(m):
        b[j] = wd0[j] + 0.5 * h * (wdd0[j] - ag1) - vnode[j]
    # sliding forces are known
    n_stuck = 0
    for j in range(m):
        if stuck[j]:
            n_stuck += 1
            lam1[j] = 0.0
        else:
            lam1[j] = -mud[j] * N1[j] * sig[j]
    recomputed = False
    if n_stuck > 0:
        idx = np.empty(n_stuck, dtype=np.int64)
        k = 0
        for j in range(m):
            if stuck[j]:
                idx[k] = j
                k += 1
        rhs_s = np.empty(n_stuck)
        for a in range(n_stuck):
            ja = idx[a]
            acc = b[ja]
            for j in range(m):
                if not stuck[j]:
                    acc += c2 * G[ja, j] * lam1[j]
            rhs_s[a] = -acc
        if not cache_ok:
            Ass = np.empty((n_stuck, n_stuck))
            for a in range(n_stuck):
                for c in range(n_stuck):
                    Ass[a, c] = c2 * G[idx[a], idx[c]]
                Ass[a, a] += 0.5 * h / mass[idx[a]]
            Ainv_cache[:n_stuck, :n_stuck] = _solve(Ass, np.eye(n_stuck))
            recomputed = True
        for a in range(n_stuck):
            acc = 0.0
            for c in range(n_stuck):
                acc += Ainv_cache[a, c] * rhs_s[c]
            lam1[idx[a]] = acc
    # structure end state
    _mv(HPt, lam1, f)
    for i in range(n):
        dq = qhat[i] - f[i]
        q1[i] = q0[i] + dq
        qd1[i] = c2 * dq - qd0[i]
        qdd1[i] = c0 * dq - c1 * qd0[i] - qdd0[i]
    _mv(P, qd1, vnode)
    vn = vnode
    for j in range(m):
        wdd1[j] = -ag1 + lam1[j] / mass[j]
        wd1[j] = wd0[j] + 0.5 * h * (wdd0[j] + wdd1[j])
        w1[j] = w0[j] + h * wd0[j] + 0.25 * h * h * (wdd0[j] + wdd1[j])
        if stuck[j]:
            # exact zero relative velocity (removes round-off drift)
            wd1[j] = vn[j]
        s1[j] = wd1[j] - vn[j]
    return recomputed


@_JIT
def _event_values(stuck, sig, lam, N, s, mus, e):
    """Event functions, positive when the current contact state is violated."""
    for j in range(stuck.shape[0]):
        if stuck[j]:
            e[j] = abs(lam[j]) - mus[j] * N[j]
        else:
            e[j] = -sig[j] * s[j]


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
    for j in range(m):
        if cand[j]:
            stuck[j] = True
        elif forced[j]:
            stuck[j] = False
    for _it in range(2 * m + 2):
        n_stuck = 0
        for j in range(m):
            if stuck[j]:
                n_stuck += 1
            else:
                lam[j] = -mud[j] * N[j] * sig[j]
        if n_stuck > 0:
            idx = np.empty(n_stuck, dtype=np.int64)
            k = 0
            for j in range(m):
                if stuck[j]:
                    idx[k] = j
                    k += 1
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
        worst = -1
        worst_ratio = 1.0 + 1e-12
        for j in range(m):
            if stuck[j] and not forced[j]:
                cap = mus[j] * N[j]
                if cap <= 0.0:
                    ratio = np.inf if lam[j] != 0.0 else 0.0
                else:
                    ratio = abs(lam[j]) / cap
                if ratio > worst_ratio:
                    worst_ratio = ratio
                    worst = j
        if worst < 0:
            break
        stuck[worst] = False
        sig[worst] = -1.0 if lam[worst] > 0.0 else 1.0
    ptl = np.empty(n)
    _mv(np.ascontiguousarray(P.T), lam, ptl)
    for i in range(n):
        qdd[i] = base[i] - ptl[i]
    for j in range(m):
        wdd[j] = -ag + lam[j] / mass[j]


@_JIT
def run_kernel(
    kd, cd, Cq, diag, P, mass, mus, mud, dt, ag, pext, N, q_init, qd_init,
    resume, w_state, wd_state, stuck_state, sig_state, e_state, t_offset,
    track_energy, max_events, max_substeps,
    out_q, out_qd, out_qdd, out_w, out_wd, out_lam, out_stuck, out_energy,
    ev_time, ev_slider, ev_kind,
):
    """Integrate ``n_steps = ag.shape[0] - 1`` steps. Returns (status, n_events, n_substeps).

    Resumable: with ``resume`` the sliders start from ``w_state, wd_state, stuck_state,
    sig_state`` and the cumulative energies from ``e_state`` (input, damping, friction);
    otherwise they start stuck on their supports. On return these arrays hold the final state,
    so a long run can be split into chunks (for progress reporting) without changing the result.
    ``t_offset`` [s] is added to event times.

    ag: (n_t,) ground acceleration at grid points; pext: (n_t, n) modal external load
    (``Φ^T (F - M r a_g)``); N: (n_t, m) normal force of each slider.
    out_energy columns: input, kinetic, strain, damping, friction dissipation (cumulative).
    """
    n = kd.shape[0]
    m = mass.shape[0]
    n_t = ag.shape[0]
    # operators for the regular step
    HPt_dt = _hmat_pt(kd, cd, Cq, diag, dt, P)
    G_dt = _mm_pt(P, np.ascontiguousarray(HPt_dt.T))
    B = _mm_pt(P, P)
    for j in range(m):
        B[j, j] += 1.0 / mass[j]
    # state
    q = q_init.copy()
    qd = qd_init.copy()
    qdd = np.zeros(n)
    wdd = np.zeros(m)
    lam = np.zeros(m)
    forced = np.zeros(m, dtype=np.bool_)
    if resume:
        w = w_state.copy()
        wd = wd_state.copy()
        stuck = stuck_state.copy()
        sig = sig_state.copy()
        E_in = e_state[0]
        E_damp = e_state[1]
        E_fric = e_state[2]
    else:
        w = np.empty(m)
        wd = np.empty(m)
        _mv(P, q, w)
        _mv(P, qd, wd)
        stuck = np.ones(m, dtype=np.bool_)
        sig = np.ones(m)
        E_in = 0.0
        E_damp = 0.0
        E_fric = 0.0
    cand = stuck.copy()
    _consistent(kd, cd, Cq, diag, P, B, mass, mus, mud, q, qd, ag[0], pext[0], N[0],
                stuck, sig, cand, forced, qdd, wdd, lam)
    n_ev = 0
    status = STATUS_OK
    for j in range(m):
        if cand[j] and not stuck[j]:
            if n_ev < max_events:
                ev_time[n_ev] = t_offset
                ev_slider[n_ev] = j
                ev_kind[n_ev] = KIND_SLIP
            n_ev += 1
    # buffers
    q1 = np.empty(n)
    qd1 = np.empty(n)
    qdd1 = np.empty(n)
    w1 = np.empty(m)
    wd1 = np.empty(m)
    wdd1 = np.empty(m)
    lam1 = np.empty(m)
    s1 = np.empty(m)
    qb = np.empty(n)
    qdb = np.empty(n)
    qddb = np.empty(n)
    wb = np.empty(m)
    wdb = np.empty(m)
    wddb = np.empty(m)
    lamb = np.empty(m)
    sb = np.empty(m)
    e_lo = np.empty(m)
    e_hi = np.empty(m)
    e_try = np.empty(m)
    tolF = np.empty(m)
    Ainv = np.zeros((m, m))
    cache_ok = False
    pe0 = np.empty(n)
    pe1 = np.empty(n)
    tmpn = np.empty(n)
    tmpn2 = np.empty(n)
    n_sub_total = 0
    wk_t = np.empty(n)
    wk_r = np.empty(n)
    wk_q = np.empty(n)
    wk_f = np.empty(n)
    wk_v = np.empty(m)
    wk_b = np.empty(m)
    s0 = np.empty(m)
    vn0 = np.empty(m)
    N_lo = np.empty(m)

    # save initial point
    out_q[0, :] = q
    out_qd[0, :] = qd
    out_qdd[0, :] = qdd
    out_w[0, :] = w
    out_wd[0, :] = wd
    out_lam[0, :] = lam
    for j in range(m):
        out_stuck[0, j] = stuck[j]
    if track_energy:
        ke = 0.5 * np.dot(qd, qd)
        for j in range(m):
            ke += 0.5 * mass[j] * wd[j] * wd[j]
        se = 0.0
        for i in range(n):
            se += 0.5 * kd[i] * q[i] * q[i]
        out_energy[0, 0] = E_in
        out_energy[0, 1] = ke
        out_energy[0, 2] = se
        out_energy[0, 3] = E_damp
        out_energy[0, 4] = E_fric
    for step in range(n_t - 1):
        tau = 0.0  # fraction of the step already integrated
        n_sub = 0
        while True:
            n_sub += 1
            if n_sub > max_substeps:
                status = STATUS_SUBSTEP_LIMIT
                break
            full = tau == 0.0
            hrem = (1.0 - tau) * dt
            # end-of-trial excitation (grid value at the end of the step)
            for i in range(n):
                pe1[i] = pext[step + 1, i]
            ag1 = ag[step + 1]
            if full:
                recomputed = _trial(
                    dt, kd, cd, Cq, diag, P, HPt_dt, G_dt, mass, mud, q, qd, qdd, w, wd, wdd,
                    ag1, pe1, N[step + 1], stuck, sig, Ainv, cache_ok,
                    q1, qd1, qdd1, w1, wd1, wdd1, lam1, s1, wk_t, wk_r, wk_q, wk_v, wk_b, wk_f,
                )
                if recomputed:
                    cache_ok = True
            else:
                HPt = _hmat_pt(kd, cd, Cq, diag, hrem, P)
                G = _mm_pt(P, np.ascontiguousarray(HPt.T))
                _trial(
                    hrem, kd, cd, Cq, diag, P, HPt, G, mass, mud, q, qd, qdd, w, wd, wdd,
                    ag1, pe1, N[step + 1], stuck, sig, Ainv, False,
                    q1, qd1, qdd1, w1, wd1, wdd1, lam1, s1, wk_t, wk_r, wk_q, wk_v, wk_b, wk_f,
                )
                cache_ok = False
            # event detection at the end of the trial (end values only; the start values are
            # needed only when an event must be located)
            any_ev = False
            for j in range(m):
                n1 = N[step + 1, j]
                if stuck[j]:
                    tolF[j] = 1e-11 * mus[j] * max(N[step, j], n1) + 1e-300
                    e_hi[j] = abs(lam1[j]) - mus[j] * n1
                else:
                    # a reversal/stick must be a real sign change of the relative velocity, not
                    # round-off around zero just after a slip onset with mu_d = mu_s
                    vscale = abs(wd1[j]) + abs(wd1[j] - s1[j]) + mud[j] * n1 / mass[j] * dt
                    tolF[j] = 1e-9 * vscale
                    e_hi[j] = -sig[j] * s1[j]
                if e_hi[j] > tolF[j]:
                    any_ev = True
            if any_ev:
                _mv(P, qd, vn0)
                for j in range(m):
                    s0[j] = wd[j] - vn0[j]
                    N_lo[j] = N[step, j] + tau * (N[step + 1, j] - N[step, j])
                _event_values(stuck, sig, lam, N_lo, s0, mus, e_lo)
            theta_hi = 1.0  # fractions of the remaining sub-step
            if any_ev:
                # Illinois regula falsi on the earliest violated event function (bisection if it
                # stalls). ``e_lo`` and ``e_hi`` always hold the true event values at the bracket
                # ends; the Illinois weights only enter the interpolation.
                theta_lo = 0.0
                streak = 0
                side = 0
                sc_lo = 1.0  # Illinois weights (interpolation only, never the violation test)
                sc_hi = 1.0
                # the hi state is the current trial
                qb[:] = q1
                qdb[:] = qd1
                qddb[:] = qdd1
                wb[:] = w1
                wdb[:] = wd1
                wddb[:] = wdd1
                lamb[:] = lam1
                sb[:] = s1
                for _it in range(100):
                    # earliest crossing by linear interpolation
                    th = theta_hi
                    jmin = -1
                    for j in range(m):
                        if e_hi[j] > tolF[j]:
                            # root of e - tolF (the violation threshold), not of e: a slider that
                            # just slipped starts at e = 0 and creeps up quadratically
                            elo = min(e_lo[j] - tolF[j], 0.0) * sc_lo
                            den = (e_hi[j] - tolF[j]) * sc_hi - elo
                            frac = -elo / den if den > 0.0 else 0.0
                            tj = theta_lo + frac * (theta_hi - theta_lo)
                            if tj < th or jmin < 0:
                                th = tj
                                jmin = j
                    if jmin < 0:
                        break
                    # convergence: the violated function is tiny at hi
                    if stuck[jmin]:
                        conv = e_hi[jmin] <= 1e-10 * mus[jmin] * N[step + 1, jmin] + tolF[jmin]
                    else:
                        conv = e_hi[jmin] <= 2.0 * tolF[jmin]
                    span = theta_hi - theta_lo
                    if conv or span * hrem <= 1e-12 * dt:
                        break
                    if streak >= 6:  # safeguard: Illinois stalled, bisect
                        th = theta_lo + 0.5 * span
                        streak = 0
                    # keep strictly inside the bracket
                    if th <= theta_lo + 1e-6 * span:
                        th = theta_lo + 1e-6 * span
                    if th >= theta_hi - 1e-6 * span:
                        th = theta_hi - 1e-6 * span
                    hsub = th * hrem
                    frac_end = tau + th * (1.0 - tau)
                    for i in range(n):
                        tmpn[i] = _interp(pext[step, i], pext[step + 1, i], frac_end)
                    ag_e = _interp(ag[step], ag[step + 1], frac_end)
                    N_e = N[step] + frac_end * (N[step + 1] - N[step])
                    HPt = _hmat_pt(kd, cd, Cq, diag, hsub, P)
                    G = _mm_pt(P, np.ascontiguousarray(HPt.T))
                    _trial(
                        hsub, kd, cd, Cq, diag, P, HPt, G, mass, mud, q, qd, qdd, w, wd, wdd,
                        ag_e, tmpn, N_e, stuck, sig, Ainv, False,
                        q1, qd1, qdd1, w1, wd1, wdd1, lam1, s1, wk_t, wk_r, wk_q, wk_v, wk_b, wk_f,
                    )
                    cache_ok = False
                    _event_values(stuck, sig, lam1, N_e, s1, mus, e_try)
                    viol_try = False
                    for j in range(m):
                        if e_try[j] > tolF[j]:
                            viol_try = True
                    if viol_try:
                        theta_hi = th
                        e_hi[:] = e_try
                        qb[:] = q1
                        qdb[:] = qd1
                        qddb[:] = qdd1
                        wb[:] = w1
                        wdb[:] = wd1
                        wddb[:] = wdd1
                        lamb[:] = lam1
                        sb[:] = s1
                        streak = streak + 1 if side == 1 else 1
                        if side == 1:
                            sc_lo *= 0.5  # lo kept twice: halve its weight
                        sc_hi = 1.0
                        side = 1
                    else:
                        theta_lo = th
                        e_lo[:] = e_try
                        streak = streak + 1 if side == -1 else 1
                        if side == -1:
                            sc_hi *= 0.5  # hi kept twice: halve its weight
                        sc_lo = 1.0
                        side = -1
                # accept the (tiny-violation) hi state
                q1[:] = qb
                qd1[:] = qdb
                qdd1[:] = qddb
                w1[:] = wb
                wd1[:] = wdb
                wdd1[:] = wddb
                lam1[:] = lamb
                s1[:] = sb
            # --- accept the sub-step [tau, tau_end]
            tau_end = tau + theta_hi * (1.0 - tau)
            if any_ev and theta_hi < 1.0:
                frac_end = tau_end
            else:
                frac_end = 1.0
                tau_end = 1.0
            n_sub_total += 1
            if track_energy:
                for i in range(n):
                    pe0[i] = _interp(pext[step, i], pext[step + 1, i], tau)
                    pe1[i] = _interp(pext[step, i], pext[step + 1, i], frac_end)
                ag_a = _interp(ag[step], ag[step + 1], tau)
                ag_b = _interp(ag[step], ag[step + 1], frac_end)
                for i in range(n):
                    tmpn[i] = qd[i] + qd1[i]
                _damp_mul(cd, Cq, diag, tmpn, tmpn2)
                dq_in = 0.0
                dd = 0.0
                for i in range(n):
                    dqi = q1[i] - q[i]
                    dq_in += dqi * 0.5 * (pe0[i] + pe1[i])
                    dd += dqi * 0.5 * tmpn2[i]
                for i in range(n):
                    tmpn[i] = q1[i] - q[i]
                _mv(P, tmpn, wk_v)
                for j in range(m):
                    dwj = w1[j] - w[j]
                    dq_in -= mass[j] * dwj * 0.5 * (ag_a + ag_b)
                    E_fric -= 0.5 * (lam[j] + lam1[j]) * (dwj - wk_v[j])
                E_in += dq_in
                E_damp += dd
            q[:] = q1
            qd[:] = qd1
            qdd[:] = qdd1
            w[:] = w1
            wd[:] = wd1
            wdd[:] = wdd1
            lam[:] = lam1
            if frac_end >= 1.0:
                if not full:
                    # a short final sub-step amplifies round-off in the Newmark acceleration
                    # update; restore accelerations from equilibrium (same forces lam)
                    for i in range(n):
                        tmpn[i] = pext[step + 1, i]
                    _accel_fixed(kd, cd, Cq, diag, P, mass, q, qd, ag[step + 1], tmpn, lam,
                                 qdd, wdd)
                break
            # --- transition at t_e = (step + tau_end) dt
            t_e = t_offset + (step + tau_end) * dt
            ag_e = _interp(ag[step], ag[step + 1], tau_end)
            for i in range(n):
                tmpn[i] = _interp(pext[step, i], pext[step + 1, i], tau_end)
            N_e = N[step] + tau_end * (N[step + 1] - N[step])
            _event_values(stuck, sig, lam, N_e, s1, mus, e_try)
            old_stuck = stuck.copy()
            old_sig = sig.copy()
            vn = np.empty(m)
            _mv(P, qd, vn)
            for j in range(m):
                cand[j] = False
                forced[j] = False
                if old_stuck[j]:
                    if e_try[j] > -1e-7 * mus[j] * N_e[j] - tolF[j]:
                        forced[j] = True  # slip onset
                        sig[j] = -1.0 if lam[j] > 0.0 else 1.0
                    else:
                        cand[j] = True  # stays at zero relative velocity
                else:
                    vs = abs(wd[j]) + abs(vn[j]) + 1e-30
                    if e_try[j] > -1e-9 * vs:
                        cand[j] = True  # relative velocity reached zero
                        wd[j] = vn[j]
            _consistent(kd, cd, Cq, diag, P, B, mass, mus, mud, q, qd, ag_e, tmpn, N_e,
                        stuck, sig, cand, forced, qdd, wdd, lam)
            cache_ok = False
            for j in range(m):
                kind = -1
                if old_stuck[j] and not stuck[j]:
                    kind = KIND_SLIP
                elif (not old_stuck[j]) and stuck[j]:
                    kind = KIND_STICK
                elif (not old_stuck[j]) and (not stuck[j]) and sig[j] != old_sig[j]:
                    kind = KIND_REVERSE
                if kind >= 0:
                    if n_ev < max_events:
                        ev_time[n_ev] = t_e
                        ev_slider[n_ev] = j
                        ev_kind[n_ev] = kind
                    n_ev += 1
            tau = tau_end
        if status != STATUS_OK:
            break
        k = step + 1
        out_q[k, :] = q
        out_qd[k, :] = qd
        out_qdd[k, :] = qdd
        out_w[k, :] = w
        out_wd[k, :] = wd
        out_lam[k, :] = lam
        for j in range(m):
            out_stuck[k, j] = stuck[j]
        if track_energy:
            ke = 0.5 * np.dot(qd, qd)
            for j in range(m):
                ke += 0.5 * mass[j] * wd[j] * wd[j]
            se = 0.0
            for i in range(n):
                se += 0.5 * kd[i] * q[i] * q[i]
            out_energy[k, 0] = E_in
            out_energy[k, 1] = ke
            out_energy[k, 2] = se
            out_energy[k, 3] = E_damp
            out_energy[k, 4] = E_fric
        if not np.isfinite(q[0]):
            status = STATUS_NONFINITE
            break
    if n_ev > max_events and status == STATUS_OK:
        status = STATUS_EVENT_OVERFLOW
    w_state[:] = w
    wd_state[:] = wd
    stuck_state[:] = stuck
    sig_state[:] = sig
    e_state[0] = E_in
    e_state[1] = E_damp
    e_state[2] = E_fric
    return status, n_ev, n_sub_total
