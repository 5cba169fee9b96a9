"""Contact decisions of the planar stick–slip kernel at an event, its event values and its
output (source shared by the numba and pure-Python backends; theory:
``docs/theory/planar_friction.md`` §3). Location itself is the shared event core's
(``_events.py``).
"""

# ruff: noqa: N803, N806  (matrix names follow the equations)

import numpy as np

try:  # names injected by the loader when executed after ``_planar_step.py``
    _chol  # type: ignore[used-before-def]  # noqa: B018
except NameError:  # pragma: no cover - plain import of this file (pure-Python twin)
    from seisrack.dynamics._events import (
        _JIT,
        KIND_REVERSE,
        KIND_SLIP,
        KIND_STICK,
        _root_on_quadratic,
    )
    from seisrack.dynamics._lapack import _chol, _chol_solve
    from seisrack.dynamics._planar_contact import _released_forces
    from seisrack.dynamics._planar_step import _s_update

#: a stuck pallet frozen by the chatter guard at level 1 (``_CHATTER``) slips beyond
#: (1 + this) mu_s N: well above the round-off of a force hovering at mu_s N
_FROZEN_SLACK = 1e-5


@_JIT
def _start_values(stuck, mus, N0, S0, e_lo):
    """Event values at the start of a sub-step (the bracket's lo end)."""
    lam, s = S0[3], S0[4]
    for p in range(stuck.shape[0]):
        jx = 2 * p
        if stuck[p]:
            e_lo[p] = np.sqrt(lam[jx] ** 2 + lam[jx + 1] ** 2) - mus[p] * N0[p]
        else:
            e_lo[p] = -np.sqrt(s[jx] ** 2 + s[jx + 1] ** 2)


@_JIT
def _first_guess(stuck, dirn, e_lo, e_hi, tolF, mass, mud, N0, P, qdd0, ag0, hrem):
    """First trial fraction of an event location (bracket [0, 1]): the earliest root of the
    violated event functions. A sliding pallet's is the root of the quadratic through its value
    and slope at the start and its value at the end: its stop function c - d0·z rises at the
    start at hrem (mu_d N / m + d0·(ag + P qdd)), its deceleration relative to its support, and
    curves with the structure's response over the step, which a straight line through the two
    ends (Illinois' first estimate) often misses by a factor of two. A stuck pallet's is that
    straight line."""
    th = 2.0
    for p in range(stuck.shape[0]):
        if e_hi[p] <= tolF[p]:
            continue
        # the middle of a sliding pallet's acceptance window (tolF, 2 tolF]; a stuck one's
        # (_conv_limit) is 5e-11 mu_s N higher, immaterial for a first trial
        tgt = 1.5 * tolF[p]
        f0 = min(e_lo[p] - tgt, 0.0)
        f1 = e_hi[p] - tgt
        tj = -f0 / (f1 - f0)
        if not stuck[p]:
            jx = 2 * p
            d = mud[p] * N0[p] / mass[p]
            for c in range(2):
                d += dirn[jx + c] * (ag0[c] + np.dot(P[jx + c], qdd0))
            tj = _root_on_quadratic(f0, f1, d * hrem, tj)
        th = min(th, tj)
    return min(max(th, 1e-6), 1.0 - 1e-6)


