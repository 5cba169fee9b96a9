"""The local engine's time loop (source shared by the numba and the pure-Python backends;
theory: ``docs/theory/local_engine.md`` §3–§4).

Per step: the trapezoidal rule in impulse form on the basis coordinates (block-tridiagonal
matrices, ``_btd.py``), each pallet's impulse resolved on its own (``_pallet.py``), the two
coupled by Newton's method on the structure's velocity change with a line search.
"""

# ruff: noqa: N803, N806  (matrix names follow the equations)

import numpy as np

try:  # names injected by the loader when executed after ``_btd.py`` and ``_pallet.py``
    _btd_factor  # type: ignore[used-before-def]  # noqa: B018
except NameError:  # pragma: no cover - plain import of this file (pure-Python twin)
    from seisrack.dynamics.local._btd import (
        _JIT,
        _btd_combine,
        _btd_condensed,
        _btd_factor,
        _btd_matvec,
        _btd_solve,
        _trsv_lower,
    )
    from seisrack.dynamics.local._pallet import _EV_SLIP, _EV_STICK, _pallet_solve

STATUS_OK = 0
STATUS_EVENT_OVERFLOW = 1
STATUS_NEWTON = 2
STATUS_NONFINITE = 3
STATUS_NOT_PD = 4
_NEWTON_MAX = 60
#: Newton iterations after which a stalled step freezes its pallets' slip onsets too
_NEWTON_FREEZE = 15
#: Newton iterations of each solve of a step retried with its onsets placed one at a time
_RETRY_MAX = 30
#: the static friction coefficient of a pallet held stuck through a retried step (finite: its
#: square times N² stays finite in the onset test)
_HELD = 1e100
#: a step not converged to _NEWTON_TOL in _NEWTON_MAX iterations is accepted when its last
#: Newton increment is below this fraction of the velocities (counted in the work)
_NEWTON_LOOSE = 1e-6
#: Newton stops when its step is below this fraction of the velocities (1e-11 cost a third
#: more iterations than 1e-9 on the warehouse rack for no change of the results)
_NEWTON_TOL = 1e-9
#: a pallet whose local solution ends stuck but whose impulse leaves it behind its support by
#: more than this fraction of its velocity scale ends the step sliding instead (see the commit)
_STUCK_SLACK = 1e-9
#: fields of a pallet's local solution (``_pallet_solve``'s ``out``)
_NOUT = 19
DEBUG = False
WARM = True
DEBUG_STEP = -1


@_JIT
def _support(P, p, s0, b, x, d):
    acc = 0.0
    for i in range(b):
        acc += P[p, d, i] * x[s0 + i]
    return acc


@_JIT
def _stuck_row(D, p, mp, nd):
    """Row p of D (m, 4): ∂J/∂y of a pallet stuck through the step, its mass (m I)."""
    D[p, 0] = mp
    D[p, 1] = 0.0
    D[p, 2] = 0.0
    D[p, 3] = mp if nd == 2 else 0.0


@_JIT
def _psd_row(D, p, mp):
    """Row p of D (m, 4), a 2 × 2 ∂J/∂y, symmetrised with its eigenvalues clipped to [0, m]
    (the pallet's own mass bounds a monotone part; a start-of-step matrix needs no more)."""
    a = D[p, 0]
    b = 0.5 * (D[p, 1] + D[p, 2])
    c = D[p, 3]
    if not (np.isfinite(a) and np.isfinite(b) and np.isfinite(c)):
        a, b, c = mp, 0.0, mp  # a finite difference across a jump: the stuck pallet's
    tr = 0.5 * (a + c)
    dif = 0.5 * (a - c)
    rad = np.sqrt(dif * dif + b * b)
    l1 = min(max(tr + rad, 0.0), mp)
    l2 = min(max(tr - rad, 0.0), mp)
    if rad == 0.0:
        D[p, 0] = l1
        D[p, 1] = 0.0
        D[p, 2] = 0.0
        D[p, 3] = l2
        return
    ang = 0.5 * np.arctan2(b, dif)
    cs = np.cos(ang)
    sn = np.sin(ang)
    D[p, 0] = l1 * cs * cs + l2 * sn * sn
    D[p, 1] = (l1 - l2) * cs * sn
    D[p, 2] = D[p, 1]
    D[p, 3] = l1 * sn * sn + l2 * cs * cs


@_JIT
def _assemble_H(Ad, Ao, Hd, Ho, sizes, P, ps, Dp, nd):
    """H = A + Σ_p P_pᵀ D_p P_p (D_p: (m, 4) row-major 2 × 2, symmetrised). Only the lower
    triangles of the diagonal blocks are written: the factorisations read no more."""
    ns = sizes.shape[0]
    for s in range(ns):
        b = sizes[s]
        for i in range(b):
            for k in range(i + 1):
                Hd[s, i, k] = Ad[s, i, k]
        if s + 1 < ns:
            bn = sizes[s + 1]
            for i in range(b):
                for k in range(bn):
                    Ho[s, i, k] = Ao[s, i, k]
    for p in range(ps.shape[0]):
        s = ps[p]
        b = sizes[s]
        d00 = Dp[p, 0]
        d01 = 0.0
        d11 = 0.0
        if nd == 2:
            d01 = 0.5 * (Dp[p, 1] + Dp[p, 2])
            d11 = Dp[p, 3]
        if d00 == 0.0 and d01 == 0.0 and d11 == 0.0:
            continue
        P0 = P[p, 0]
        P1 = P[p, 1]
        H = Hd[s]
        for i in range(b):
            # row i of Pᵀ D P: (Pᵀ D)_i · P, both directions in one sweep
            c0 = d00 * P0[i] + d01 * P1[i]
            c1 = d01 * P0[i] + d11 * P1[i]
            if c0 == 0.0 and c1 == 0.0:
                continue
            for k in range(i + 1):
                H[i, k] += c0 * P0[k] + c1 * P1[k]


