"""Exact-propagator stick–slip kernel (source shared by the numba and pure-Python backends).

Loaded after ``_events.py``, ``_kernel.py``, ``_exact_modes.py`` and ``_exact_config.py`` in
the same namespace (see :mod:`seisrack.dynamics.kernels`): it reuses the event core
(detection, location, transitions, output), ``_mv``, the modal propagators and the
configuration handling from them; this part holds the trial step and the main loop.

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
        _bracket_end,
        _bracket_start,
        _classify,
        _detect,
        _event_buffers,
        _finish,
        _init_sliders,
        _propose,
        _record_events,
        _sample,
        _substep_end,
        _write_output,
    )
    from seisrack.dynamics._exact_config import (
        _cfg_key,
        _cfg_mass,
        _consistent_cfg,
        _find_config,
        _rank1,
    )
    from seisrack.dynamics._exact_modes import _energy_substep, _mode_matrices, _propagate
    from seisrack.dynamics._linalg import _mv

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