@_JIT
def _decide(kd, cd, Co, P, mass, mus, mud, S, T0, S0, ag, pext, N, stuck, dirn, cand, forced,
            A, base, frozen, stats):
    """Contact state at an instant and consistent accelerations (active set).

    ``cand``: pallets at zero relative velocity to be decided (they stick when the force that
    keeps them stuck is within mu_s N, else slide opposite to it); ``forced``: stuck pallets
    whose slip onset was just located (at mu_s N to the location's tolerance). Every one starts
    stuck and the most overloaded is released, one at a time, the forced ones from 1 - 1e-7 of
    their capacity: when several reach their threshold together, releasing one can unload the
    others (an all-at-once release chattered, each pallet re-sticking at once). Updates
    ``stuck``, ``dirn`` and ``S`` (the stuck pallets' mass); writes qdd, wdd and lam.
    ``frozen`` pallets keep their state (see ``_CHATTER``) unless ``forced``. Damping: ``cd``
    its diagonal, ``Co`` the rest or (0, 0) (see ``_trial``). ``stats[2]`` counts the
    factorisations of I + S (one, and one more after each release or re-stick).
    """
    r = kd.shape[0]
    m = mass.shape[0]
    q, qd, qdd = T0[0], T0[1], T0[2]
    wdd, lam = S0[2], S0[3]
    for p in range(m):
        if cand[p] and not stuck[p]:
            stuck[p] = True
            _s_update(S, P, mass, p, 1.0)
    zr = np.zeros(m, dtype=np.bool_)  # released here: sliding from zero relative velocity
    fv = np.empty(2 * m)
    for _it in range(4 * m + 4):
        # (I + S) qdd = pext - C qd - K q - sum_F P_pᵀ lam_p - sum_S m_p P_pᵀ ag
        for i in range(r):
            for k in range(i + 1):
                A[i, k] = S[i, k]
            A[i, i] += 1.0
        _chol(A)
        stats[2] += 1
        n_rel = 0
        for p in range(m):
            if zr[p] and not stuck[p]:
                n_rel += 1
            for c in range(2):
                j = 2 * p + c
                if stuck[p]:
                    fv[j] = mass[p] * ag[c]
                elif zr[p]:
                    fv[j] = 0.0  # from the contact problem below
                else:
                    fv[j] = -mud[p] * N[p] * dirn[j]
                    lam[j] = fv[j]
        base[:] = pext - cd * qd - kd * q - np.dot(fv, P)
        if Co.shape[0] > 0:  # non-classical damping: its off-diagonal part
            base[:] -= np.dot(Co, qd)
        _chol_solve(A, base)
        if n_rel > 0:
            rel = np.empty(n_rel, dtype=np.int64)
            a = 0
            for p in range(m):
                if zr[p] and not stuck[p]:
                    rel[a] = p
                    a += 1
            inside = np.zeros(n_rel, dtype=np.bool_)
            _released_forces(A, P, mass, mud, N, ag, base, rel, lam, inside)
            restick = False
            for a in range(n_rel):
                p = rel[a]
                if inside[a]:
                    # holds with less than mu_d N once the others slide: it sticks (and is
                    # released again only beyond mu_s N)
                    stuck[p] = True
                    zr[p] = False
                    forced[p] = False
                    _s_update(S, P, mass, p, 1.0)
                    restick = True
                else:
                    _slide_away(lam, dirn, p)
            if restick:
                continue
        for i in range(r):
            qdd[i] = base[i]
        worst = -1
        worst_ratio = 1.0 + 1e-12
        pa = np.dot(P, qdd)
        for p in range(m):
            if not stuck[p]:
                continue
            for c in range(2):
                j = 2 * p + c
                lam[j] = mass[p] * (pa[j] + ag[c])
            mag = np.sqrt(lam[2 * p] ** 2 + lam[2 * p + 1] ** 2)
            cap = mus[p] * N[p]
            ratio = mag / cap if cap > 0.0 else (np.inf if mag > 0.0 else 0.0)
            if frozen[p] and not forced[p]:
                continue
            if forced[p]:
                ratio += 1e-7 + 1e-12  # released from 1 - 1e-7 of the capacity
            if ratio > worst_ratio:
                worst_ratio = ratio
                worst = p
        if worst < 0:
            break
        stuck[worst] = False
        zr[worst] = True
        _s_update(S, P, mass, worst, -1.0)
        _slide_away(lam, dirn, worst)
    pa = np.dot(P, qdd)
    for p in range(m):
        for c in range(2):
            j = 2 * p + c
            if stuck[p]:
                wdd[j] = pa[j]
            else:
                wdd[j] = -ag[c] + lam[j] / mass[p]