@_JIT
def _own_compliance(Ld, P, p, s, b, nd, Dp, t1, t2):
    """G_p = P_p H_{−p}⁻¹ P_pᵀ from slice s's block with both sides condensed, L_ss L_ssᵀ =
    ((H⁻¹)_ss)⁻¹ (``_btd_condensed``, §4.1):
    g = P (L Lᵀ)⁻¹ Pᵀ, then the pallet's own D removed, G = (g⁻¹ − D)⁻¹. Returns g11, g12,
    g22."""
    for i in range(b):
        t1[i] = P[p, 0, i]
        t2[i] = P[p, 1, i] if nd == 2 else 0.0
    _trsv_lower(Ld[s], b, t1)
    a11 = 0.0
    a12 = 0.0
    a22 = 0.0
    for i in range(b):
        a11 += t1[i] * t1[i]
    if nd == 2:
        _trsv_lower(Ld[s], b, t2)
        for i in range(b):
            a12 += t1[i] * t2[i]
            a22 += t2[i] * t2[i]
    if a11 <= 0.0:
        return 0.0, 0.0, 0.0
    if nd == 1:
        inv = 1.0 / a11 - Dp[p, 0]
        return (1.0 / inv if inv > 0.0 else a11), 0.0, 0.0
    det = a11 * a22 - a12 * a12
    i11 = a22 / det - Dp[p, 0]
    i12 = -a12 / det - 0.5 * (Dp[p, 1] + Dp[p, 2])
    i22 = a11 / det - Dp[p, 3]
    d2 = i11 * i22 - i12 * i12
    if not (d2 > 0.0 and i11 > 0.0):
        return a11, a12, a22
    return i22 / d2, -i12 / d2, i11 / d2


@_JIT
def _eval_pallets(dv, offsets, sizes, P, ps, nd, h, mass, mus, mud, Nk0, Nk1, agp0, agp1,
                  stuck, sv, dirn, jerk, beta, nprev, Gc, gstamp, stamp, Ld, Dp, outs, ev, t1,
                  t2, stats, want_D):
    """Every pallet's local solution for the structure's velocity change ``dv`` (warm
    started from the β already in its row of ``outs``; ∂J/∂y written when ``want_D``)."""
    _eval_range(0, ps.shape[0], dv, offsets, sizes, P, ps, nd, h, mass, mus, mud, Nk0, Nk1,
                agp0, agp1, stuck, sv, dirn, jerk, beta, nprev, Gc, gstamp, stamp, Ld, Dp,
                outs, ev, t1, t2, stats, want_D)


@_JIT
def _eval_range(p0, p1, dv, offsets, sizes, P, ps, nd, h, mass, mus, mud, Nk0, Nk1, agp0,
                agp1, stuck, sv, dirn, jerk, beta, nprev, Gc, gstamp, stamp, Ld, Dp, outs, ev,
                t1, t2, stats, want_D):
    """Pallets ``p0`` to ``p1 − 1``'s local solutions into their rows of ``outs`` (see
    ``_eval_pallets``). One loop, not a call per pallet: a call passes some thirty arrays,
    and each costs numba a reference-count increment and decrement (atomic; they were about
    a tenth of the run on the 150-pallet example)."""
    for p in range(p0, p1):
        s = ps[p]
        o = offsets[s]
        b = sizes[s]
        yx = 0.0
        yz = 0.0
        for i in range(b):
            yx += P[p, 0, i] * dv[o + i]
            if nd == 2:
                yz += P[p, 1, i] * dv[o + i]
        row = outs[p]
        # the support's reference accelerations of the two previous steps (the contact
        # decisions' filter, _pallet.py), when both are of the pallet's present state
        usef = nprev[p] >= 2
        bpx = beta[p, 0]
        bpz = beta[p, 1]
        bqx = bpx - h * jerk[p, 2]
        bqz = bpz - h * jerk[p, 3]
        if stuck[p]:
            fast = _pallet_solve(yx, yz, True, 0.0, 0.0, dirn[p, 0], dirn[p, 1], h, mass[p],
                                 mus[p], mud[p], Nk0[p], Nk1[p], agp0[0], agp0[1], agp1[0],
                                 agp1[1], jerk[p, 0], jerk[p, 1], bpx, bpz, bqx, bqz, usef,
                                 0.0, 0.0, 0.0, nd, ev[p], row, False, want_D)
            if fast:
                continue
        if gstamp[p] != stamp:
            g11, g12, g22 = _own_compliance(Ld, P, p, s, b, nd, Dp, t1, t2)
            Gc[p, 0] = g11
            Gc[p, 1] = g12
            Gc[p, 2] = g22
            gstamp[p] = stamp
        stats[3] += 1
        _pallet_solve(yx, yz, stuck[p], sv[p, 0], sv[p, 1], dirn[p, 0], dirn[p, 1], h,
                      mass[p], mus[p], mud[p], Nk0[p], Nk1[p], agp0[0], agp0[1], agp1[0],
                      agp1[1], jerk[p, 0], jerk[p, 1], bpx, bpz, bqx, bqz, usef, Gc[p, 0],
                      Gc[p, 1], Gc[p, 2], nd, ev[p], row, WARM, want_D)


@_JIT
def _residual(Ad, Ao, sizes, offsets, dv, rhs, P, ps, nd, outs, R):
    """R = A dv − rhs + Σ_p P_pᵀ J_p."""
    for i in range(R.shape[0]):
        R[i] = -rhs[i]
    _btd_matvec(Ad, Ao, sizes, offsets, dv, R, 1.0)
    for p in range(ps.shape[0]):
        s = ps[p]
        o = offsets[s]
        for d in range(nd):
            J = outs[p, d]
            if J != 0.0:
                for i in range(sizes[s]):
                    R[o + i] += P[p, d, i] * J


