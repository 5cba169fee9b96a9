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
  ``lam = -mu_d N sign(s)`` (or their velocity-dependent law). The step, with any nonlinear
  hinges, is ``_kernel_hinge._nl_trial``: one solve with the structure's (tangent) effective
  stiffness with the stuck sliders' masses, never a matrix of the sliders. The rest of an
  event's step and the next ``comp_steps - 1`` steps are Bathe's composite, L-stable steps
  instead (``_kernel_stage._composite``), so the jump of the contact forces leaves no
  period-2h residue in the directions too stiff for the step.
* Transitions are located *inside* the step: an event function per slider (``|lam| - mu_s N`` for
  stuck sliders, ``-sigma s`` for sliding ones) is driven to zero by Illinois regula falsi
  (bisection safeguard) on the sub-step length, the step is split there, and the new contact
  state is decided at the acceleration level (``_consistent``: an active set solved in the
  structure's coordinates with the stuck sliders' masses, the configuration mass ``Ms_key``
  kept by rank-one changes as in the exact kernel).
  Detection, location, transitions and output are the event core in ``_events.py``, shared
  with the exact kernel; this file holds the driver.
"""

# ruff: noqa: N803, N806  (matrix names follow the equations)

import numpy as np

try:  # names injected by the loader when executed after ``_events.py``
    _record_events  # type: ignore[used-before-def]  # noqa: B018
except NameError:  # pragma: no cover - plain import of this file (pure-Python twin)
    from seisrack.dynamics._contact import (
        _accel_fixed,
        _cfg_key,
        _cfg_mass,
        _cfg_update,
        _consistent,
        _free_accel,
    )
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
        _first_trial,
        _init_sliders,
        _interp,
        _propose,
        _record_events,
        _sample,
        _substep_end,
        _write_output,
    )
    from seisrack.dynamics._kernel_hinge import (
        _hinge_commit,
        _hinge_state,
        _minus_qtz,
        _mu_now,
        _nl_trial,
    )
    from seisrack.dynamics._kernel_stage import (
        GAMMA,
        _algorithmic,
        _composite,
        _hinge_commit2,
        _stage_energy,
        _trap_coefs,
    )
    from seisrack.dynamics._linalg import _dh_into, _mv


@_JIT
def run_kernel(
    kd, cd, Cq, diag, P, mass, mus, mud, rate, Q, hth0, hk, hlaw, hpar, hst, dt, ag, pext, N,
    q_init, qd_init, resume, w_state, wd_state, stuck_state, sig_state, e_state, t_offset,
    track_energy, max_events, max_substeps, comp_steps,
    out_q, out_qd, out_qdd, out_w, out_wd, out_lam, out_stuck, out_energy, out_hm,
    ev_time, ev_slider, ev_kind, stats,
):
    """Integrate ``n_steps = ag.shape[0] - 1`` steps. Returns (status, n_events, n_substeps).

    Resumable: with ``resume`` the sliders start from ``w_state, wd_state, stuck_state,
    sig_state``, the cumulative energies from ``e_state`` (input, damping, friction, hinge
    correction work, the composite steps' algorithmic term; then the composite steps still to
    take) and the hinges from their committed states ``hst``; otherwise the sliders
    start stuck on their supports. On return these arrays hold the final state, so a long run
    can be split into chunks (for progress reporting) without changing the result.
    ``t_offset`` [s] is added to event times.

    ag: (n_t,) ground acceleration at grid points; pext: (n_t, n) modal external load
    (``Φ^T (F - M r a_g)``); N: (n_t, m) normal force of each slider.
    rate: (m,) velocity-dependence of friction [s/m] (0: Coulomb). Hinges (``_kernel_hinge``):
    Q (n_h, n) rotations of the basis coordinates, hth0 (n_h,) rotations of the state the run
    starts from (q = 0), hk (n_h,) elastic stiffness, hlaw, hpar,
    hst (n_h, HYST_NSTATE) law, parameters and committed state; out_hm (n_t, n_h) moments.
    out_energy columns: input, kinetic, strain (with the hinges' correction work, so that the
    column is the structure's whole internal work), damping, friction dissipation (cumulative),
    column 5 the composite steps' algorithmic term (``_kernel_stage._algorithmic``, cumulative).
    ``comp_steps``: composite steps from each event on (0: the trapezoidal rule throughout).
    ``stats`` (int64, 4) accumulates the work: trial steps, Newton iterations, factorisations of
    the Newton core, location trials (as the planar kernel's).
    """
    n = kd.shape[0]
    m = mass.shape[0]
    nh = hk.shape[0]
    n_t = ag.shape[0]
    D = np.empty((m + nh, n))  # [P; Q]: P alone on the linear path
    D[:m] = P
    D[m:] = Q
    DH = np.empty((2, m + nh, n))  # D K̂⁻¹ of the regular step, and of a shorter one
    _dh_into(kd, cd, Cq, diag, 2.0 / dt, D, DH[0])
    # state at the start of the (sub)step: T0 rows q, qd, qdd; S0 rows w, wd, lam, s, wdd
    T0 = np.zeros((3, n))
    T0[0] = q_init
    T0[1] = qd_init
    q, qd, qdd = T0[0], T0[1], T0[2]
    S0, stuck, sig, cand, forced, E_in, E_damp, E_fric = _init_sliders(
        5, resume, P, q, qd, w_state, wd_state, stuck_state, sig_state, e_state)
    w, wd, lam, s0, wdd = S0[0], S0[1], S0[2], S0[3], S0[4]
    E_z = e_state[3] if resume else 0.0
    E_alg = e_state[4] if resume else 0.0  # taken out by the composite steps (_algorithmic)
    n_comp = int(e_state[5]) if resume else 0  # composite steps still to take
    Wh = np.zeros((4, nh))  # hinge moments, corrections (committed), and trial copies
    hM, hz, hM_t, hz_t = Wh[0], Wh[1], Wh[2], Wh[3]
    hst_t = hst.copy()
    hst_m = hst.copy()  # the hinges at a composite step's mid state
    hz_m = np.zeros(nh)
    sc = np.empty(4)  # the step's relations (_kernel_stage.py)
    kq = np.empty((2, n))
    kw = np.empty((2, m))
    ea = np.zeros(3)  # energy increments of a sub-step: input, damping, friction
    wn = np.empty((4, n))  # scratch of the trial step, and its Newton core's cache
    wx = np.empty((12, m + nh))
    Kc = np.zeros((2, n, n))
    piv = np.zeros(max(n, 1), dtype=np.int64)  # piv[0] also marks a Cholesky factor
    om = np.zeros(nh)
    cmeta = np.zeros(3)
    _hinge_state(Q, hth0, hk, hlaw, hpar, hst, q, hst_t, hM, hz)
    mu_now = mud.copy()
    pe_eff = np.empty(n)
    _mv(P, qd, s0)  # relative velocities (a resumed run slides on at mu(|s|))
    for j in range(m):
        s0[j] = wd[j] - s0[j]
    _mu_now(mus, mud, rate, stuck, s0, mu_now)
    _minus_qtz(pext[0], Q, hz, pe_eff)
    on_struct = np.ones(m, dtype=np.bool_)
    key = np.zeros(m, dtype=np.bool_)
    Ms_key = np.empty((n, n))  # I + Σ_stuck m_j p_j p_jᵀ, the configuration mass
    _cfg_key(stuck, on_struct, key)
    _cfg_mass(P, mass, key, Ms_key)
    base = np.empty(n)
    _free_accel(kd, cd, Cq, diag, q, qd, pe_eff, base)
    _consistent(P, mass, mus, mu_now, on_struct, Ms_key, key, base, ag[0], N[0], stuck, sig,
                cand, forced, qdd, wdd, lam)
    _chg, n_rank1 = _cfg_update(P, mass, stuck, on_struct, key, Ms_key, 0)
    n_cfg = 0.0  # changes of the stuck set (the nonlinear trial's cache key)
    n_ev = _record_events(cand, sig, stuck, sig, t_offset, 0, max_events,
                          ev_time, ev_slider, ev_kind)
    status = STATUS_OK
    st_tr = STATUS_OK
    # trial end state and its copy at the bracket's hi end
    # (rows 3-5 and 5-9: a composite step's mid state)
    T1, S1, Tb, Sb, br, e_lo, e_hi, e_try, tolF, old_stuck, old_sig = _event_buffers(6, n, 10, m)
    q1, qd1, qdd1 = T1[0], T1[1], T1[2]
    w1, wd1, lam1, s1, wdd1 = S1[0], S1[1], S1[2], S1[3], S1[4]
    n_sub_total = 0
    Wn = np.empty((6, n))  # scratch
    pe0, pe1, tmpn, tmpn2, pe_m, pe_e = Wn[0], Wn[1], Wn[2], Wn[3], Wn[4], Wn[5]
    Wm = np.empty((4, m))
    wk_v, vn0, N_e, N_m = Wm[0], Wm[1], Wm[2], Wm[3]

    _write_output(0, q, qd, qdd, w, wd, lam, stuck, mass, kd, track_energy, E_in, E_damp,
                  E_fric, out_q, out_qd, out_qdd, out_w, out_wd, out_lam, out_stuck, out_energy)
    out_energy[0, 2] += E_z
    out_energy[0, 5] = E_alg
    out_hm[0, :] = hM
    for step in range(n_t - 1):
        tau = 0.0  # fraction of the step already integrated
        n_sub = 0  # sub-steps taken in this step
        while True:
            full = tau == 0.0
            comp = n_comp > 0
            hrem = (1.0 - tau) * dt
            if n_sub >= max_substeps:
                status = STATUS_SUBSTEP_LIMIT
                break
            # end-of-trial excitation (grid value at the end of the step)
            for i in range(n):
                pe1[i] = pext[step + 1, i]
            ag1 = ag[step + 1]
            if comp:
                ag_m = _sample(ag, pext, N, step, tau + GAMMA * (1.0 - tau), pe_m, N_m)
                st_tr = _composite(
                    hrem, kd, cd, Cq, diag, D, DH[1], mass, mus, mud, rate, hth0, hk, hlaw,
                    hpar, hst, hst_m, hst_t, T0, S0, T1, S1, ag_m, pe_m, N_m, ag1, pe1,
                    N[step + 1], stuck, sig, hz, hM_t, hz_t, hz_m, wn, wx, Ms_key, n_cfg, Kc,
                    piv, om, cmeta, stats, sc, kq, kw)
            else:
                _trap_coefs(hrem, w, qd, qdd, wd, wdd, ag1, sc, kq, kw)
                if not full:
                    _dh_into(kd, cd, Cq, diag, sc[1], D, DH[1])
                DHh = DH[0] if full else DH[1]
                hz_t[:] = hz
                st_tr = _nl_trial(
                    sc, kq, kw, kd, cd, Cq, diag, D, DHh, mass, mus, mud,
                    rate, hth0, hk, hlaw, hpar, hst, hst_t, q, lam, ag1, pe1, N[step + 1],
                    stuck, sig, q1, qd1, qdd1, w1, wd1, wdd1, lam1, s1, hM_t, hz_t, wn, wx,
                    Ms_key, n_cfg, Kc, piv, om, cmeta, stats)
            if st_tr != STATUS_OK:
                status = st_tr
                break
            any_ev = _detect(stuck, sig, mus, mud, mass, N[step], N[step + 1], lam1, wd1, s1,
                             dt, tolF, e_hi)
            theta_hi = 1.0  # fraction of the remaining sub-step
            if any_ev:
                _mv(P, qd, vn0)
                for j in range(m):
                    s0[j] = wd[j] - vn0[j]
                    N_e[j] = _interp(N[step, j], N[step + 1, j], tau)
                _bracket_start(br, stuck, sig, lam, N_e, s0, mus, e_lo, T1, S1, Tb, Sb)
                for _it in range(100):
                    th = _propose(br, stuck, e_lo, e_hi, tolF, mus, N[step + 1], hrem, dt)
                    if th < 0.0:
                        break
                    if _it == 0:  # the sliders' accelerations relative to their supports
                        _mv(P, qdd, wk_v)
                        for j in range(m):
                            wk_v[j] = wdd[j] - wk_v[j]
                        th = _first_trial(stuck, sig, e_lo, e_hi, tolF, mus, N[step + 1], wk_v,
                                          hrem)
                    stats[3] += 1
                    ag_e = _sample(ag, pext, N, step, tau + th * (1.0 - tau), pe_e, N_e)
                    hsub = th * hrem
                    if comp:
                        ag_m = _sample(ag, pext, N, step, tau + GAMMA * th * (1.0 - tau),
                                       pe_m, N_m)
                        st_tr = _composite(
                            hsub, kd, cd, Cq, diag, D, DH[1], mass, mus, mud, rate, hth0, hk,
                            hlaw, hpar, hst, hst_m, hst_t, T0, S0, T1, S1, ag_m, pe_m, N_m,
                            ag_e, pe_e, N_e, stuck, sig, hz, hM_t, hz_t, hz_m, wn, wx, Ms_key,
                            n_cfg, Kc, piv, om, cmeta, stats, sc, kq, kw)
                    else:
                        _trap_coefs(hsub, w, qd, qdd, wd, wdd, ag_e, sc, kq, kw)
                        _dh_into(kd, cd, Cq, diag, sc[1], D, DH[1])
                        hz_t[:] = hz
                        st_tr = _nl_trial(
                            sc, kq, kw, kd, cd, Cq, diag, D, DH[1], mass, mus, mud, rate, hth0,
                            hk, hlaw, hpar, hst, hst_t, q, lam, ag_e, pe_e, N_e, stuck, sig,
                            q1, qd1, qdd1, w1, wd1, wdd1, lam1, s1, hM_t, hz_t, wn, wx, Ms_key,
                            n_cfg, Kc, piv, om, cmeta, stats)
                    if st_tr != STATUS_OK:
                        status = st_tr
                        break
                    _accept_trial(br, th, stuck, sig, lam1, N_e, s1, mus, tolF, e_try,
                                  e_lo, e_hi, T1, S1, Tb, Sb)
                if status != STATUS_OK:
                    break
                theta_hi = _bracket_end(br, T1, S1, Tb, Sb)
            # --- accept the sub-step [tau, tau_end]
            tau_end = _substep_end(tau, theta_hi, any_ev)
            n_sub += 1
            n_sub_total += 1
            if track_energy:
                for i in range(n):
                    pe0[i] = _interp(pext[step, i], pext[step + 1, i], tau)
                    pe1[i] = _interp(pext[step, i], pext[step + 1, i], tau_end)
                ag_a = _interp(ag[step], ag[step + 1], tau)
                ag_b = _interp(ag[step], ag[step + 1], tau_end)
                ea[:] = 0.0
                if comp:  # two stages, each a trapezoid of its end values
                    tmid = tau + GAMMA * (tau_end - tau)
                    for i in range(n):
                        pe_m[i] = _interp(pext[step, i], pext[step + 1, i], tmid)
                    ag_m = _interp(ag[step], ag[step + 1], tmid)
                    _stage_energy(q, qd, T1[3], T1[4], w, S1[5], lam, S1[7], pe0, pe_m, ag_a,
                                  ag_m, P, mass, cd, Cq, diag, tmpn, tmpn2, wk_v, ea)
                    _stage_energy(T1[3], T1[4], q1, qd1, S1[5], w1, S1[7], lam1, pe_m, pe1,
                                  ag_m, ag_b, P, mass, cd, Cq, diag, tmpn, tmpn2, wk_v, ea)
                    E_alg += _algorithmic(T1[3], T1[4], T1[5], q1, qd1, qdd1, S1[5], S1[6],
                                          S1[9], w1, wd1, wdd1, mass)
                else:
                    _stage_energy(q, qd, q1, qd1, w, w1, lam, lam1, pe0, pe1, ag_a, ag_b, P,
                                  mass, cd, Cq, diag, tmpn, tmpn2, wk_v, ea)
                E_in += ea[0]
                E_damp += ea[1]
                E_fric += ea[2]
            if nh > 0 and comp:
                E_z += _hinge_commit2(Q, hth0, hk, hlaw, hpar, hst, hst_m, hst_t, T1[3], q1,
                                      hM, hz, hM_t, hz_t, hz_m)
            elif nh > 0:
                E_z += _hinge_commit(Q, hth0, hk, hlaw, hpar, hst, hst_t, q1, hM, hz, hM_t,
                                     hz_t, not any_ev)
            T0[:] = T1[:3]
            S0[:] = S1[:5]
            if tau_end >= 1.0:
                if n_comp > 0:
                    n_comp -= 1
                if not full:
                    # a short final sub-step amplifies round-off in the Newmark acceleration
                    # update; restore accelerations from equilibrium (same forces lam)
                    _minus_qtz(pext[step + 1], Q, hz, tmpn)
                    _accel_fixed(kd, cd, Cq, diag, P, mass, q, qd, ag[step + 1], tmpn, lam,
                                 qdd, wdd)
                break
            # --- transition at t_e = (step + tau_end) dt (§5)
            ag_e = _sample(ag, pext, N, step, tau_end, tmpn, N_e)
            _minus_qtz(tmpn, Q, hz, tmpn)
            _mv(P, qd, vn0)
            _classify(stuck, sig, lam, s1, wd, vn0, mus, N_e, tolF, e_try, old_stuck, old_sig,
                      cand, forced)
            _mu_now(mus, mud, rate, stuck, s0, mu_now)
            _free_accel(kd, cd, Cq, diag, q, qd, tmpn, base)
            _consistent(P, mass, mus, mu_now, on_struct, Ms_key, key, base, ag_e, N_e, stuck,
                        sig, cand, forced, qdd, wdd, lam)
            chg, n_rank1 = _cfg_update(P, mass, stuck, on_struct, key, Ms_key, n_rank1)
            if chg:
                n_cfg += 1.0
            n_comp = comp_steps
            n_ev = _record_events(old_stuck, old_sig, stuck, sig,
                                  t_offset + (step + tau_end) * dt, n_ev, max_events,
                                  ev_time, ev_slider, ev_kind)
            tau = tau_end
        if status != STATUS_OK:
            break
        status = _write_output(step + 1, q, qd, qdd, w, wd, lam, stuck, mass, kd, track_energy,
                               E_in, E_damp, E_fric, out_q, out_qd, out_qdd, out_w, out_wd,
                               out_lam, out_stuck, out_energy)
        out_energy[step + 1, 2] += E_z
        out_energy[step + 1, 5] = E_alg
        out_hm[step + 1, :] = hM
        if status != STATUS_OK:
            break
    status = _finish(status, n_ev, max_events, w, wd, stuck, sig, E_in, E_damp, E_fric,
                     w_state, wd_state, stuck_state, sig_state, e_state)
    e_state[3] = E_z
    e_state[4] = E_alg
    e_state[5] = n_comp
    return status, n_ev, n_sub_total
