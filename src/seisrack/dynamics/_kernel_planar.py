"""Planar stick–slip kernel: pallets sliding in the horizontal plane with isotropic Coulomb
friction on a linear structure (source shared by the numba and pure-Python backends).

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

try:  # names injected by the loader when executed after ``_events.py``
    _propose  # type: ignore[used-before-def]  # noqa: B018
except NameError:  # pragma: no cover - plain import of this file (pure-Python twin)
    from seisrack.dynamics._events import (
        _JIT,
        KIND_REVERSE,
        KIND_SLIP,
        KIND_STICK,
        STATUS_EVENT_OVERFLOW,
        STATUS_NONFINITE,
        STATUS_OK,
        STATUS_SUBSTEP_LIMIT,
        _accept_values,
        _bracket_end,
        _bracket_open,
        _interp,
        _propose,
        _substep_end,
    )

#: status of a Newton iteration of the planar step that did not converge
STATUS_PLANAR_NEWTON = 4
_NEWTON_MAX = 40
#: transitions of one pallet within one step after which its state is kept to the step's end:
#: at mu_d = mu_s a pallet whose holding force hovers at mu_s N can stop and slide again after
#: ever shorter times (a Zeno sequence); kept, it carries at most a round-off excess over
#: mu_s N, or stops inside its return map, until the next step
_CHATTER = 4


@_JIT
def _chol(a):
    """In-place lower Cholesky factor of the SPD matrix ``a``; False if not positive."""
    n = a.shape[0]
    for j in range(n):
        d = a[j, j]
        for k in range(j):
            d -= a[j, k] * a[j, k]
        if not d > 0.0:
            return False
        d = np.sqrt(d)
        a[j, j] = d
        for i in range(j + 1, n):
            acc = a[i, j]
            for k in range(j):
                acc -= a[i, k] * a[j, k]
            a[i, j] = acc / d
    return True


@_JIT
def _chol_solve(L, x):
    """Solve (L Lᵀ) y = x in place."""
    n = L.shape[0]
    for i in range(n):
        acc = x[i]
        for k in range(i):
            acc -= L[i, k] * x[k]
        x[i] = acc / L[i, i]
    for i in range(n - 1, -1, -1):
        acc = x[i]
        for k in range(i + 1, n):
            acc -= L[k, i] * x[k]
        x[i] = acc / L[i, i]


@_JIT
def _s_update(S, P, mass, p, sign):
    """S += sign · m_p (P_xᵀ P_x + P_zᵀ P_z): the stuck pallets' mass in basis coordinates."""
    r = S.shape[0]
    mp = sign * mass[p]
    for row in (2 * p, 2 * p + 1):
        for i in range(r):
            a = mp * P[row, i]
            if a != 0.0:
                for k in range(r):
                    S[i, k] += a * P[row, k]


@_JIT
def _s_build(S, P, mass, stuck):
    S[:, :] = 0.0
    for p in range(stuck.shape[0]):
        if stuck[p]:
            _s_update(S, P, mass, p, 1.0)


@_JIT
def _sample_row(X, step, frac, out):
    for i in range(out.shape[0]):
        out[i] = _interp(X[step, i], X[step + 1, i], frac)


@_JIT
def _a_lin(A, S, c0, c2, cd, kd):
    """A = diag(c0 + c2 cd + kd) + c0 S: the step's stiffness with the stuck pallets."""
    r = kd.shape[0]
    for i in range(r):
        for k in range(r):
            A[i, k] = c0 * S[i, k]
        A[i, i] += c0 + c2 * cd[i] + kd[i]