@_JIT
def _newton(k, maxit, freeze, Ad, Ao, Hd, Ho, sizes, offsets, P, ps, nd, h, mass, mus_k, mud,
            Nk0, Nk1, agp, stuck, sv, dirn, jerk, beta, nprev, Gc, gstamp, stamp, Le, Dp, Dn,
            Ld, X, Ld2, X2, outs, outs_n, ev, t1, t2, stats, rhs, dv, R, Rn, dlt, tmp,
            vscale):
    """Newton's method on the step's residual from ``dv`` (with ``outs`` and ``R`` its
    evaluation), the factor ``Ld``, ``X`` of the Newton matrix given; ``freeze``: a stalled
    iteration freezes the contacts of pallets with events (``mus_k``). Returns (converged,
    what the last step left of its way to the root: (1 − α) of it after a damped step, so
    that a line search stalled near α = 0 is neither converged nor loose)."""
    N = dv.shape[0]
    m = ps.shape[0]
    converged = False
    prev = -1.0
    left = -1.0  # the last step's distance to the root (what the loose acceptance reads)
    refac = False
    for _it in range(maxit):
        stats[1] += 1
        if refac:
            # a poor contraction: the Newton matrix with the pallets' current ∂J/∂y
            # (an onset with mu_d < mu_s makes ∂J/∂y negative, bounded by the support's
            # own stiffness: H stays positive definite, §4.3; if finite differences across
            # a kink break that, the clipped ∂J/∂y is used)
            _eval_pallets(dv, offsets, sizes, P, ps, nd, h, mass, mus_k, mud, Nk0, Nk1,
                          agp[k], agp[k + 1], stuck, sv, dirn, jerk, beta, nprev,
                          Gc, gstamp, stamp,
                          Le, Dp, outs, ev, t1, t2, stats, True)
            for attempt in range(2):
                for p in range(m):
                    for c in range(4):
                        Dn[p, c] = outs[p, 2 + c]
                    if attempt == 1:
                        _psd_row(Dn, p, mass[p])
                    if nd == 1:
                        Dn[p, 1] = 0.0
                        Dn[p, 2] = 0.0
                        Dn[p, 3] = 0.0
                _assemble_H(Ad, Ao, Hd, Ho, sizes, P, ps, Dn, nd)
                stats[2] += 1
                if _btd_factor(Hd, Ho, sizes, Ld2, X2):
                    Ld[:] = Ld2
                    X[:] = X2
                    break
            refac = False
        for i in range(N):
            dlt[i] = -R[i]
        _btd_solve(Ld, X, sizes, offsets, dlt)
        g0 = 0.0
        dmax = 0.0
        dvmax = 0.0
        for i in range(N):
            g0 += R[i] * dlt[i]
            dmax = max(dmax, abs(dlt[i]))
            dvmax = max(dvmax, abs(dv[i]))
        if dmax <= _NEWTON_TOL * max(vscale, dvmax):
            # the last evaluation (at dv) stands: converged
            converged = True
            break
        # trial point
        for i in range(N):
            tmp[i] = dv[i] + dlt[i]
        _eval_pallets(tmp, offsets, sizes, P, ps, nd, h, mass, mus_k, mud, Nk0, Nk1,
                      agp[k], agp[k + 1], stuck, sv, dirn, jerk, beta, nprev,
                      Gc, gstamp, stamp, Le,
                      Dp, outs_n, ev, t1, t2, stats, False)
        _residual(Ad, Ao, sizes, offsets, tmp, rhs, P, ps, nd, outs_n, Rn)
        g1 = 0.0
        for i in range(N):
            g1 += Rn[i] * dlt[i]
        alpha = 1.0
        if g0 < 0.0 and g1 > 0.5 * abs(g0):
            # line search: root of g(α) = R(dv + α δ)·δ (increasing along δ)
            lo = 0.0
            glo = g0
            hi = 1.0
            ghi = g1
            side = 0
            for _ls in range(40):
                stats[4] += 1
                alpha = lo - glo * (hi - lo) / (ghi - glo)
                for i in range(N):
                    tmp[i] = dv[i] + alpha * dlt[i]
                _eval_pallets(tmp, offsets, sizes, P, ps, nd, h, mass, mus_k, mud, Nk0,
                              Nk1, agp[k], agp[k + 1], stuck, sv, dirn, jerk, beta, nprev,
                              Gc, gstamp,
                              stamp, Le, Dp, outs_n, ev, t1, t2, stats, False)
                _residual(Ad, Ao, sizes, offsets, tmp, rhs, P, ps, nd, outs_n, Rn)
                ga = 0.0
                for i in range(N):
                    ga += Rn[i] * dlt[i]
                if abs(ga) <= 1e-2 * abs(g0):
                    break
                if ga < 0.0:
                    lo = alpha
                    glo = ga
                    if side == -1:
                        ghi *= 0.5
                    side = -1
                else:
                    hi = alpha
                    ghi = ga
                    if side == 1:
                        glo *= 0.5
                    side = 1
        for i in range(N):
            dv[i] = tmp[i]
            R[i] = Rn[i]
        for p in range(m):
            for c in range(_NOUT):
                outs[p, c] = outs_n[p, c]
        dvmax = 0.0
        for i in range(N):
            dvmax = max(dvmax, abs(dv[i]))
        # what is left of this step's way to the root: (1 − α) of it after a damped step (a
        # line search that stops near α = 0 has not converged: its residual stands)
        rem = max(alpha, 1.0 - alpha) * dmax
        if rem <= _NEWTON_TOL * max(vscale, dvmax) or dmax == 0.0:
            converged = True
            break
        # the next step estimated from the contraction of the last two full steps (the
        # state now is the last evaluation's: no further solve is needed)
        if alpha == 1.0 and 0.0 < prev and dmax < 0.2 * prev \
                and dmax * (dmax / prev) <= _NEWTON_TOL * max(vscale, dvmax):
            converged = True
            break
        if prev >= 0.0 and alpha * dmax > 0.2 * prev:
            refac = True
        prev = alpha * dmax
        left = rem
        if DEBUG and k == DEBUG_STEP:
            print("it", _it, "dmax", dmax, "alpha", alpha, "g0", g0, "g1", g1)
            for p in range(m):
                print("   p", p, "stuck0", stuck[p], "J", outs[p, 0], outs[p, 1], "D",
                      outs[p, 2], outs[p, 3], outs[p, 4], outs[p, 5], "end", outs[p, 6],
                      "nev", outs[p, 17], "mus_k", mus_k[p])
        if freeze and _it >= 6 and _it % 3 == 0 and _it < maxit - 1:
            # stalled: a pallet whose impulse jumps with y (a grazing slip onset, where
            # the holding force touches mu_s N inside the step) has no root; it keeps its
            # start state's contact for this step (theory §4.3)
            for i in range(N):
                tmp[i] = dv[i] + 1e-6 * dlt[i]
            _eval_pallets(tmp, offsets, sizes, P, ps, nd, h, mass, mus_k, mud, Nk0, Nk1,
                          agp[k], agp[k + 1], stuck, sv, dirn, jerk, beta, nprev,
                          Gc, gstamp, stamp,
                          Le, Dp, outs_n, ev, t1, t2, stats, False)
            for p in range(m):
                dj = abs(outs_n[p, 0] - outs[p, 0]) + abs(outs_n[p, 1] - outs[p, 1])
                if dj > 1e-4 * (abs(outs[p, 0]) + abs(outs[p, 1]) + mass[p] * h):
                    mus_k[p] = 1e300
                    stats[5] += 1
                elif _it >= _NEWTON_FREEZE and outs[p, 17] > 0.0 and mus_k[p] < 1e300:
                    # still stalled: a pallet with an event inside the step keeps (or,
                    # after a stop, takes) the contact for the rest of the step: a slip
                    # onset whose impulse falls with y as fast as the support's
                    # compliance allows (mu_d < mu_s: H is singular along it, the onset
                    # time undetermined; 3D paper rack under El Centro, four pallets at
                    # t = 2.055 s), or a stop whose restart toggles between iterations
                    mus_k[p] = 1e300
                    stats[5] += 1
            _eval_pallets(dv, offsets, sizes, P, ps, nd, h, mass, mus_k, mud, Nk0, Nk1,
                          agp[k], agp[k + 1], stuck, sv, dirn, jerk, beta, nprev,
                          Gc, gstamp, stamp,
                          Le, Dp, outs, ev, t1, t2, stats, False)
            _residual(Ad, Ao, sizes, offsets, dv, rhs, P, ps, nd, outs, R)
    return converged, left


