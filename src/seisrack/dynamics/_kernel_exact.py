"""Exact-propagator stick–slip kernel (source shared by the numba and pure-Python backends).

Loaded after ``_events.py``, ``_kernel.py``, ``_exact_modes.py`` and ``_exact_config.py`` in
the same namespace (see :mod:`seisrack.dynamics.kernels`): it reuses the event core
(detection, location, transitions, output), ``_mv``, the modal propagators and the trial
step, and the configuration handling from them; this part holds the output of a step and the
main loop.

Performance note: a call from one compiled function to another costs an atomic reference
count increment and decrement per array argument, unless numba can prune them: the callee
must be a leaf whose arrays all die in its exit block, and must not be inlined by LLVM (an
inlined call keeps them). So the per-step functions (``_trial_exact``, ``_energy_substep``,
``_step_output``) are leaves written that way, ``_trial_exact`` (which LLVM inlines) takes
its ~35 vectors packed into 16 arrays, and the loop creates no array view per step: at
r = 8 a step went from ~2 µs to ~0.55 µs, with bitwise the same results.

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
    from seisrack.dynamics._contact import _cfg_key, _cfg_mass, _cfg_update
    from seisrack.dynamics._events import (
        _JIT,
        STATUS_NONFINITE,
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
    from seisrack.dynamics._exact_config import _consistent_cfg, _find_config
    from seisrack.dynamics._exact_modes import _energy_substep, _mode_matrices, _trial_exact
    from seisrack.dynamics._linalg import _mv

@_JIT
def _load_config(slot, c_psi, c_nu2, c_cc, PS, NC):
    """PS = (Ψ, Ψᵀ), NC = (ν², c) of the cached configuration ``slot`` (copies)."""
    n = NC.shape[1]
    for i in range(n):
        NC[0, i] = c_nu2[slot, i]
        NC[1, i] = c_cc[slot, i]
        for k in range(n):
            PS[0, i, k] = c_psi[slot, i, k]
            PS[1, k, i] = c_psi[slot, i, k]


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
def _step_output(k, w2, cd, P, series, pat, x, xd, q, qd, qdd, w, wd, lam, stuck, mass,
                 track_energy, E_in, E_damp, E_fric, out_q, out_qd, out_qdd, out_w, out_wd,
                 out_lam, out_stuck, out_energy):
    """End of step ``k``: q = Ψ η and q̇ = Ψ η̇ (``x``, ``xd``, from the last sub-step),
    q̈ from equilibrium (the load ``series[k] @ pat``) and the output row (as
    ``_write_output``) in one leaf (see ``_trial_exact``); the kinetic energy's q̇ᵀq̇ is
    summed in index order."""
    n = w2.shape[0]
    m = P.shape[0]
    npat = pat.shape[0]
    for i in range(n):
        q[i] = x[i]
        qd[i] = xd[i]
    for i in range(n):
        acc = 0.0
        for c in range(npat):
            acc += series[k, c] * pat[c, i]
        acc += -cd[i] * qd[i] - w2[i] * q[i]
        for j in range(m):
            acc -= P[j, i] * lam[j]
        qdd[i] = acc
        out_q[k, i] = q[i]
        out_qd[k, i] = qd[i]
        out_qdd[k, i] = acc
    for j in range(m):
        out_w[k, j] = w[j]
        out_wd[k, j] = wd[j]
        out_lam[k, j] = lam[j]
        out_stuck[k, j] = stuck[j]
    if track_energy:
        vv = 0.0
        se = 0.0
        for i in range(n):
            vv += qd[i] * qd[i]
            se += 0.5 * w2[i] * q[i] * q[i]
        ke = 0.5 * vv
        for j in range(m):
            ke += 0.5 * mass[j] * wd[j] * wd[j]
        out_energy[k, 0] = E_in
        out_energy[k, 1] = ke
        out_energy[k, 2] = se
        out_energy[k, 3] = E_damp
        out_energy[k, 4] = E_fric
    # every array's last use in the exit block (see ``_trial_exact``)
    used = (cd.shape[0] + P.shape[0] + series.shape[0] + pat.shape[0] + xd.shape[0]
            + qdd.shape[0] + w.shape[0] + wd.shape[0] + lam.shape[0] + stuck.shape[0]
            + mass.shape[0] + out_q.shape[0]
            + out_qd.shape[0] + out_qdd.shape[0] + out_w.shape[0] + out_wd.shape[0]
            + out_lam.shape[0] + out_stuck.shape[0] + out_energy.shape[0] + x.shape[0]
            + w2.shape[0] + q.shape[0] + qd.shape[0])
    ok = np.isfinite(q[0]) and used >= 0
    return STATUS_OK if ok else STATUS_NONFINITE


@_JIT
def _modal_load(pat, ser, out):
    """out = ser @ pat: the modal load of the load series' values ``ser`` (npat,)."""
    for i in range(out.shape[0]):
        acc = 0.0
        for c in range(ser.shape[0]):
            acc += ser[c] * pat[c, i]
        out[i] = acc