@_JIT
def _slide_away(lam, dirn, p):
    """Direction of sliding opposite to the force ``lam`` of pallet ``p`` (its holding force
    when released from stick, its friction force while sliding)."""
    fx = lam[2 * p]
    fz = lam[2 * p + 1]
    fn = np.sqrt(fx * fx + fz * fz)
    if fn > 0.0:
        dirn[2 * p] = -fx / fn
        dirn[2 * p + 1] = -fz / fn


@_JIT
def _record(old_stuck, stuck, turned, t_e, n_ev, max_events, ev_time, ev_pallet, ev_kind):
    for p in range(stuck.shape[0]):
        kind = -1
        if old_stuck[p] and not stuck[p]:
            kind = KIND_SLIP
        elif stuck[p] and not old_stuck[p]:
            kind = KIND_STICK
        elif turned[p] and not stuck[p]:
            kind = KIND_REVERSE
        if kind >= 0:
            if n_ev < max_events:
                ev_time[n_ev] = t_e
                ev_pallet[n_ev] = p
                ev_kind[n_ev] = kind
            n_ev += 1
    return n_ev


@_JIT
def _classify(stuck, dirn, mus, N, S0, e, cand, forced, old_stuck, turned, c_full, frozen):
    """Pallets whose state must be decided at an event: slip onsets (``forced``, sliding
    opposite to their holding force) and pallets at zero relative velocity (``cand``; a sliding
    one is snapped onto its support's velocity)."""
    wd, lam, s, vn = S0[1], S0[3], S0[4], S0[5]
    old_stuck[:] = stuck
    for p in range(stuck.shape[0]):
        cand[p] = False
        forced[p] = False
        turned[p] = False
        jx = 2 * p
        jz = jx + 1
        if frozen[p] == 2 or (frozen[p] == 1 and not stuck[p]):
            continue
        if stuck[p]:
            mag = np.sqrt(lam[jx] ** 2 + lam[jz] ** 2)
            if frozen[p] == 1:  # released only beyond its capacity, never re-decided
                if mag > mus[p] * N[p]:
                    forced[p] = True
                    _slide_away(lam, dirn, p)
            elif mag - mus[p] * N[p] > -1e-7 * mus[p] * N[p] - 1e-300:
                forced[p] = True
                _slide_away(lam, dirn, p)
            else:
                cand[p] = True
        else:
            vs = (np.sqrt(wd[jx] ** 2 + wd[jz] ** 2) + np.sqrt(vn[jx] ** 2 + vn[jz] ** 2)
                  + 1e-30)
            # a stop, unless the located event is a sharp turn with the pallet still sliding
            # (then nothing changes: the next sub-step starts in the new direction); a stop
            # leaves a velocity across d0 of the order of the turn, snapped to zero when below
            # a tenth of what friction removes in half a step (an O(dt²) displacement)
            sn = np.sqrt(s[jx] ** 2 + s[jz] ** 2)
            if e[p] > -1e-9 * vs and sn <= max(0.1 * c_full[p], 1e-9 * vs):
                cand[p] = True
                turned[p] = True  # marks the snap for _snap_stops (reset by the caller)