@_JIT
def _onsets_in_turn(k, Ad, Ao, Hd, Ho, sizes, offsets, P, ps, nd, h, mass, mus, mus_k, mud,
                    Nk0, Nk1, agp, stuck, sv, dirn, jerk, beta, nprev, Gc, gstamp, stamp, Le,
                    Dp, Dn, Ld, X, Ld2, X2, outs, outs_n, ev, t1, t2, stats, rhs, dv, R, Rn,
                    dlt, tmp, vscale, dvp, dvs, tried):
    """A step whose Newton iteration failed, retried from its start contacts with its slip
    onsets placed one at a time (theory §4.5): every pallet stuck at the start is held and the
    step solved; then, while a held pallet's holding force reaches mu_s N inside the step, the
    one whose onset comes first is released and the step solved again from the last solution.
    A release whose Newton iteration does not converge in _RETRY_MAX iterations is undone and
    that pallet keeps its contact for the step (counted in ``stats[5]``, frozen contacts).
    Bounded: one solve per pallet at most. Returns (converged, the last increment's size)."""
    N = dv.shape[0]
    m = ps.shape[0]
    stats[7] += 1
    solves0 = stats[3]
    for p in range(m):
        mus_k[p] = _HELD if stuck[p] else mus[p]
        tried[p] = False
    _assemble_H(Ad, Ao, Hd, Ho, sizes, P, ps, Dp, nd)
    stats[2] += 1
    if not _btd_factor(Hd, Ho, sizes, Ld, X):
        return False, -1.0
    for i in range(N):
        dv[i] = dvp[i]
    _eval_pallets(dv, offsets, sizes, P, ps, nd, h, mass, mus_k, mud, Nk0, Nk1, agp[k],
                  agp[k + 1], stuck, sv, dirn, jerk, beta, nprev, Gc, gstamp, stamp, Le, Dp,
                  outs, ev, t1, t2, stats, False)
    _residual(Ad, Ao, sizes, offsets, dv, rhs, P, ps, nd, outs, R)
    conv, prev = _newton(k, _RETRY_MAX, False, Ad, Ao, Hd, Ho, sizes, offsets, P, ps, nd, h,
                         mass, mus_k, mud, Nk0, Nk1, agp, stuck, sv, dirn, jerk, beta, nprev,
                         Gc, gstamp, stamp, Le, Dp, Dn, Ld, X, Ld2, X2, outs, outs_n, ev, t1,
                         t2, stats, rhs, dv, R, Rn, dlt, tmp, vscale)
    if not conv:
        stats[10] += stats[3] - solves0
        return False, prev
    last = prev
    for _r in range(m):
        # the held pallets with a slip onset at this solution (their own friction law)
        _eval_pallets(dv, offsets, sizes, P, ps, nd, h, mass, mus, mud, Nk0, Nk1, agp[k],
                      agp[k + 1], stuck, sv, dirn, jerk, beta, nprev, Gc, gstamp, stamp, Le,
                      Dp, outs_n, ev, t1, t2, stats, False)
        q = -1
        tq = 1e300
        for p in range(m):
            if mus_k[p] >= _HELD and not tried[p] and outs_n[p, 17] > 0.0 \
                    and ev[p, 0, 0] < tq:
                q = p
                tq = ev[p, 0, 0]
        if q < 0:
            break
        tried[q] = True
        stats[8] += 1
        for i in range(N):
            dvs[i] = dv[i]
        mus_k[q] = mus[q]
        _eval_pallets(dv, offsets, sizes, P, ps, nd, h, mass, mus_k, mud, Nk0, Nk1, agp[k],
                      agp[k + 1], stuck, sv, dirn, jerk, beta, nprev, Gc, gstamp, stamp, Le,
                      Dp, outs, ev, t1, t2, stats, False)
        _residual(Ad, Ao, sizes, offsets, dv, rhs, P, ps, nd, outs, R)
        conv, prev = _newton(k, _RETRY_MAX, False, Ad, Ao, Hd, Ho, sizes, offsets, P, ps, nd,
                             h, mass, mus_k, mud, Nk0, Nk1, agp, stuck, sv, dirn, jerk, beta,
                             nprev, Gc, gstamp, stamp, Le, Dp, Dn, Ld, X, Ld2, X2, outs,
                             outs_n, ev, t1, t2, stats, rhs, dv, R, Rn, dlt, tmp, vscale)
        if conv:
            last = prev
        else:
            mus_k[q] = _HELD
            stats[5] += 1
            for i in range(N):
                dv[i] = dvs[i]
    # the step's solution with its final contacts (its events in ``ev``)
    _eval_pallets(dv, offsets, sizes, P, ps, nd, h, mass, mus_k, mud, Nk0, Nk1, agp[k],
                  agp[k + 1], stuck, sv, dirn, jerk, beta, nprev, Gc, gstamp, stamp, Le, Dp,
                  outs, ev, t1, t2, stats, False)
    _residual(Ad, Ao, sizes, offsets, dv, rhs, P, ps, nd, outs, R)
    stats[10] += stats[3] - solves0
    return True, last