@_JIT
def _return_map(p, h, c2, P, mass, mud, N1, zf, dq, dirn, lam, pv, A):
    """Friction of sliding pallet ``p`` at the end of the step for the increment ``dq``:
    ``y = zf - c2 P_p dq`` is its relative velocity without this step's friction; outside the
    disc |y| > c = h mu_d N / (2 m) it slides on, lam = -mu_d N y/|y|; inside, it would stop
    within the step, lam = -(2 m / h) y. Adds the Jacobian of lam (times c2 P_p) to ``A``
    unless ``A`` is empty. Returns c - |y| (> 0: the pallet stops inside the step)."""
    r = P.shape[1]
    jx = 2 * p
    jz = jx + 1
    yx = zf[jx]
    yz = zf[jz]
    for i in range(r):
        yx -= c2 * P[jx, i] * dq[i]
        yz -= c2 * P[jz, i] * dq[i]
    yn = np.sqrt(yx * yx + yz * yz)
    f = mud[p] * N1[p]
    cc = 0.5 * h * f / mass[p]
    if yn > cc and yn > 0.0:
        lam[jx] = -f * yx / yn
        lam[jz] = -f * yz / yn
        if A.shape[0] > 0:
            # rank one, across the direction of sliding
            kap = f * c2 / yn
            tx = -yz / yn
            tz = yx / yn
            for i in range(r):
                pv[i] = P[jx, i] * tx + P[jz, i] * tz
            for i in range(r):
                a = kap * pv[i]
                if a != 0.0:
                    for k in range(r):
                        A[i, k] += a * pv[k]
    else:
        km = 2.0 * mass[p] / h
        lam[jx] = -km * yx
        lam[jz] = -km * yz
        if A.shape[0] > 0:
            a2 = km * c2
            for row in (jx, jz):
                for i in range(r):
                    a = a2 * P[row, i]
                    if a != 0.0:
                        for k in range(r):
                            A[i, k] += a * P[row, k]
    return cc - yn


@_JIT
def _y_of(p, c2, P, zf, dq):
    jx = 2 * p
    jz = jx + 1
    yx = zf[jx]
    yz = zf[jz]
    for i in range(P.shape[1]):
        yx -= c2 * P[jx, i] * dq[i]
        yz -= c2 * P[jz, i] * dq[i]
    return yx, yz


@_JIT
def _huber(p, h, c2, P, mass, mud, N1, zf, dq):
    """Friction potential of sliding pallet ``p``: (m/h)|y|² inside the disc |y| <= c,
    (2m/h)(c|y| - c²/2) outside (its gradient in y is -lam)."""
    yx, yz = _y_of(p, c2, P, zf, dq)
    yn = np.sqrt(yx * yx + yz * yz)
    cc = 0.5 * h * mud[p] * N1[p] / mass[p]
    if yn <= cc:
        return mass[p] / h * yn * yn
    return 2.0 * mass[p] / h * (cc * yn - 0.5 * cc * cc)


@_JIT
def _quad_lin(S, c0, c2, cd, kd, x):
    """xᵀ A x with A = diag(c0 + c2 cd + kd) + c0 S."""
    r = x.shape[0]
    val = 0.0
    for i in range(r):
        acc = (c0 + c2 * cd[i] + kd[i]) * x[i]
        for k in range(r):
            acc += c0 * S[i, k] * x[k]
        val += x[i] * acc
    return val


@_JIT
def _dot_grad(rhs, S, c0, c2, cd, kd, dq, P, lam, stuck, step):
    """Directional derivative of the potential at ``dq`` along ``step`` (gradient: the
    residual A dq - rhs + Σ P_pᵀ lam_p, with ``lam`` evaluated at ``dq``)."""
    r = dq.shape[0]
    val = 0.0
    for i in range(r):
        acc = (c0 + c2 * cd[i] + kd[i]) * dq[i] - rhs[i]
        for k in range(r):
            acc += c0 * S[i, k] * dq[k]
        for p in range(stuck.shape[0]):
            if not stuck[p]:
                acc += P[2 * p, i] * lam[2 * p] + P[2 * p + 1, i] * lam[2 * p + 1]
        val += acc * step[i]
    return val