@_JIT
def _snap_stops(P, S, mass, T0, S0, stuck, snap):
    """Pallets at a located stop (``snap``, from :func:`_classify`) keep a small relative
    velocity ``s`` (of the order of the location's tolerance; exactly zero when the stop fell
    inside the step's return map): they are snapped onto their supports by one impulsive
    friction contact, all together, the structure with its stuck pallets taking the reaction
    (momentum kept): with ``X = (I + S)⁻¹ P_sᵀ`` (``S`` the stuck pallets' mass in basis
    coordinates) and ``W = diag(1/m) + P_s X``, the impulses are ``J = −W⁻¹ s``; the
    pallets' velocities change by ``J/m``, the structure's by ``−X J`` and the stuck pallets'
    with their supports. Returns the energy the contact dissipates, ``½ sᵀ W⁻¹ s`` (exact:
    the kinetic energy lost), for the friction term."""
    wd, s = S0[1], S0[4]
    k = 0
    for p in range(snap.shape[0]):
        if snap[p] and (s[2 * p] != 0.0 or s[2 * p + 1] != 0.0):
            k += 1
        else:
            snap[p] = False
    if k == 0:
        return 0.0
    r = P.shape[1]
    rows = np.empty(2 * k, dtype=np.int64)
    sv = np.empty(2 * k)
    a = 0
    for p in range(snap.shape[0]):
        if snap[p]:
            for c in range(2):
                rows[2 * a + c] = 2 * p + c
                sv[2 * a + c] = s[2 * p + c]
            a += 1
    W = np.zeros((2 * k, 2 * k))
    X = np.zeros((2 * k, r))  # row a: (I + S)⁻¹ P_aᵀ
    if r > 0:
        L = np.empty((r, r))
        for i in range(r):
            for j in range(i + 1):
                L[i, j] = S[i, j]
            L[i, i] += 1.0
        if not _chol(L):  # not reached: I + S is positive definite
            return 0.0
        for a in range(2 * k):
            for i in range(r):
                X[a, i] = P[rows[a], i]
            _chol_solve(L, X[a])
        for a in range(2 * k):
            for b in range(2 * k):
                W[a, b] = np.dot(P[rows[a]], X[b])
    for a in range(2 * k):
        W[a, a] += 1.0 / mass[rows[a] // 2]
    J = -np.linalg.solve(W, sv)
    lost = -0.5 * np.dot(sv, J)
    if r > 0:
        dqd = np.zeros(r)
        for a in range(2 * k):
            for i in range(r):
                dqd[i] -= X[a, i] * J[a]
        for i in range(r):
            T0[1, i] += dqd[i]
        dvn = np.dot(P, dqd)
        for p in range(stuck.shape[0]):
            if stuck[p]:
                for c in range(2):
                    wd[2 * p + c] += dvn[2 * p + c]
    for a in range(2 * k):
        wd[rows[a]] += J[a] / mass[rows[a] // 2]
    return lost


@_JIT
def _mask_frozen(frozen, stuck, e):
    """No event of a frozen pallet in the rest of the step (its event value masked), except
    a stuck one's slip onset at level 1 (``_frozen_slack``)."""
    for p in range(e.shape[0]):
        if frozen[p] == 2 or (frozen[p] == 1 and not stuck[p]):
            e[p] = -1e300


@_JIT
def _frozen_slack(frozen, stuck, mus, N1, tolF):
    """A stuck pallet frozen at level 1 slips when its force passes mu_s N by
    ``_FROZEN_SLACK``: hovering at mu_s N (the Zeno sequence) is not an event, a force that
    goes on rising is."""
    for p in range(tolF.shape[0]):
        if frozen[p] == 1 and stuck[p]:
            tolF[p] = max(tolF[p], _FROZEN_SLACK * mus[p] * N1[p])


@_JIT
def _track_direction(stuck, S0, dirn):
    """Sliding direction after a sub-step: opposite to the friction force (which is
    -mu_d N ẑ)."""
    lam = S0[3]
    for p in range(stuck.shape[0]):
        if not stuck[p]:
            _slide_away(lam, dirn, p)


@_JIT
def _fill_relative(P, T0, S0):
    """Support velocity ``vn`` and relative velocity ``s`` of the state (after a transition)."""
    wd, s, vn = S0[1], S0[4], S0[5]
    vn[:] = np.dot(P, T0[1])
    for j in range(P.shape[0]):
        s[j] = wd[j] - vn[j]


@_JIT
def _output(k, P, T0, S0, stuck, out_q, out_qd, out_qdd, out_u, out_v, out_lam, out_stuck):
    out_q[k, :] = T0[0]
    out_qd[k, :] = T0[1]
    out_qdd[k, :] = T0[2]
    out_u[k, :] = S0[0] - np.dot(P, T0[0])
    out_v[k, :] = S0[4]
    out_lam[k, :] = S0[3]
    for p in range(stuck.shape[0]):
        out_stuck[k, p] = stuck[p]