@_JIT
def _eval_frozen(dv, offsets, sizes, P, ps, nd, h, mass, mus_k, mud, Nk0, Nk1, agp0, agp1,
                 stuck, sv, dirn, jerk, beta, nprev, Gc, gstamp, stamp, Ld, Dp, outs, ev, t1,
                 t2, stats):
    """Every pallet in ``_frozen_step``: a stuck pallet held (``mus_k`` holds it); a sliding
    one by the return map on its friction disc, as the planar engine (no support compliance,
    the direction of the end of the step): with ``z`` its relative velocity at the end
    without friction, it slides on with ``J = −m c ẑ`` when ``|z| > c = mu_d N̄ h / m``, else
    it stops inside the step, ``J = −m z``. Returns the potential of the impulses,
    ``Σ ψ_p`` with ``∂ψ_p/∂y_p = J_p`` (convex: the step's Newton iteration backtracks on
    it)."""
    m = ps.shape[0]
    psi = 0.0
    for p in range(m):
        s = ps[p]
        o = offsets[s]
        b = sizes[s]
        row = outs[p]
        yx = _support(P, p, o, b, dv, 0)
        yz = _support(P, p, o, b, dv, 1) if nd == 2 else 0.0
        Agx = 0.5 * h * (agp0[0] + agp1[0])
        Agz = 0.5 * h * (agp0[1] + agp1[1]) if nd == 2 else 0.0
        mp = mass[p]
        if stuck[p]:
            _eval_range(p, p + 1, dv, offsets, sizes, P, ps, nd, h, mass, mus_k, mud, Nk0,
                        Nk1, agp0, agp1, stuck, sv, dirn, jerk, beta, nprev, Gc, gstamp, stamp,
                        Ld, Dp, outs, ev, t1, t2, stats, False)
            _stuck_row(outs[:, 2:6], p, mp, nd)
            psi += mp * (Agx * yx + Agz * yz + 0.5 * (yx * yx + yz * yz))
            continue
        zx = sv[p, 0] - Agx - yx
        zz = (sv[p, 1] - Agz - yz) if nd == 2 else 0.0
        zn = np.sqrt(zx * zx + zz * zz)
        c = mud[p] * 0.5 * h * (Nk0[p] + Nk1[p]) / mp
        s0n = np.sqrt(sv[p, 0] ** 2 + sv[p, 1] ** 2)
        if zn > c:  # slides on
            ex = zx / zn
            ez = zz / zn
            row[0] = -mp * c * ex
            row[1] = -mp * c * ez
            g = mp * c / zn
            row[2] = g * (1.0 - ex * ex)
            row[3] = -g * ex * ez
            row[4] = row[3]
            row[5] = g * (1.0 - ez * ez) if nd == 2 else 0.0
            row[6] = 0.0
            row[7] = zx - c * ex
            row[8] = zz - c * ez
            row[9] = ex
            row[10] = ez
            row[11] = 0.5 * h * (sv[p, 0] + row[7])
            row[12] = 0.5 * h * (sv[p, 1] + row[8])
            row[13] = -mud[p] * Nk1[p] * ex
            row[14] = -mud[p] * Nk1[p] * ez
            row[17] = 0.0
            psi += mp * (c * zn - 0.5 * c * c)
        else:  # stops inside the step, at about the share of its impulse that stops it
            tau = h * min(s0n / max(c, 1e-300), 1.0)
            row[0] = -mp * zx
            row[1] = -mp * zz
            _stuck_row(outs[:, 2:6], p, mp, nd)
            row[6] = 1.0
            row[7] = 0.0
            row[8] = 0.0
            row[9] = dirn[p, 0]
            row[10] = dirn[p, 1]
            row[11] = 0.5 * tau * sv[p, 0]
            row[12] = 0.5 * tau * sv[p, 1]
            row[13] = mp * (agp1[0] + yx / h)
            row[14] = mp * (agp1[1] + yz / h) if nd == 2 else 0.0
            row[17] = 1.0
            ev[p, 0, 0] = tau
            ev[p, 0, 1] = _EV_STICK
            psi += 0.5 * mp * zn * zn
        row[15] = yx / h
        row[16] = yz / h
        row[18] = 0.0
    return psi


@_JIT
def _frozen_potential(Ad, Ao, sizes, offsets, dv, rhs, tmp, psi):
    """½ dvᵀ A dv − rhsᵀ dv + Σ ψ_p: the potential whose gradient is the step's residual."""
    for i in range(dv.shape[0]):
        tmp[i] = 0.0
    _btd_matvec(Ad, Ao, sizes, offsets, dv, tmp, 1.0)
    acc = psi
    for i in range(dv.shape[0]):
        acc += dv[i] * (0.5 * tmp[i] - rhs[i])
    return acc


@_JIT
def _frozen_step(k, Ad, Ao, Hd, Ho, sizes, offsets, P, ps, nd, h, mass, mus, mus_k, mud, Nk0,
                 Nk1, agp, stuck, sv, dirn, jerk, beta, nprev, Gc, gstamp, stamp, Le, Dp, Ld,
                 X, outs, ev, t1, t2, stats, rhs, dv, R, dlt, dvp, tmp, dvs, vscale):
    """The last resort of a step whose Newton iteration and retry both failed (theory §4.6):
    every pallet stuck at the start is held through the step, every sliding one follows the
    return map on its friction disc without the support's compliance (``_eval_frozen``).
    The impulses are then the gradient of a convex potential, monotone in the support's
    motion, and Newton's method with backtracking on that potential converges. Slip onsets
    wait for the next step, whose local solves see them already due at τ = 0 (counted:
    ``stats[11]``). Returns False when the step matrix is not positive definite or the
    iteration does not converge."""
    N = dv.shape[0]
    m = ps.shape[0]
    stats[11] += 1
    for p in range(m):
        mus_k[p] = _HELD if stuck[p] else mus[p]
    for i in range(N):
        dv[i] = dvp[i]
    for _it in range(_RETRY_MAX):
        stats[1] += 1
        psi = _eval_frozen(dv, offsets, sizes, P, ps, nd, h, mass, mus_k, mud, Nk0, Nk1,
                           agp[k], agp[k + 1], stuck, sv, dirn, jerk, beta, nprev, Gc, gstamp,
                           stamp, Le, Dp, outs, ev, t1, t2, stats)
        _residual(Ad, Ao, sizes, offsets, dv, rhs, P, ps, nd, outs, R)
        for p in range(m):
            for c in range(4):
                Dp[p, c] = outs[p, 2 + c]
        _assemble_H(Ad, Ao, Hd, Ho, sizes, P, ps, Dp, nd)
        stats[2] += 1
        if not _btd_factor(Hd, Ho, sizes, Ld, X):
            return False
        for i in range(N):
            dlt[i] = -R[i]
        _btd_solve(Ld, X, sizes, offsets, dlt)
        dmax = 0.0
        dvmax = 0.0
        slope = 0.0
        for i in range(N):
            dmax = max(dmax, abs(dlt[i]))
            dvmax = max(dvmax, abs(dv[i]))
            slope += R[i] * dlt[i]
        if dmax <= _NEWTON_TOL * max(vscale, dvmax):
            return True  # the last evaluation (at dv) stands
        phi0 = _frozen_potential(Ad, Ao, sizes, offsets, dv, rhs, tmp, psi)
        for i in range(N):
            dvs[i] = dv[i]
        alpha = 1.0
        for _ls in range(30):
            for i in range(N):
                dv[i] = dvs[i] + alpha * dlt[i]
            psi = _eval_frozen(dv, offsets, sizes, P, ps, nd, h, mass, mus_k, mud, Nk0, Nk1,
                               agp[k], agp[k + 1], stuck, sv, dirn, jerk, beta, nprev, Gc,
                               gstamp, stamp, Le, Dp, outs, ev, t1, t2, stats)
            phi = _frozen_potential(Ad, Ao, sizes, offsets, dv, rhs, tmp, psi)
            # Armijo, with room for the round-off of the potential's large linear part
            if phi <= phi0 + 1e-4 * alpha * slope + 1e-13 * abs(phi0):
                break
            alpha *= 0.5
    return False