@_JIT
def _trial(h, kd, cd, P, mass, mus, mud, S, T0, S0, N0, stuck, dirn, ag1, pext1, N1,
           T1, S1, e, tolF, dt, W, A):
    """One Newmark step of length ``h`` with a fixed contact state, from (T0, S0) to (T1, S1).

    T rows: q, qd, qdd (r); S rows: w, wd, wdd, lam, s (relative velocity), vn (support
    velocity) (2m). Writes the event values ``e`` (positive when the state is violated) and
    their thresholds ``tolF``. ``W`` (9, max(r, 2m)) and ``A`` (r, r) are scratch. Returns
    0, or 1 when the step matrix is not positive definite, 2 when Newton's iteration on the
    sliding directions did not converge.
    """
    r = kd.shape[0]
    m = mass.shape[0]
    c0 = 4.0 / (h * h)
    c1 = 4.0 / h
    c2 = 2.0 / h
    q0, qd0, qdd0 = T0[0], T0[1], T0[2]
    w0, wd0, wdd0 = S0[0], S0[1], S0[2]
    rhs, dq, res, pv = W[0, :r], W[1, :r], W[2, :r], W[3, :r]
    pq, zf, lam = W[4, :2 * m], W[5, :2 * m], W[6, :2 * m]
    for i in range(r):
        rhs[i] = pext1[i] + c1 * qd0[i] + qdd0[i] + cd[i] * qd0[i] - kd[i] * q0[i]
    for j in range(2 * m):
        acc = 0.0
        for i in range(r):
            acc += P[j, i] * qd0[i]
        pq[j] = acc
    n_slide = 0
    for p in range(m):
        for c in range(2):
            j = 2 * p + c
            if stuck[p]:
                # lam = m c0 P dq + beta: the stuck pallet is a mass on its support
                beta = mass[p] * (-c2 * pq[j] - c2 * wd0[j] - wdd0[j] + ag1[c])
                for i in range(r):
                    rhs[i] -= P[j, i] * beta
            else:
                zf[j] = wd0[j] + 0.5 * h * (wdd0[j] - ag1[c]) + pq[j]
                lam[j] = -mud[p] * N1[p] * dirn[j]  # first iterate: the current direction
        if not stuck[p]:
            n_slide += 1
    # Semismooth Newton on dq: R = A dq - rhs + sum_F P_pᵀ lam_p(y_p), y_p = zf_p - c2 P_p dq,
    # lam_p = -(2 m / h) clip(y_p, c) (the return map, continuous and monotone in y_p); the
    # first iterate takes the friction of the start of the step
    for i in range(r):
        res[i] = rhs[i]
    for p in range(m):
        if not stuck[p]:
            for c in range(2):
                j = 2 * p + c
                for i in range(r):
                    res[i] -= P[j, i] * lam[j]
    _a_lin(A, S, c0, c2, cd, kd)
    if not _chol(A):
        return 1
    _chol_solve(A, res)
    for i in range(r):
        dq[i] = res[i]
    converged = n_slide == 0
    # the equation is the gradient of a strictly convex potential (the friction term is a
    # Huber function of y_p): Newton's steps are damped by backtracking on it, which cures
    # the cycling of plain Newton across the disc
    trial, rlin = W[7, :r], W[8, :r]
    for _it in range(_NEWTON_MAX if n_slide > 0 else 0):
        _a_lin(A, S, c0, c2, cd, kd)
        for i in range(r):
            acc = rhs[i]
            for k in range(r):
                acc -= A[i, k] * dq[k]
            res[i] = acc
            rlin[i] = acc
        ymax = 0.0
        hub0 = 0.0
        for p in range(m):
            if stuck[p]:
                continue
            _return_map(p, h, c2, P, mass, mud, N1, zf, dq, dirn, lam, pv, A)
            hub0 += _huber(p, h, c2, P, mass, mud, N1, zf, dq)
            for c in range(2):
                j = 2 * p + c
                for i in range(r):
                    res[i] -= P[j, i] * lam[j]
            ymax = max(ymax, abs(zf[2 * p]) + abs(zf[2 * p + 1])
                       + mud[p] * N1[p] * h / mass[p])
        if not _chol(A):
            return 1
        _chol_solve(A, res)  # res now holds the Newton step
        # change of the potential along the step, without forming the potential itself
        # (its linear part is large and would cancel): a alin1 + a² alin2 / 2 + Δhuber / c2
        lin1 = 0.0
        slope = 0.0
        for i in range(r):
            lin1 -= rlin[i] * res[i]
        slope = _dot_grad(rhs, S, c0, c2, cd, kd, dq, P, lam, stuck, res)
        lin2 = _quad_lin(S, c0, c2, cd, kd, res)
        alpha = 1.0
        for _ls in range(40):
            for i in range(r):
                trial[i] = dq[i] + alpha * res[i]
            hub1 = 0.0
            for p in range(m):
                if not stuck[p]:
                    hub1 += _huber(p, h, c2, P, mass, mud, N1, zf, trial)
            dpi = alpha * lin1 + 0.5 * alpha * alpha * lin2 + (hub1 - hub0) / c2
            if dpi <= 1e-4 * alpha * slope + 1e-14 * (abs(hub0) / c2 + abs(lin2)):
                break
            alpha *= 0.5
        step = 0.0
        for i in range(r):
            dq[i] = trial[i]
        for p in range(m):
            if stuck[p]:
                continue
            for c in range(2):
                acc = 0.0
                for i in range(r):
                    acc += P[2 * p + c, i] * res[i]
                step = max(step, abs(c2 * alpha * acc))
        if step <= 1e-12 * ymax + 1e-300:
            converged = True
            break
    for p in range(m):
        if not stuck[p]:
            _return_map(p, h, c2, P, mass, mud, N1, zf, dq, dirn, lam, pv, A[:0, :0])
    # end state
    q1, qd1, qdd1 = T1[0], T1[1], T1[2]
    w1, wd1, wdd1, lam1, s1, vn1 = S1[0], S1[1], S1[2], S1[3], S1[4], S1[5]
    for i in range(r):
        q1[i] = q0[i] + dq[i]
        qd1[i] = c2 * dq[i] - qd0[i]
        qdd1[i] = c0 * dq[i] - c1 * qd0[i] - qdd0[i]
    for j in range(2 * m):
        acc = 0.0
        for i in range(r):
            acc += P[j, i] * qd1[i]
        vn1[j] = acc
    for p in range(m):
        for c in range(2):
            j = 2 * p + c
            if stuck[p]:
                wd1[j] = vn1[j]
                wdd1[j] = c2 * (wd1[j] - wd0[j]) - wdd0[j]
                lam1[j] = mass[p] * (wdd1[j] + ag1[c])
            else:
                lam1[j] = lam[j]
                wdd1[j] = -ag1[c] + lam1[j] / mass[p]
                wd1[j] = wd0[j] + 0.5 * h * (wdd0[j] + wdd1[j])
            w1[j] = w0[j] + h * wd0[j] + 0.25 * h * h * (wdd0[j] + wdd1[j])
            s1[j] = wd1[j] - vn1[j]
        jx = 2 * p
        jz = jx + 1
        if stuck[p]:
            e[p] = np.sqrt(lam1[jx] ** 2 + lam1[jz] ** 2) - mus[p] * N1[p]
            tolF[p] = 1e-11 * mus[p] * max(N0[p], N1[p]) + 1e-300
        else:
            # z = s1 - h lam1 / (2 m): the relative velocity without this step's friction
            zx = s1[jx] - 0.5 * h * lam1[jx] / mass[p]
            zz = s1[jz] - 0.5 * h * lam1[jz] / mass[p]
            cc = 0.5 * h * mud[p] * N1[p] / mass[p]
            # c - d0·z with d0 the direction at the start of the sub-step: positive when the
            # pallet stops inside the step (|z| < c) or its velocity turns by more than about
            # a right angle (it passed near zero between the step ends, where a stop could hide)
            e[p] = cc - (dirn[jx] * zx + dirn[jz] * zz)
            vs = (np.sqrt(wd1[jx] ** 2 + wd1[jz] ** 2) + np.sqrt(vn1[jx] ** 2 + vn1[jz] ** 2)
                  + mud[p] * N1[p] / mass[p] * dt)
            # the second term: just after a slip onset with mu_d = mu_s, e starts at
            # c (1 - |lam|/(mu_s N)), within the onset tolerance 1e-7 of zero
            tolF[p] = 1e-9 * vs + 1e-6 * cc
    return 0 if converged else 2


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
def _decide(kd, cd, P, mass, mus, mud, S, T0, S0, ag, pext, N, stuck, dirn, cand, forced,
            A, base, frozen):
    """Contact state at an instant and consistent accelerations (active set).

    ``cand``: pallets at zero relative velocity to be decided (they stick when the force that
    keeps them stuck is within mu_s N, else slide opposite to it); ``forced``: stuck pallets
    whose slip onset was just located (at mu_s N to the location's tolerance). Every one starts
    stuck and the most overloaded is released, one at a time, the forced ones from 1 - 1e-7 of
    their capacity: when several reach their threshold together, releasing one can unload the
    others (an all-at-once release chattered, each pallet re-sticking at once). Updates
    ``stuck``, ``dirn`` and ``S`` (the stuck pallets' mass); writes qdd, wdd and lam.
    ``frozen`` pallets keep their state (see ``_CHATTER``).
    """
    r = kd.shape[0]
    m = mass.shape[0]
    q, qd, qdd = T0[0], T0[1], T0[2]
    wdd, lam = S0[2], S0[3]
    for p in range(m):
        if cand[p] and not stuck[p]:
            stuck[p] = True
            _s_update(S, P, mass, p, 1.0)
    for _it in range(2 * m + 2):
        # (I + S) qdd = pext - C qd - K q - sum_F P_pᵀ lam_p - sum_S m_p P_pᵀ ag
        for i in range(r):
            base[i] = pext[i] - cd[i] * qd[i] - kd[i] * q[i]
        for p in range(m):
            for c in range(2):
                j = 2 * p + c
                if stuck[p]:
                    f = mass[p] * ag[c]
                else:
                    f = -mud[p] * N[p] * dirn[j]
                    lam[j] = f
                for i in range(r):
                    base[i] -= P[j, i] * f
        for i in range(r):
            for k in range(r):
                A[i, k] = S[i, k]
            A[i, i] += 1.0
        _chol(A)
        _chol_solve(A, base)
        for i in range(r):
            qdd[i] = base[i]
        worst = -1
        worst_ratio = 1.0 + 1e-12
        for p in range(m):
            if not stuck[p]:
                continue
            for c in range(2):
                j = 2 * p + c
                acc = 0.0
                for i in range(r):
                    acc += P[j, i] * qdd[i]
                lam[j] = mass[p] * (acc + ag[c])
            mag = np.sqrt(lam[2 * p] ** 2 + lam[2 * p + 1] ** 2)
            cap = mus[p] * N[p]
            ratio = mag / cap if cap > 0.0 else (np.inf if mag > 0.0 else 0.0)
            if frozen[p]:
                continue
            if forced[p]:
                ratio += 1e-7 + 1e-12  # released from 1 - 1e-7 of the capacity
            if ratio > worst_ratio:
                worst_ratio = ratio
                worst = p
        if worst < 0:
            break
        stuck[worst] = False
        _s_update(S, P, mass, worst, -1.0)
        _slide_away(lam, dirn, worst)
    for p in range(m):
        for c in range(2):
            j = 2 * p + c
            if stuck[p]:
                acc = 0.0
                for i in range(r):
                    acc += P[j, i] * qdd[i]
                wdd[j] = acc
            else:
                wdd[j] = -ag[c] + lam[j] / mass[p]