@_JIT
def run_kernel_exact(
    w2, cd, a1, fixed, P, mass, mus, mud, dt, ag, pat, series, N, q_init, qd_init,
    resume, w_state, wd_state, stuck_state, sig_state, e_state, t_offset,
    track_energy, max_events, max_substeps, cache_size,
    out_q, out_qd, out_qdd, out_w, out_wd, out_lam, out_stuck, out_energy,
    ev_time, ev_slider, ev_kind,
):
    """Integrate ``n_steps = ag.shape[0] - 1`` steps with exact modal propagators.

    Same interface and outputs as ``run_kernel`` (Newmark) except: ``a1`` (C = a1 K) or
    ``fixed`` (no slider on the structure: the basis never changes), the modal load given
    split as ``series @ pat`` ((n_t, npat) time series of (npat, n) modal load patterns, never
    formed as a whole: a fresh (n_t, n) array costs its page faults), and ``cache_size``
    (contact configurations kept).
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
    pe_t = np.empty(n)  # the modal load series @ pat at an instant
    ser_t = np.empty(npat)
    _modal_load(pat, series[0], pe_t)
    _consistent_cfg(w2, cd, P, mass, mus, mud, on_struct, Ms_key, key, q, qd, ag[0], pe_t,
                    N[0], stuck, sig, cand, forced, qdd, wdd, lam)
    n_ev = _record_events(cand, sig, stuck, sig, t_offset, 0, max_events,
                          ev_time, ev_slider, ev_kind)
    status = STATUS_OK
    _cfg_key(stuck, on_struct, key)
    _cfg_mass(P, mass, key, Ms_key)
    slot, built = _find_config(key, Ms_key, cfg_key, cfg_valid, cfg_stamp, stamp, w2, cd, a1,
                               fixed, pat, dt, c_psi, c_psitm, c_nu2, c_cc, c_gpat, c_E)
    n_built += 1
    # eta, etad, g0 (modal loads at the start of a trial), x0 = Ψ η, xd0 = Ψ η̇
    T0 = np.empty((5, n))
    eta, etad, g0, x0, xd0 = T0[0], T0[1], T0[2], T0[3], T0[4]
    # the current configuration, packed for _trial_exact: Ψ, Ψᵀ and ν², c (copies)
    PS = np.empty((2, n, n))
    NC = np.empty((2, n))
    psi, nu2, cc = PS[0], NC[0], NC[1]
    _load_config(slot, c_psi, c_nu2, c_cc, PS, NC)
    gpat = c_gpat[slot]
    Efull = c_E[slot]  # propagator of a whole step
    MM = np.empty((2, m))  # mass, mu_d
    for j in range(m):
        MM[0, j] = mass[j]
        MM[1, j] = mud[j]
    _to_modal(c_psitm[slot], q, qd, eta, etad)
    # trial end state and its copy at the bracket's hi end
    T1, S1, Tb, Sb, br, e_lo, e_hi, e_try, tolF, old_stuck, old_sig = _event_buffers(5, n, 4, m)
    g1 = T1[2]
    wd1, lam1, s1 = S1[1], S1[2], S1[3]
    W = np.empty((3, n))  # scratch of _trial_exact: η̈, Ψ η̈, structure load of the sliders
    fq = W[2]
    Esub = np.empty((n, 4))
    ework = np.zeros(3)
    SER = np.empty((3, npat))  # load series at the start, the step's end, a trial's end
    ser0, sere = SER[0], SER[2]
    Wn = np.empty((2, n))
    f0, fs = Wn[0], Wn[1]
    # T0's g0 and x0 hold the current start state's values (set by an accepted sub-step,
    # void after a transition, which changes the state or the configuration)
    fresh = False
    NN = np.empty((4, m))  # normal forces at the start, the step's end, a trial's end, step
    N0, N_e, Ns = NN[0], NN[2], NN[3]
    vn = np.empty(m)
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
            if n_sub >= max_substeps:
                status = STATUS_SUBSTEP_LIMIT
                break
            full = tau == 0.0
            hrem = (1.0 - tau) * dt
            ag0 = _sample(ag, series, N, step, tau, ser0, N0)
            for c in range(npat):
                SER[1, c] = series[step + 1, c]
            for j in range(m):  # copies, not views: a view costs two atomic reference counts
                NN[3, j] = N[step, j]
                NN[1, j] = N[step + 1, j]
            ag1 = ag[step + 1]
            if not full:
                _mode_matrices(nu2, cc, hrem, Esub)
            Eh = Efull if full else Esub
            _trial_exact(hrem, Eh, PS, NC, P, gpat, MM, on_struct, stuck, sig, T0, S0, SER, NN,
                         1, ag0, ag1, T1, S1, W, fresh)
            fresh = True  # g0, x0 now hold the start state's values (also for the trials)
            any_ev = _detect(stuck, sig, mus, mud, mass, Ns, NN[1], lam1, wd1, s1, dt, tolF,
                             e_hi)
            theta_hi = 1.0
            if any_ev:
                _bracket_start(br, stuck, sig, lam, N0, s, mus, e_lo, T1, S1, Tb, Sb)
                for _it in range(100):
                    th = _propose(br, stuck, e_lo, e_hi, tolF, mus, NN[1], hrem, dt)
                    if th < 0.0:
                        break
                    hsub = th * hrem
                    _mode_matrices(nu2, cc, hsub, Esub)
                    ag_e = _sample(ag, series, N, step, tau + th * (1.0 - tau), sere, N_e)
                    _trial_exact(hsub, Esub, PS, NC, P, gpat, MM, on_struct, stuck, sig, T0,
                                 S0, SER, NN, 2, ag0, ag_e, T1, S1, W, True)
                    _accept_trial(br, th, stuck, sig, lam1, N_e, s1, mus, tolF, e_try,
                                  e_lo, e_hi, T1, S1, Tb, Sb)
                theta_hi = _bracket_end(br, T1, S1, Tb, Sb)
            tau_end = _substep_end(tau, theta_hi, any_ev)
            h_acc = (tau_end - tau) * dt
            n_sub += 1
            n_sub_total += 1
            if track_energy:
                whole = full and tau_end >= 1.0
                if not whole:
                    _mode_matrices(nu2, cc, h_acc, Esub)
                ag_b = _sample(ag, series, N, step, tau_end, ser_t, N_e)
                Eacc = Efull if whole else Esub
                _energy_substep(h_acc, Eacc, psi, nu2, cc, P, eta, etad, g0, g1, mass, mud,
                                on_struct, stuck, sig, w, wd, ag0, ag_b, N0, N_e, ework,
                                fq, f0, fs)
                E_in += ework[0]
                E_damp += ework[1]
                E_fric += ework[2]
            # g0 <- g1, x0 <- x1: the loads and Ψ η at the new start (still ``fresh``: the
            # same configuration and contact state until a transition)
            for i in range(n):  # T0[:] = T1, S0[:] = S1, without temporary views
                for r_ in range(5):
                    T0[r_, i] = T1[r_, i]
            for j in range(m):
                for r_ in range(4):
                    S0[r_, j] = S1[r_, j]
            if tau_end >= 1.0:
                break
            # --- transition at t_e = (step + tau_end) dt (§5)
            ag_e = _sample(ag, series, N, step, tau_end, ser_t, N_e)
            _modal_load(pat, ser_t, pe_t)
            q[:] = x0  # Ψ η and Ψ η̇, bitwise as _to_physical
            qd[:] = xd0
            fresh = False
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
            changed, n_rank1 = _cfg_update(P, mass, stuck, on_struct, key, Ms_key, n_rank1)
            if changed:
                stamp += 1
                slot, built = _find_config(key, Ms_key, cfg_key, cfg_valid, cfg_stamp, stamp,
                                           w2, cd, a1, fixed, pat, dt, c_psi, c_psitm, c_nu2,
                                           c_cc, c_gpat, c_E)
                if built:
                    n_built += 1
                _load_config(slot, c_psi, c_nu2, c_cc, PS, NC)
                gpat = c_gpat[slot]
                Efull = c_E[slot]
                _to_modal(c_psitm[slot], q, qd, eta, etad)
            tau = tau_end
        if status != STATUS_OK:
            break
        # Ψ η and Ψ η̇ of the last accepted sub-step (bitwise as _to_physical), q̈, output
        status = _step_output(step + 1, w2, cd, P, series, pat, x0, xd0, q, qd, qdd, w, wd, lam,
                              stuck, mass, track_energy, E_in, E_damp, E_fric, out_q, out_qd,
                              out_qdd, out_w, out_wd, out_lam, out_stuck, out_energy)
        if status != STATUS_OK:
            break
    status = _finish(status, n_ev, max_events, w, wd, stuck, sig, E_in, E_damp, E_fric,
                     w_state, wd_state, stuck_state, sig_state, e_state)
    return status, n_ev, n_sub_total, n_built