@_JIT
def run_local(Md, Cd, Kd, Mo, Co, Ko, sizes, offsets, P, ps, nd, mass, mus, mud, dt, pat,
              ser, agp, gz, resume, q, v, dvp, stuck, sv, dirn, uu, lam, beta, jerk, nprev,
              Dp, rows, energy, t_offset, max_events, out_q, out_v, out_u, out_s, out_lam,
              out_stuck, out_e, ev_time, ev_pallet, ev_kind, stats):
    """Integrate ``ser.shape[0] - 1`` steps of length ``dt``.

    Structure: block-tridiagonal M, C, K (``Md``...``Ko``, ``sizes``, ``offsets``); loads
    ``ser`` (n_t, k) @ ``pat`` (k, size). Pallets: ``P`` (m, 2, bmax) support rows on their
    slice ``ps``; ground accelerations ``agp`` (n_t, 2) along the pallets' directions; normal
    forces ``mass * max(gz, 0)``. State (read when ``resume``, written back): q, v, dvp (the
    last Δv), stuck, sv (relative velocity), dirn (sliding direction), uu (sliding), lam (end
    force), beta and jerk (the support's reference acceleration and its rate), nprev, Dp
    (∂J/∂y of the last step), rows (2, m, _NOUT) the pallets' last local solutions (their
    warm starts), energy [input, damping, friction]. Outputs per step row;
    events; ``stats``: steps, Newton iterations, factorisations, local solves, line-search
    evaluations. Returns (status, n_events, last row written).
    """
    bmax = Md.shape[1]
    N = q.shape[0]
    m = ps.shape[0]
    n_t = ser.shape[0]
    h = dt
    Ad = np.empty_like(Md)
    Ao = np.empty_like(Mo)
    _btd_combine(Md, Cd, Kd, Mo, Co, Ko, sizes, 1.0, 0.5 * h, 0.25 * h * h, Ad, Ao)
    Hd = np.empty_like(Md)
    Ho = np.empty_like(Mo)
    Ld = np.zeros_like(Md)
    X = np.zeros_like(Mo)
    Ld2 = np.zeros_like(Md)
    X2 = np.zeros_like(Mo)
    # the pallets' compliances read both sides of their slice condensed (_btd_condensed)
    Le = np.zeros_like(Md)
    Rb = np.zeros_like(Md)
    Yb = np.zeros_like(Md)
    Dn = np.zeros((m, 4))
    dvs = np.empty(q.shape[0])
    tried = np.zeros(m, dtype=np.bool_)
    jlast = jerk[:, 2:]  # the last difference of beta (stored beside the jerk)
    rhs = np.empty(N)
    R = np.empty(N)
    Rn = np.empty(N)
    dv = np.empty(N)
    dlt = np.empty(N)
    tmp = np.empty(N)
    fbar = np.empty(N)
    vbar = np.empty(N)
    outs = rows[0]
    outs_n = rows[1]
    ev = np.zeros((m, 8, 2))
    Gc = np.zeros((m, 3))
    gstamp = np.full(m, -1, dtype=np.int64)
    t1 = np.empty(bmax)
    t2 = np.empty(bmax)
    Nk0 = np.empty(m)
    mus_k = np.empty(m)
    Nk1 = np.empty(m)
    n_ev = 0
    status = STATUS_OK
    if not resume:
        for p in range(m):
            stuck[p] = True
            for d in range(2):
                sv[p, d] = 0.0
                uu[p, d] = 0.0
                lam[p, d] = 0.0
                beta[p, d] = 0.0
            for d in range(4):
                jerk[p, d] = 0.0
            nprev[p] = 0
            _stuck_row(Dp, p, mass[p], nd)
        for i in range(N):
            dvp[i] = 0.0
        rows[:, :, :] = 0.0
    _write(0, q, v, uu, sv, lam, stuck, energy, Md, Mo, Kd, Ko, sizes, offsets, P, ps, nd,
           mass, tmp, out_q, out_v, out_u, out_s, out_lam, out_stuck, out_e)
    k_done = 0
    stamp = 0
    for k in range(n_t - 1):
        stats[0] += 1
        # loads: f̄ (mean over the step, exact for loads linear inside it)
        for i in range(N):
            fbar[i] = 0.0
        for c in range(ser.shape[1]):
            a = 0.5 * (ser[k, c] + ser[k + 1, c])
            if a != 0.0:
                for i in range(N):
                    fbar[i] += a * pat[c, i]
        for p in range(m):
            mus_k[p] = mus[p]
            Nk0[p] = max(mass[p] * gz[k], 0.0)
            Nk1[p] = max(mass[p] * gz[k + 1], 0.0)
        # rhs = h f̄ − h C v0 − h K (q0 + h v0 / 2)
        for i in range(N):
            rhs[i] = h * fbar[i]
            tmp[i] = q[i] + 0.5 * h * v[i]
        _btd_matvec(Cd, Co, sizes, offsets, v, rhs, -h)
        _btd_matvec(Kd, Ko, sizes, offsets, tmp, rhs, -h)
        # Newton matrix with the pallets' D of the start state; factorised once a step
        for p in range(m):
            if stuck[p]:
                _stuck_row(Dp, p, mass[p], nd)
            else:
                _psd_row(Dp, p, mass[p])
                if nd == 1:
                    Dp[p, 1] = 0.0
                    Dp[p, 2] = 0.0
                    Dp[p, 3] = 0.0
        _assemble_H(Ad, Ao, Hd, Ho, sizes, P, ps, Dp, nd)
        stats[2] += 1
        if not _btd_factor(Hd, Ho, sizes, Ld, X):
            status = STATUS_NOT_PD
            break
        if not _btd_condensed(Hd, Ho, sizes, X, Rb, Yb, Le):
            Le[:] = Ld  # not reached for a positive definite H; the left side only
        stamp = k + 1
        # predictor: the last step's Δv
        for i in range(N):
            dv[i] = dvp[i]
        _eval_pallets(dv, offsets, sizes, P, ps, nd, h, mass, mus_k, mud, Nk0, Nk1, agp[k],
                      agp[k + 1], stuck, sv, dirn, jerk, beta, nprev,
                      Gc, gstamp, stamp, Le, Dp, outs, ev,
                      t1, t2, stats, False)
        _residual(Ad, Ao, sizes, offsets, dv, rhs, P, ps, nd, outs, R)
        vscale = 1e-300
        for i in range(N):
            vscale = max(vscale, abs(v[i]) + abs(dvp[i]))
        frozen0 = stats[5]
        converged, prev = _newton(k, _NEWTON_MAX, True, Ad, Ao, Hd, Ho, sizes, offsets, P, ps,
                                  nd, h, mass, mus_k, mud, Nk0, Nk1, agp, stuck, sv, dirn,
                                  jerk, beta, nprev, Gc, gstamp, stamp, Le, Dp, Dn, Ld, X, Ld2,
                                  X2, outs, outs_n, ev, t1, t2, stats, rhs, dv, R, Rn, dlt, tmp,
                                  vscale)
        if not converged:
            # a cluster of slip onsets that does not contract: the step retried from its start
            # contacts with the onsets placed one at a time (the freezes of the failed
            # iteration are discarded with it)
            stats[5] = frozen0
            converged, prev = _onsets_in_turn(
                k, Ad, Ao, Hd, Ho, sizes, offsets, P, ps, nd, h, mass, mus, mus_k, mud, Nk0,
                Nk1, agp, stuck, sv, dirn, jerk, beta, nprev, Gc, gstamp, stamp, Le, Dp, Dn,
                Ld, X, Ld2, X2, outs, outs_n, ev, t1, t2, stats, rhs, dv, R, Rn, dlt, tmp,
                vscale, dvp, dvs, tried)
        if not converged:
            # still moving after _NEWTON_MAX iterations (a linear contraction near a pallet's
            # stop or frozen onset): accepted when the last increment is below
            # _NEWTON_LOOSE of the velocities, counted (work["loose_steps"]); else the run
            # stops
            dvmax = 0.0
            for i in range(N):
                dvmax = max(dvmax, abs(dv[i]))
            if prev >= 0.0 and prev <= _NEWTON_LOOSE * max(vscale, dvmax):
                stats[6] += 1
            elif not _frozen_step(k, Ad, Ao, Hd, Ho, sizes, offsets, P, ps, nd, h, mass, mus,
                                  mus_k, mud, Nk0, Nk1, agp, stuck, sv, dirn, jerk, beta,
                                  nprev, Gc, gstamp, stamp, Le, Dp, Ld, X, outs, ev, t1, t2,
                                  stats, rhs, dv, R, dlt, dvp, tmp, dvs, vscale):
                status = STATUS_NEWTON
                break
        # commit: structure
        for i in range(N):
            vbar[i] = v[i] + 0.5 * dv[i]
        e_in = 0.0
        for i in range(N):
            e_in += h * vbar[i] * fbar[i]
        tmp[:] = 0.0
        _btd_matvec(Cd, Co, sizes, offsets, vbar, tmp, 1.0)
        e_damp = 0.0
        for i in range(N):
            e_damp += h * vbar[i] * tmp[i]
        e_fr = 0.0
        t_k = t_offset + k * h
        for p in range(m):
            s = ps[p]
            o = offsets[s]
            b = sizes[s]
            row = outs[p]
            Agx = 0.5 * h * (agp[k, 0] + agp[k + 1, 0])
            Agz = 0.5 * h * (agp[k, 1] + agp[k + 1, 1]) if nd == 2 else 0.0
            yx = _support(P, p, o, b, dv, 0)
            yz = _support(P, p, o, b, dv, 1) if nd == 2 else 0.0
            # end relative velocity from momentum (eq. 3.2): exact impulse balance
            end_stuck = row[6] > 0.5
            s1x = sv[p, 0] + row[0] / mass[p] - Agx - yx
            s1z = (sv[p, 1] + row[1] / mass[p] - Agz - yz) if nd == 2 else 0.0
            slipped = False
            if end_stuck:
                # a pallet that ends stuck has the support's velocity, to the tolerance of its
                # local solve; when its impulse leaves it more than _STUCK_SLACK behind, the
                # local solve found no root (a grazing onset, where J jumps with y) and the
                # structure converged on the jump: the pallet has slipped, and ends the step
                # sliding with the velocity its impulse gives it (momentum and the energy
                # balance stay exact; theory §4.6)
                vs = abs(Agx) + abs(Agz) + abs(yx) + abs(yz) \
                    + 0.5 * h * mus[p] * (Nk0[p] + Nk1[p]) / mass[p]
                sn = np.sqrt(s1x * s1x + s1z * s1z)
                if sn > _STUCK_SLACK * vs:
                    end_stuck = False
                    slipped = True
                    stats[9] += 1
                else:
                    s1x = 0.0
                    s1z = 0.0
            # a pallet held stuck through the step by a frozen contact or a retry (mus_k above
            # its mu_s), or stopped inside the step (mostly in a frozen step's return map),
            # whose end force is beyond mu_s N slips at the end of the step, from zero
            # relative velocity: its onset is placed late (by less than a step, counted with
            # the slips at step end), not lost; left held, it stayed stuck at up to 1.008
            # mu_s N for five steps on the 3D paper rack, and a stop in a frozen step was
            # reported at 4.7 mu_s N (theory §4.7)
            released = False
            if end_stuck and (mus_k[p] > mus[p] or not stuck[p]) \
                    and row[13] * row[13] + row[14] * row[14] > (mus[p] * Nk1[p]) ** 2:
                end_stuck = False
                released = True
                stats[9] += 1
            vbx = _support(P, p, o, b, vbar, 0)
            vbz = _support(P, p, o, b, vbar, 1) if nd == 2 else 0.0
            sbx = 0.5 * (sv[p, 0] + s1x)
            sbz = 0.5 * (sv[p, 1] + s1z)
            e_in -= mass[p] * (Agx * (vbx + sbx) + Agz * (vbz + sbz))
            e_fr -= row[0] * sbx + row[1] * sbz
            # events of this pallet
            if not (stuck[p] and row[6] > 0.5 and row[17] == 0.0):
                ne = int(row[17])
                for e in range(min(ne, ev.shape[1])):
                    if n_ev < max_events:
                        ev_time[n_ev] = t_k + ev[p, e, 0]
                        ev_pallet[n_ev] = p
                        ev_kind[n_ev] = int(ev[p, e, 1])
                    n_ev += 1
            was_stuck = stuck[p]
            stuck[p] = end_stuck
            sv[p, 0] = s1x
            sv[p, 1] = s1z
            dirn[p, 0] = row[9]
            dirn[p, 1] = row[10]
            uu[p, 0] += row[11]
            uu[p, 1] += row[12]
            lam[p, 0] = row[13]
            lam[p, 1] = row[14]
            if slipped or released:
                # sliding from the end of the step: against its velocity (left behind by its
                # impulse), or from rest away from the force that held it
                if slipped:
                    sn = np.sqrt(s1x * s1x + s1z * s1z)
                    dirn[p, 0] = s1x / sn
                    dirn[p, 1] = s1z / sn
                else:
                    fn = np.sqrt(row[13] * row[13] + row[14] * row[14])
                    dirn[p, 0] = -row[13] / fn
                    dirn[p, 1] = -row[14] / fn
                lam[p, 0] = -mud[p] * Nk1[p] * dirn[p, 0]
                lam[p, 1] = -mud[p] * Nk1[p] * dirn[p, 1]
                if n_ev < max_events:
                    ev_time[n_ev] = t_k + h
                    ev_pallet[n_ev] = p
                    ev_kind[n_ev] = _EV_SLIP
                n_ev += 1
            # the support's reference acceleration and its rate (jerk) for the next step:
            # the minmod of the last two differences, so that a jump of the support's
            # acceleration (a neighbour's event) does not become a spurious jerk; after an
            # event of the pallet itself its reference changes, so no difference is taken
            # across it and the jerk from before it is dropped (kept, it extrapolated the
            # holding force to 1.045 mu_s N; theory §4.1, §4.7)
            for d in range(2):
                dj = (row[15 + d] - beta[p, d]) / h
                if nprev[p] >= 2:
                    jp = jlast[p, d]
                    if dj * jp <= 0.0:
                        jerk[p, d] = 0.0
                    elif abs(dj) < abs(jp):
                        jerk[p, d] = dj
                    else:
                        jerk[p, d] = jp
                if nprev[p] >= 1:
                    jlast[p, d] = dj
                beta[p, d] = row[15 + d]
            if row[17] > 0.0 or end_stuck != was_stuck or slipped:
                nprev[p] = 0
                jerk[p, 0] = 0.0
                jerk[p, 1] = 0.0
            else:
                nprev[p] += 1
            for c in range(4):
                Dp[p, c] = row[2 + c]
            if slipped:  # its ∂J/∂y was taken across the jump: the stuck one instead
                _stuck_row(Dp, p, mass[p], nd)
        energy[0] += e_in
        energy[1] += e_damp
        energy[2] += e_fr
        fin = 0.0  # every coordinate and the pallets' forces: a NaN anywhere shows in the sum
        for i in range(N):
            q[i] += h * vbar[i]
            v[i] += dv[i]
            dvp[i] = dv[i]
            fin += q[i] + v[i]
        for j in range(lam.shape[0]):
            for c in range(lam.shape[1]):
                fin += lam[j, c]
        _write(k + 1, q, v, uu, sv, lam, stuck, energy, Md, Mo, Kd, Ko, sizes, offsets, P,
               ps, nd, mass, tmp, out_q, out_v, out_u, out_s, out_lam, out_stuck, out_e)
        k_done = k + 1
        if not np.isfinite(fin):
            status = STATUS_NONFINITE
            break
    if n_ev > max_events and status == STATUS_OK:
        status = STATUS_EVENT_OVERFLOW
    return status, n_ev, k_done