@_JIT
def _slide_away(lam, dirn, p):
    """Sliding direction of a pallet released from stick: opposite to its holding force."""
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
def run_planar(kd, cd, P, mass, mus, mud, dt, agx, agz, pext, N, resume, T_state, S_state,
               stuck, dirn, S, t_offset, max_events, max_substeps,
               out_q, out_qd, out_qdd, out_u, out_v, out_lam, out_stuck,
               ev_time, ev_pallet, ev_kind):
    """Integrate ``agx.shape[0] - 1`` steps. Returns (status, n_events, n_substeps, the last
    output row written).

    agx, agz: (n_t,) ground accelerations down-aisle (x) and cross-aisle (z); pext: (n_t, r)
    modal loads; N: (n_t, m) normal forces. The state (``T_state`` (3, r): q, qd, qdd;
    ``S_state`` (6, 2m): w, wd, wdd, lam, s, vn; ``stuck``, ``dirn``, ``S``) is read when
    ``resume`` (else the pallets start stuck on a structure at the given q, qd) and written
    back at the end, so chunks continue exactly. Outputs per step (n_t rows): q, qd, qdd,
    u (sliding displacement w - P q), v (relative velocity), lam (friction force on the
    pallet), stuck.
    """
    r = kd.shape[0]
    m = mass.shape[0]
    n_t = agx.shape[0]
    nw = max(r, 2 * m, 1)
    W = np.empty((9, nw))
    A = np.empty((r, r))
    T0 = T_state.copy()
    S0 = S_state.copy()
    T1 = np.empty_like(T0)
    S1 = np.empty_like(S0)
    Tb = np.empty_like(T0)
    Sb = np.empty_like(S0)
    e_lo = np.empty(m)
    e_hi = np.empty(m)
    e_try = np.empty(m)
    tolF = np.empty(m)
    tolT = np.empty(m)
    c_full = np.empty(m)
    br = np.empty(6)
    cand = np.zeros(m, dtype=np.bool_)
    forced = np.zeros(m, dtype=np.bool_)
    turned = np.zeros(m, dtype=np.bool_)
    old_stuck = stuck.copy()
    ag = np.empty(2)
    pe = np.empty(r)
    Ne = np.empty(m)
    N0 = np.empty(m)
    n_ev = 0
    n_sub = 0
    status = STATUS_OK
    if not resume:
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
        _decide(kd, cd, P, mass, mus, mud, S, T0, S0, ag, pext[0], N[0], stuck, dirn,
                cand, forced, A, pe, forced)
        for p in range(m):
            old_stuck[p] = True  # "slip" at t = 0 for pallets released at once
            cand[p] = False
        n_ev = _record(old_stuck, stuck, turned, t_offset, n_ev, max_events,
                       ev_time, ev_pallet, ev_kind)
        _fill_relative(P, T0, S0)
    _output(0, P, T0, S0, stuck, out_q, out_qd, out_qdd, out_u, out_v, out_lam, out_stuck)
    k_done = 0
    n_tr = np.zeros(m, dtype=np.int64)
    frozen = np.zeros(m, dtype=np.bool_)
    for k in range(n_t - 1):
        tau = 0.0
        n_here = 0
        for p in range(m):
            n_tr[p] = 0
            frozen[p] = False
        while True:
            hrem = (1.0 - tau) * dt
            for p in range(m):
                N0[p] = _interp(N[k, p], N[k + 1, p], tau)
            ag[0] = agx[k + 1]
            ag[1] = agz[k + 1]
            ok = _trial(hrem, kd, cd, P, mass, mus, mud, S, T0, S0, N0, stuck, dirn, ag,
                        pext[k + 1], N[k + 1], T1, S1, e_hi, tolF, dt, W, A)
            _mask_frozen(frozen, e_hi)
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
                _bracket_open(br, T1, S1, Tb, Sb)
                for _loc in range(200):
                    th = _propose(br, stuck, e_lo, e_hi, tolF, mus, N[k + 1], hrem, dt)
                    if th < 0.0:
                        break
                    frac = tau + th * (1.0 - tau)
                    ag[0] = _interp(agx[k], agx[k + 1], frac)
                    ag[1] = _interp(agz[k], agz[k + 1], frac)
                    _sample_row(pext, k, frac, pe)
                    for p in range(m):
                        Ne[p] = _interp(N[k, p], N[k + 1, p], frac)
                    ok = _trial(th * hrem, kd, cd, P, mass, mus, mud, S, T0, S0, N0, stuck,
                                dirn, ag, pe, Ne, T1, S1, e_try, tolT, dt, W, A)
                    _mask_frozen(frozen, e_try)
                    if ok != 0:
                        status = STATUS_PLANAR_NEWTON + ok - 1
                        break
                    _accept_values(br, th, e_try, tolF, e_lo, e_hi, T1, S1, Tb, Sb)
                if status != STATUS_OK:
                    break
                th_hi = _bracket_end(br, T1, S1, Tb, Sb)
            T0[:] = T1
            S0[:] = S1
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
                _decide(kd, cd, P, mass, mus, mud, S, T0, S0, ag, pe, Ne, stuck, dirn,
                        cand, forced, A, W[7, :r], frozen)
                for p in range(m):
                    # a pallet that reached zero velocity and slides on has turned
                    turned[p] = cand[p] and not stuck[p] and not old_stuck[p]
                    # events of p in this step, with or without a change of state (a
                    # located sharp turn changes none)
                    if turned[p] or stuck[p] != old_stuck[p] or e_hi[p] >= -tolF[p]:
                        n_tr[p] += 1
                        if n_tr[p] >= _CHATTER:
                            frozen[p] = True
                n_ev = _record(old_stuck, stuck, turned, t_offset + (k + tau) * dt, n_ev,
                               max_events, ev_time, ev_pallet, ev_kind)
                _fill_relative(P, T0, S0)
            if tau >= 1.0:
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
        k_done = k + 1
        if not np.isfinite(T0[0, 0]):
            status = STATUS_NONFINITE
            break
    if n_ev > max_events and status == STATUS_OK:
        status = STATUS_EVENT_OVERFLOW
    T_state[:] = T0
    S_state[:] = S0
    return status, n_ev, n_sub, k_done


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
        if frozen[p]:
            continue
        if stuck[p]:
            mag = np.sqrt(lam[jx] ** 2 + lam[jz] ** 2)
            if mag - mus[p] * N[p] > -1e-7 * mus[p] * N[p] - 1e-300:
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
                wd[jx] = vn[jx]
                wd[jz] = vn[jz]
                s[jx] = 0.0
                s[jz] = 0.0


