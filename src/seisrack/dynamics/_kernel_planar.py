"""Planar stick–slip kernel: pallets sliding in the horizontal plane with isotropic Coulomb
friction on a linear structure (source shared by the numba and pure-Python backends). This
file holds the driver ``run_planar``; the step is ``_planar_step.py``, the decisions at an
event ``_planar_events.py``, the location the shared event core ``_events.py``.

Theory: ``docs/theory/planar_friction.md``. Each pallet ``p`` rests on its supports; ``P``
rows ``2p`` (x) and ``2p + 1`` (z) map the basis coordinates ``q`` to the support
displacement. A pallet's state is its displacement ``w`` relative to the ground (2 components)
and its contact state: stuck (relative velocity 0, friction force of magnitude ≤ mu_s N) or
sliding (friction -mu_d N v/|v|, opposite to the relative velocity vector ``v``).

Newmark average acceleration on [q, w] with the friction force at the end of the step. For a
sliding pallet the end force is -mu_d N ẑ, where ``z`` is the relative velocity the pallet
would have at the end of the step without its friction (a return map on the friction disc:
the sliding velocity ``s1 = z (1 - c/|z|)`` with ``c = h mu_d N / (2 m)`` stays parallel to
``z``). The step is one equation in the structure's coordinates, solved by Newton's method
(stuck pallets enter linearly as masses on their supports, sliding ones through the direction
of ``z``). Events, located inside the step by the shared event core (``_events.py``):
a stuck pallet slips when |lam| = mu_s N; a sliding pallet reaches zero relative velocity when
|z| = c, where it sticks or slides on in a new direction (decided at the acceleration level).
"""

# ruff: noqa: N803, N806  (matrix names follow the equations)

import numpy as np

try:  # names injected by the loader when executed after ``_planar_events.py``
    _decide  # type: ignore[used-before-def]  # noqa: B018
except NameError:  # pragma: no cover - plain import of this file (pure-Python twin)
    from seisrack.dynamics._events import (
        _JIT,
        STATUS_EVENT_OVERFLOW,
        STATUS_NONFINITE,
        STATUS_OK,
        STATUS_SUBSTEP_LIMIT,
        _accept_values,
        _bracket_end,
        _bracket_open,
        _interp,
        _keep_old,
        _propose3,
        _substep_end,
    )
    from seisrack.dynamics._planar_axial import _axial_force
    from seisrack.dynamics._planar_events import (
        _classify,
        _decide,
        _fill_relative,
        _first_guess,
        _frozen_slack,
        _mask_frozen,
        _output,
        _record,
        _snap_stops,
        _start_values,
        _track_direction,
    )
    from seisrack.dynamics._planar_hinges import _hinge_commit_at, _hinge_committed, _minus_qtz
    from seisrack.dynamics._planar_stage import GAMMA_PL, _algorithmic_pl, _stage_work, _step
    from seisrack.dynamics._planar_step import _sample_row

#: status of a Newton iteration of the planar step that did not converge
STATUS_PLANAR_NEWTON = 4
#: transitions of one pallet within one step after which its state is kept to the step's end:
#: at mu_d = mu_s a pallet whose holding force hovers at mu_s N can stop and slide again after
#: ever shorter times (a Zeno sequence). Frozen (level 1), a sliding pallet stops only in the
#: next step; a stuck one still slips, once its force passes mu_s N by _FROZEN_SLACK (held to
#: the step's end, it was reported at 1.24 mu_s N on the 10 x 5 row), and is not re-decided
#: at other pallets' events. After twice as many transitions (level 2) the state is kept
#: whatever the force, so that the step ends
_CHATTER = 4
#: an event is located when its bracket is shorter than this fraction of dt (or its event
#: function is within its tolerance): 5e-9 s at dt = 5 ms, where a late slip onset or stop
#: changes the state by O(span²)
_SPAN = 1e-6


@_JIT
def _finite_state(T0, S0):
    """Whether the state is finite, read at its first structural coordinate, or at its first
    pallet's when the kernel integrates no direction (every one held quasi-statically: reading
    ``T0[0, 0]`` there read past an empty array, and the run stopped at random as
    "non-finite")."""
    if T0.shape[1] > 0:
        return np.isfinite(T0[0, 0])
    if S0.shape[1] > 0:
        return np.isfinite(S0[0, 0])
    return True