@_JIT
def _write(k, q, v, uu, sv, lam, stuck, energy, Md, Mo, Kd, Ko, sizes, offsets, P, ps, nd,
           mass, tmp, out_q, out_v, out_u, out_s, out_lam, out_stuck, out_e):
    """Output row ``k``: q, v (when kept), the pallets' sliding, relative velocity, force and
    state, and the energy terms [input, kinetic, strain, damping, friction]."""
    if out_q.shape[1] > 0:
        out_q[k, :] = q
        out_v[k, :] = v
    m = ps.shape[0]
    for p in range(m):
        for d in range(2):
            out_u[k, p, d] = uu[p, d]
            out_s[k, p, d] = sv[p, d]
            out_lam[k, p, d] = lam[p, d]
        out_stuck[k, p] = stuck[p]
    tmp[:] = 0.0
    _btd_matvec(Md, Mo, sizes, offsets, v, tmp, 1.0)
    ke = 0.0
    for i in range(q.shape[0]):
        ke += 0.5 * v[i] * tmp[i]
    for p in range(m):
        s = ps[p]
        o = offsets[s]
        b = sizes[s]
        wx = _support(P, p, o, b, v, 0) + sv[p, 0]
        wz = (_support(P, p, o, b, v, 1) + sv[p, 1]) if nd == 2 else 0.0
        ke += 0.5 * mass[p] * (wx * wx + wz * wz)
    tmp[:] = 0.0
    _btd_matvec(Kd, Ko, sizes, offsets, q, tmp, 1.0)
    se = 0.0
    for i in range(q.shape[0]):
        se += 0.5 * q[i] * tmp[i]
    out_e[k, 0] = energy[0]
    out_e[k, 1] = ke
    out_e[k, 2] = se
    out_e[k, 3] = energy[1]
    out_e[k, 4] = energy[2]