@_JIT
def _mask_frozen(frozen, e):
    for p in range(e.shape[0]):
        if frozen[p]:
            e[p] = -1e300


@_JIT
def _track_direction(stuck, S0, dirn):
    """Sliding direction after a sub-step: opposite to the friction force (which is
    -mu_d N ẑ)."""
    lam = S0[3]
    for p in range(stuck.shape[0]):
        if not stuck[p]:
            fx = lam[2 * p]
            fz = lam[2 * p + 1]
            fn = np.sqrt(fx * fx + fz * fz)
            if fn > 0.0:
                dirn[2 * p] = -fx / fn
                dirn[2 * p + 1] = -fz / fn


@_JIT
def _fill_relative(P, T0, S0):
    """Support velocity ``vn`` and relative velocity ``s`` of the state (after a transition)."""
    qd = T0[1]
    wd, s, vn = S0[1], S0[4], S0[5]
    for j in range(P.shape[0]):
        acc = 0.0
        for i in range(P.shape[1]):
            acc += P[j, i] * qd[i]
        vn[j] = acc
        s[j] = wd[j] - acc


@_JIT
def _output(k, P, T0, S0, stuck, out_q, out_qd, out_qdd, out_u, out_v, out_lam, out_stuck):
    out_q[k, :] = T0[0]
    out_qd[k, :] = T0[1]
    out_qdd[k, :] = T0[2]
    q = T0[0]
    w = S0[0]
    for j in range(P.shape[0]):
        acc = 0.0
        for i in range(P.shape[1]):
            acc += P[j, i] * q[i]
        out_u[k, j] = w[j] - acc
    out_v[k, :] = S0[4]
    out_lam[k, :] = S0[3]
    for p in range(stuck.shape[0]):
        out_stuck[k, p] = stuck[p]