@_JIT
def run_planar(kd, cd, Co, P, mass, mus, mud, dt, agx, agz, pext, N, resume, T_state, S_state,
               stuck, dirn, S, A, fac, t_offset, max_events, max_substeps,
               out_q, out_qd, out_qdd, out_u, out_v, out_lam, out_stuck,
               ev_time, ev_pallet, ev_kind, stats,
               Q, hth0, hk, hlaw, hpar, hst, HW, e_state, out_hm, out_energy,
               AA, AG, Ao, As, Ac, comp_steps):
    """Integrate ``agx.shape[0] - 1`` steps. Returns (status, n_events, n_substeps, the last
    output row written).

    kd, cd: (r,) the stiffness and the damping's diagonal in the basis; ``Co`` (r, r) the
    damping's off-diagonal part (non-classical damping, e.g. a1 K_E in the modes of
    K_E + K_G), or (0, 0) when it is diagonal: the diagonal path then runs as before.
    agx, agz: (n_t,) ground accelerations down-aisle (x) and cross-aisle (z); pext: (n_t, r)
    modal loads; N: (n_t, m) normal forces. The state is read when ``resume`` (else the
    pallets start stuck on a structure at the given q, qd) and written back at the end, so
    chunks continue exactly: ``T_state`` (3, r): q, qd, qdd; ``S_state`` (6, 2m): w, wd, wdd,
    lam, s, vn; ``stuck``, ``dirn``; ``S`` (r + 2, r): the stuck pallets' mass (see
    ``_s_update``); ``A`` (r, r) and ``fac`` (1,): the last factorised Newton matrix and its
    step length, -1 for none (see ``_trial``). ``stats`` (int64, 4) accumulates the trial
    steps, Newton iterations, Cholesky factorisations (of the step's Newton matrix and of
    ``_decide``'s configuration mass) and location trials. Outputs per step
    (n_t rows): q, qd, qdd, u (sliding displacement w - P q), v (relative velocity), lam
    (friction force on the pallet), stuck.

    Nonlinear hinges (``docs/theory/planar_friction.md`` §7): ``Q`` (n_h, r) their rotations
    of the basis coordinates, ``hth0`` (n_h,) their rotations at q = 0, ``hk`` their elastic
    stiffness (in ``kd``), ``hlaw``, ``hpar`` their laws, ``hst`` (n_h, HYST_NSTATE) their
    committed states (read and written back, as the pallets' state), ``HW`` (4, n_h) scratch
    that goes with ``A``; ``out_hm`` (n_t, n_h) their moments. Energy (cumulative from the
    start of the run, resumed from ``e_state``: input, damping, friction, the hinges'
    correction work ∫ z dθ, the work of the P-Δ of the axial forces' change ∫ f · dq, what the
    composite steps take out, then the composite steps still to take):
    ``out_energy`` (n_t, 7) columns input, kinetic, strain (with both works), damping,
    friction, the P-Δ work, the composite steps' algorithmic term; ``out_energy`` with no
    columns (n_t, 0): the energy terms are not computed (nobody reads them: a study's runs).

    ``comp_steps``: the first ``comp_steps`` steps of a run, and after an event the rest of its
    step and the next ``comp_steps - 1``, are Bathe's composite steps (``_planar_stage.py``);
    0: the trapezoidal rule throughout; more than the run's steps: composite throughout.

    The P-Δ of the current axial forces (``_planar_axial.py``): ``AA`` (n_m, r), ``AG``
    (n_g, r), ``Ao``, ``As``, ``Ac`` (n_g,) the operators of :mod:`seisrack.dynamics.axial` in
    the basis; no rows (n_g = 0): none, and the trials are the plain ones.
    """
    r = kd.shape[0]
    m = mass.shape[0]
    n_t = agx.shape[0]
    nw = max(r, 2 * m, 1)
    W = np.empty((13, nw))  # scratch: rows 0–9, 11, 12 _trial's, 10 _decide's
    G = np.empty((2 * m, r))
    PF = np.empty((2 * m, r))
    dqa = np.empty(r)  # the last two trials of a location (fractions tha, thb): the next
    dqb = np.empty(r)  # trial starts from their quadratic interpolation through dq(0) = 0
    dqg = np.empty(r)
    qdd_full = np.empty(r)
    # the state: T rows q, qd, qdd; S rows w, wd, wdd, lam, s, vn; rows 3-5 and 6-11 of the
    # trial and bracket states: a composite step's mid state
    T0 = np.zeros((6, r))
    S0 = np.zeros((12, 2 * m))
    T0[:3] = T_state
    S0[:6] = S_state
    T1 = np.zeros_like(T0)
    S1 = np.zeros_like(S0)
    Tb = np.zeros_like(T0)
    Sb = np.zeros_like(S0)
    kq = np.empty((2, r))  # a step's relations (_planar_stage.py)
    kw = np.empty((2, 2 * m))
    ag_m = np.empty(2)  # the excitation at a composite step's mid state
    pe_m = np.empty(r)
    N_m = np.empty(m)
    dqp = np.empty(r)
    hst_m = hst.copy()  # the hinges at a composite step's mid state
    hzm = np.empty(hk.shape[0])
    ew = np.zeros(3)  # the work of a sub-step: input, damping, friction
    agb = np.empty(2)
    e_lo = np.empty(m)
    e_hi = np.empty(m)
    e_try = np.empty(m)
    e_old = np.empty(m)
    tolF = np.empty(m)
    tolT = np.empty(m)
    c_full = np.empty(m)
    br = np.empty(6)
    cand = np.zeros(m, dtype=np.bool_)
    forced = np.zeros(m, dtype=np.bool_)
    turned = np.zeros(m, dtype=np.bool_)
    old_stuck = stuck.copy()
    ag = np.empty(2)
    ag0 = np.empty(2)
    pe = np.empty(r)
    Ne = np.empty(m)
    N0 = np.empty(m)
    n_ev = 0
    n_sub = 0
    status = STATUS_OK
    nh = hk.shape[0]
    hst_t = hst.copy()
    hM = np.empty(nh)  # committed moments and corrections
    hz = np.empty(nh)
    hMt = np.empty(nh)  # a trial's
    hzt = np.empty(nh)
    _hinge_committed(hst, hk, hM, hz)
    pz = np.empty(r)  # a modal load with the hinges' corrections moved over
    pea = np.empty(r)
    peb = np.empty(r)
    dqe = np.empty(r)
    ena = np.empty(2)
    E_in, E_damp, E_fric, E_z = e_state[0], e_state[1], e_state[2], e_state[3]
    E_ax = e_state[4]
    E_alg = e_state[5]
    n_comp = int(e_state[6])
    track = out_energy.shape[1] > 0
    AXW = np.empty((4, r))  # scratch of _trial_ax
    dn = np.empty(AA.shape[0])
    gw = np.empty(AG.shape[0])
    fa = np.empty(r)  # the axial P-Δ force at the committed state, and at a trial's end
    fb = np.empty(r)
    axial = AG.shape[0] > 0
    if not resume:
        E_in, E_damp, E_fric, E_z, E_ax, E_alg = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
        n_comp = comp_steps
        # pallets start stuck, moving with their supports
        stuck[:] = False
        S[:, :] = 0.0
        for j in range(2 * m):
            acc = 0.0
            accv = 0.0
            for i in range(r):
                acc += P[j, i] * T0[0, i]
                accv += P[j, i] * T0[1, i]
            S0[0, j] = acc
            S0[1, j] = accv
        for p in range(m):
            cand[p] = True
        old_stuck[:] = False
        ag[0] = agx[0]
        ag[1] = agz[0]
        _minus_qtz(pext[0], Q, hz, pz)
        if axial:
            _axial_force(AA, AG, Ao, As, Ac, T0[0], dn, gw, fa)
            for i in range(r):
                pz[i] -= fa[i]
        _decide(kd, cd, Co, P, mass, mus, mud, S, T0, S0, ag, pz, N[0], stuck, dirn,
                cand, forced, A, pe, forced, stats)
        for p in range(m):
            old_stuck[p] = True  # "slip" at t = 0 for pallets released at once
            cand[p] = False
        n_ev = _record(old_stuck, stuck, turned, t_offset, n_ev, max_events,
                       ev_time, ev_pallet, ev_kind)
        _fill_relative(P, T0, S0)
    _output(0, P, T0, S0, stuck, out_q, out_qd, out_qdd, out_u, out_v, out_lam, out_stuck)
    out_hm[0, :] = hM
    if axial:
        _axial_force(AA, AG, Ao, As, Ac, T0[0], dn, gw, fa)
    if track:
        _energy_row(0, T0, S0, kd, mass, E_in, E_damp, E_fric, E_z, E_ax, E_alg, out_energy)
    k_done = 0
    n_tr = np.zeros(m, dtype=np.int64)
    frozen = np.zeros(m, dtype=np.int8)  # 0, or the level of the chatter guard (_CHATTER)
    for k in range(n_t - 1):
        tau = 0.0
        n_here = 0
        for p in range(m):
            n_tr[p] = 0
            frozen[p] = 0
        while True:
            hrem = (1.0 - tau) * dt
            comp = n_comp > 0
            if comp:
                _sample_mid(agx, agz, pext, N, k, tau + GAMMA_PL * (1.0 - tau), ag_m, pe_m, N_m)
            for p in range(m):
                N0[p] = _interp(N[k, p], N[k + 1, p], tau)
            ag[0] = agx[k + 1]
            ag[1] = agz[k + 1]
            for i in range(r):
                dqg[i] = hrem * T0[1, i] + 0.5 * hrem * hrem * T0[2, i]
            ok = _step(hrem, comp, kq, kw, kd, cd, Co, P, mass, mus, mud, S, T0, S0, N0, stuck,
                       dirn, ag_m, pe_m, N_m, ag, pext[k + 1], N[k + 1], T1, S1, e_hi, tolF, dt,
                       W, A, G, PF, stats, dqg, True, fac, Q, hth0, hk, hlaw, hpar, hst, hst_m,
                       hst_t, hz, hzm, hMt, hzt, HW, AA, AG, Ao, As, Ac, AXW, dn, gw, dqp)
            _mask_frozen(frozen, stuck, e_hi)
            _frozen_slack(frozen, stuck, mus, N[k + 1], tolF)
            if ok != 0:
                status = STATUS_PLANAR_NEWTON + ok - 1
                break
            any_ev = False
            for p in range(m):
                if e_hi[p] > tolF[p]:
                    any_ev = True
            th_hi = 1.0
            if any_ev:
                _start_values(stuck, mus, N0, S0, e_lo)
                ag0[0] = _interp(agx[k], agx[k + 1], tau)
                ag0[1] = _interp(agz[k], agz[k + 1], tau)
                _bracket_open(br, T1, S1, Tb, Sb)
                tha = 1.0
                thb = -1.0
                th_old = -1.0
                for i in range(r):
                    dqa[i] = T1[0, i] - T0[0, i]
                    qdd_full[i] = T1[2, i]
                for _loc in range(200):
                    th = _propose3(br, stuck, e_lo, e_hi, e_old, th_old, tolF, mus, N[k + 1],
                                   hrem, dt, _SPAN)
                    if th < 0.0:
                        break
                    if _loc == 0:
                        th = _first_guess(stuck, dirn, e_lo, e_hi, tolF, mass, mud, N0, P,
                                          T0[2], ag0, hrem)
                    frac = tau + th * (1.0 - tau)
                    ag[0] = _interp(agx[k], agx[k + 1], frac)
                    ag[1] = _interp(agz[k], agz[k + 1], frac)
                    _sample_row(pext, k, frac, pe)
                    for p in range(m):
                        Ne[p] = _interp(N[k, p], N[k + 1, p], frac)
                    stats[3] += 1
                    warm = True
                    if thb > 0.0:
                        # quadratic through dq(0) = 0 and the last two trials
                        la = th * (th - thb) / (tha * (tha - thb))
                        lb = th * (th - tha) / (thb * (thb - tha))
                        for i in range(r):
                            dqg[i] = la * dqa[i] + lb * dqb[i]
                    else:
                        # Newmark's dq with the end acceleration linear between the start and
                        # the end of the full trial
                        hs = th * hrem
                        for i in range(r):
                            dqg[i] = hs * T0[1, i] + 0.25 * hs * hs * (
                                2.0 * T0[2, i] + th * (qdd_full[i] - T0[2, i]))
                    if comp:
                        _sample_mid(agx, agz, pext, N, k, tau + GAMMA_PL * th * (1.0 - tau),
                                    ag_m, pe_m, N_m)
                    ok = _step(th * hrem, comp, kq, kw, kd, cd, Co, P, mass, mus, mud, S, T0,
                               S0, N0, stuck, dirn, ag_m, pe_m, N_m, ag, pe, Ne, T1, S1, e_try,
                               tolT, dt, W, A, G, PF, stats, dqg, warm, fac, Q, hth0, hk, hlaw,
                               hpar, hst, hst_m, hst_t, hz, hzm, hMt, hzt, HW, AA, AG, Ao, As,
                               Ac, AXW, dn, gw, dqp)
                    dqb[:] = dqa
                    thb = tha
                    tha = th
                    for i in range(r):
                        dqa[i] = T1[0, i] - T0[0, i]
                    _mask_frozen(frozen, stuck, e_try)
                    if ok != 0:
                        status = STATUS_PLANAR_NEWTON + ok - 1
                        break
                    th_old = _keep_old(br, e_try, tolF, e_lo, e_hi, e_old)
                    _accept_values(br, th, e_try, tolF, e_lo, e_hi, T1, S1, Tb, Sb)
                if status != STATUS_OK:
                    break
                th_hi = _bracket_end(br, T1, S1, Tb, Sb)
            # the work over the accepted sub-step [tau, tau_end] (Newmark's energy identity:
            # forces averaged over the two ends of each stage, which is exact for the
            # trapezoidal rule; a backward-difference stage's excess is the algorithmic term)
            tau_e = _substep_end(tau, th_hi, any_ev)
            if track:
                _sample_row(pext, k, tau, pea)
                _sample_row(pext, k, tau_e, peb)
                ena[0] = _interp(agx[k], agx[k + 1], tau)
                ena[1] = _interp(agz[k], agz[k + 1], tau)
                agb[0] = _interp(agx[k], agx[k + 1], tau_e)
                agb[1] = _interp(agz[k], agz[k + 1], tau_e)
                ew[:] = 0.0
                if comp:
                    _sample_mid(agx, agz, pext, N, k, tau + GAMMA_PL * (tau_e - tau), ag_m,
                                pe_m, N_m)
                    _stage_work(T0, S0, T1[3:6], S1[6:12], pea, pe_m, ena, ag_m, cd, Co, P,
                                mass, dqe, ew)
                    _stage_work(T1[3:6], S1[6:12], T1, S1, pe_m, peb, ag_m, agb, cd, Co, P,
                                mass, dqe, ew)
                    E_alg += _algorithmic_pl(T1[3:6], S1[6:12], T1, S1, mass)
                else:
                    _stage_work(T0, S0, T1, S1, pea, peb, ena, agb, cd, Co, P, mass, dqe, ew)
                E_in += ew[0]
                E_damp += ew[1]
                E_fric += ew[2]
                if axial:  # the P-Δ force's work, by the trapezoid as every other force's
                    if comp:
                        _axial_force(AA, AG, Ao, As, Ac, T1[3], dn, gw, fb)
                        for i in range(r):
                            E_ax += 0.5 * (fa[i] + fb[i]) * (T1[3, i] - T0[0, i])
                        fa[:] = fb
                        for i in range(r):
                            dqe[i] = T1[0, i] - T1[3, i]
                    else:
                        for i in range(r):
                            dqe[i] = T1[0, i] - T0[0, i]
                    _axial_force(AA, AG, Ao, As, Ac, T1[0], dn, gw, fb)
                    for i in range(r):
                        E_ax += 0.5 * (fa[i] + fb[i]) * dqe[i]
                    fa[:] = fb
            if nh > 0 and comp:  # through the mid state: the laws are path-dependent
                E_z += _hinge_commit_at(Q, hth0, hk, hlaw, hpar, hst, hst_t, T1[3], hM, hz)
            T0[:] = T1
            S0[:] = S1
            if nh > 0:
                E_z += _hinge_commit_at(Q, hth0, hk, hlaw, hpar, hst, hst_t, T0[0], hM, hz)
            _track_direction(stuck, S0, dirn)
            tau = _substep_end(tau, th_hi, any_ev)
            if any_ev:
                ag[0] = _interp(agx[k], agx[k + 1], tau)
                ag[1] = _interp(agz[k], agz[k + 1], tau)
                _sample_row(pext, k, tau, pe)
                for p in range(m):
                    Ne[p] = _interp(N[k, p], N[k + 1, p], tau)
                for p in range(m):
                    c_full[p] = 0.5 * dt * mud[p] * Ne[p] / mass[p]
                _classify(stuck, dirn, mus, Ne, S0, e_hi, cand, forced, old_stuck, turned,
                          c_full, frozen)
                lost = _snap_stops(P, S, mass, T0, S0, stuck, turned)
                if lost > 0.0:  # the structure's velocity moved: every support's with it
                    E_fric += lost
                    _fill_relative(P, T0, S0)
                _minus_qtz(pe, Q, hz, pz)
                if axial:
                    _axial_force(AA, AG, Ao, As, Ac, T0[0], dn, gw, fb)
                    for i in range(r):
                        pz[i] -= fb[i]
                _decide(kd, cd, Co, P, mass, mus, mud, S, T0, S0, ag, pz, Ne, stuck, dirn,
                        cand, forced, A, W[10, :r], frozen, stats)
                fac[0] = -1.0
                for p in range(m):
                    # a pallet that reached zero velocity and slides on has turned
                    turned[p] = cand[p] and not stuck[p] and not old_stuck[p]
                    # events of p in this step, with or without a change of state (a
                    # located sharp turn changes none)
                    if turned[p] or stuck[p] != old_stuck[p] or e_hi[p] >= -tolF[p]:
                        n_tr[p] += 1
                        if n_tr[p] >= _CHATTER:
                            frozen[p] = 2 if n_tr[p] >= 2 * _CHATTER else 1
                n_ev = _record(old_stuck, stuck, turned, t_offset + (k + tau) * dt, n_ev,
                               max_events, ev_time, ev_pallet, ev_kind)
                n_comp = comp_steps
                _fill_relative(P, T0, S0)
            if tau >= 1.0:
                if n_comp > 0 and not any_ev:
                    n_comp -= 1
                break
            n_here += 1
            n_sub += 1
            if n_here > max_substeps:
                status = STATUS_SUBSTEP_LIMIT
                break
        if status != STATUS_OK:
            break
        _output(k + 1, P, T0, S0, stuck, out_q, out_qd, out_qdd, out_u, out_v, out_lam,
                out_stuck)
        out_hm[k + 1, :] = hM
        if track:
            _energy_row(k + 1, T0, S0, kd, mass, E_in, E_damp, E_fric, E_z, E_ax, E_alg,
                        out_energy)
        k_done = k + 1
        if not _finite_state(T0, S0):
            status = STATUS_NONFINITE
            break
    if n_ev > max_events and status == STATUS_OK:
        status = STATUS_EVENT_OVERFLOW
    T_state[:] = T0[:3]
    S_state[:] = S0[:6]
    e_state[5] = E_alg
    e_state[6] = n_comp
    e_state[0] = E_in
    e_state[1] = E_damp
    e_state[2] = E_fric
    e_state[3] = E_z
    e_state[4] = E_ax
    return status, n_ev, n_sub, k_done


@_JIT
def _energy_row(k, T0, S0, kd, mass, E_in, E_damp, E_fric, E_z, E_ax, E_alg, out_energy):
    """Row ``k`` of the energy output: input, kinetic (structure and pallets, relative to the
    ground), strain (½ qᵀ kd q plus the hinges' correction work and the P-Δ force's work),
    damping, friction, the P-Δ force's work alone, the composite steps' algorithmic term."""
    kin = 0.5 * np.dot(T0[1], T0[1])
    for p in range(mass.shape[0]):
        kin += 0.5 * mass[p] * (S0[1, 2 * p] ** 2 + S0[1, 2 * p + 1] ** 2)
    strain = E_z + E_ax
    for i in range(kd.shape[0]):
        strain += 0.5 * kd[i] * T0[0, i] * T0[0, i]
    out_energy[k, 0] = E_in
    out_energy[k, 1] = kin
    out_energy[k, 2] = strain
    out_energy[k, 3] = E_damp
    out_energy[k, 4] = E_fric
    out_energy[k, 5] = E_ax
    out_energy[k, 6] = E_alg


@_JIT
def _sample_mid(agx, agz, pext, N, k, frac, ag_m, pe_m, N_m):
    """The excitation at the fraction ``frac`` of step ``k``: ground accelerations, modal
    loads, normal forces."""
    ag_m[0] = _interp(agx[k], agx[k + 1], frac)
    ag_m[1] = _interp(agz[k], agz[k + 1], frac)
    _sample_row(pext, k, frac, pe_m)
    for p in range(N_m.shape[0]):
        N_m[p] = _interp(N[k, p], N[k + 1, p], frac)
