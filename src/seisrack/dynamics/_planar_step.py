"""The Newmark step of the planar stick–slip kernel with a fixed contact state (source
shared by the numba and pure-Python backends; theory: ``docs/theory/planar_friction.md`` §2).

``_trial`` advances the structure (basis coordinates) and the pallets by one (sub)step; a
sliding pallet's end force comes from the return map onto its friction disc, a nonlinear
hinge's from its hysteresis law (the correction ``z = M(θ) − k θ`` to the elastic spring kept in
``kd``, as on a line: ``docs/theory/nonlinear_hinges.md``), and the step equation (the
gradient of a potential, convex for the monotone laws) is solved by Newton's method with
backtracking (``docs/theory/planar_friction.md`` §7).
"""

# ruff: noqa: N803, N806  (matrix names follow the equations)

import numpy as np

try:  # names injected by the loader when executed after ``_events.py``
    _interp  # type: ignore[used-before-def]  # noqa: B018
except NameError:  # pragma: no cover - plain import of this file (pure-Python twin)
    from seisrack.dynamics._events import _JIT, _interp
    from seisrack.dynamics._hysteresis import _hyst_trial_at, _hyst_zwork
    from seisrack.dynamics._lapack import _chol, _chol_solve, _syrk_lower
    from seisrack.dynamics._planar_hinges import _hinge_eval, _minus_qtz

_NEWTON_MAX = 40


@_JIT
def _s_update(S, P, mass, p, sign):
    """Add (sign = 1) or remove (-1) pallet ``p`` from the stuck pallets' mass in basis
    coordinates: rows :r of ``S`` (r + 2, r) hold Σ m_p (P_xᵀ P_x + P_zᵀ P_z), rows r and
    r + 1 the first moments Σ m_p P_x and Σ m_p P_z (the load of a ground acceleration)."""
    r = S.shape[1]
    mp = sign * mass[p]
    for c in range(2):
        row = 2 * p + c
        for i in range(r):
            S[r + c, i] += mp * P[row, i]
        for i in range(r):
            a = mp * P[row, i]
            if a != 0.0:
                for k in range(r):
                    S[i, k] += a * P[row, k]


@_JIT
def _sample_row(X, step, frac, out):
    for i in range(out.shape[0]):
        out[i] = _interp(X[step, i], X[step + 1, i], frac)


@_JIT
def _a_lin(A, S, c0, c2, cd, Co, kd):
    """A = diag(c0 + c2 cd + kd) + c2 Co + c0 S: the step's stiffness with the stuck pallets
    (its lower triangle, all that :func:`_chol` reads); ``Co`` the off-diagonal part of the
    damping, (r, r), or (0, 0) when the damping is diagonal in the basis."""
    r = kd.shape[0]
    full = Co.shape[0] > 0
    for i in range(r):
        for k in range(i + 1):
            A[i, k] = c0 * S[i, k]
        if full:
            for k in range(i):
                A[i, k] += c2 * Co[i, k]
        A[i, i] += c0 + c2 * cd[i] + kd[i]


@_JIT
def _damp_off(Co, v, out):
    """out = Co v (0 when the damping is diagonal: ``Co`` is (0, 0))."""
    if Co.shape[0] > 0:
        out[:] = np.dot(Co, v)
    else:
        out[:] = 0.0


@_JIT
def _frictions(n_slide, sl, h, c2, PF, mass, mud, N1, zf, pd, lam, G, jac):
    """Friction of the sliding pallets ``sl[:n_slide]`` (rows ``2a``, ``2a + 1`` of ``PF``,
    ``zf``, ``pd`` and ``lam`` for the a-th) at the end of the step from ``y = zf − c2 pd``,
    a pallet's relative velocity without this step's friction: outside the disc
    |y| > c = h mu_d N / (2 m) it slides on, lam = −mu_d N y/|y|; inside, it would stop within
    the step, lam = −(2 m / h) y (the return map, continuous and monotone in y). When ``jac``,
    writes the rows ``g`` of the Jacobian of lam (times c2 P_p) = Σ gᵀ g from the first row of
    ``G``; returns the number of rows. One call for all of them: numba counts a reference to
    every array argument of a call (an atomic increment and decrement), which per pallet and
    Newton iteration was about a sixth of the 150-pallet example's run."""
    r = PF.shape[1]
    ng = 0
    for a in range(n_slide):
        p = sl[a]
        jx = 2 * a
        jz = jx + 1
        yx = zf[jx] - c2 * pd[jx]
        yz = zf[jz] - c2 * pd[jz]
        yn = np.sqrt(yx * yx + yz * yz)
        f = mud[p] * N1[p]
        cc = 0.5 * h * f / mass[p]
        if yn > cc and yn > 0.0:
            lam[jx] = -f * yx / yn
            lam[jz] = -f * yz / yn
            if jac:
                # rank one, across the direction of sliding
                b = np.sqrt(f * c2 / yn)
                tx = -b * yz / yn
                tz = b * yx / yn
                for i in range(r):
                    G[ng, i] = PF[jx, i] * tx + PF[jz, i] * tz
                ng += 1
        else:
            km = 2.0 * mass[p] / h
            lam[jx] = -km * yx
            lam[jz] = -km * yz
            if jac:
                b = np.sqrt(km * c2)
                for i in range(r):
                    G[ng, i] = b * PF[jx, i]
                    G[ng + 1, i] = b * PF[jz, i]
                ng += 2
    return ng


@_JIT
def _huber(yx, yz, cc, mp, h):
    """Friction potential of a sliding pallet of mass ``mp`` in ``y``: (m/h)|y|² inside the
    disc |y| <= c, (2m/h)(c|y| - c²/2) outside (its gradient in y is -lam)."""
    yn = np.sqrt(yx * yx + yz * yz)
    if yn <= cc:
        return mp / h * yn * yn
    return 2.0 * mp / h * (cc * yn - 0.5 * cc * cc)


@_JIT
def _trial(h, kq, kw, kd, cd, Co, P, mass, mus, mud, S, T0, N0, stuck, dirn, ag1, pext1,
           N1, T1, S1, e, tolF, dt, W, A, G, PF, stats, dq_start, warm, fac,
           Q, hth0, hk, hlaw, hpar, hst_c, hst_t, hz_c, hM, hz, HW):
    """One step with a fixed contact state, from ``T0`` (the pallets' start state enters
    through the relations) to (T1, S1): the trapezoidal rule over ``h`` or a stage of the
    composite step (``_planar_stage.py``), given by its relations (``v = 2/h``, ``a = v²``):
    ``q̇₁ = v Δq + kq[1]``, ``q̈₁ = a Δq + kq[0]``, a pallet's ``ẇ₁ = (h/2) λ₁/m + kw[0]`` and
    ``w₁ = kw[1] + (h/2) ẇ₁``; equilibrium at the end.

    T rows: q, qd, qdd (r); S rows: w, wd, wdd, lam, s (relative velocity), vn (support
    velocity) (2m). Writes the event values ``e`` (positive when the state is violated) and
    their thresholds ``tolF``. ``W`` (13, max(r, 2m)) (rows 0–9 and 11–12; row 10 is
    ``_decide``'s), ``G`` and ``PF`` (2m, r) are scratch
    (``PF``: the sliding pallets' rows of ``P``, so that the products inside Newton's
    iteration skip the stuck pallets); ``stats`` counts trials, Newton iterations and
    factorisations. ``warm``: Newton starts from ``dq_start`` (a prediction from nearby
    trials) instead of the linear step with the friction of the start of the step. ``A``
    (r, r) holds the last factorised Newton matrix, of step length ``fac[0]`` (-1: none): a
    warm trial within 0.1 % of that length starts with chord steps on it. Returns 0, or 1 when
    the step matrix is not positive definite, 2 when Newton's iteration on the sliding
    directions did not converge. Products with ``P`` and ``S`` go through BLAS.

    Damping: ``cd`` (r,) its diagonal in the basis, ``Co`` (r, r) the rest (zero diagonal), or
    (0, 0) when it is diagonal (classical): the products with ``Co`` are skipped then (its
    terms stay exact zeros, set once per call). Without hinges (n_h = 0) their loops are
    skipped as a whole: the per-iteration cost is then the one of the plain stick–slip step.

    Nonlinear hinges (n_h = ``hk.shape[0]``, possibly 0): ``Q`` (n_h, r) their rotations of the
    basis coordinates, ``hth0`` the rotations at q = 0, ``hk`` the elastic stiffness in ``kd``,
    ``hlaw``, ``hpar``, ``hst_c`` their laws and committed states, ``hz_c`` the committed
    corrections (the first iterate's); written: the trial states ``hst_t``, moments ``hM`` and
    corrections ``hz`` at the end of the step. ``HW`` (4, n_h) is scratch (its last row goes with
    ``A``: the tangents in its factor). Their forces
    ``−Qᵀ z(θ)`` enter the residual, their tangents ``Qᵀ (k_t − k) Q`` the Newton matrix.
    """
    r = kd.shape[0]
    m = mass.shape[0]
    m2 = 2 * m
    c0 = 4.0 / (h * h)
    c2 = 2.0 / h
    q0 = T0[0]
    rhs, dq, res, stp, rlin, dg = W[0, :r], W[1, :r], W[2, :r], W[3, :r], W[4, :r], W[5, :r]
    zf, lam, pd, ps = W[6, :m2], W[7, :m2], W[8, :m2], W[9, :m2]
    stats[0] += 1
    nh = hk.shape[0]
    thb, th, dth = HW[0], HW[1], HW[2]  # hinge rotations at dq = 0, now, and along a step
    kfac = HW[3]  # the hinges' k_t − k in the factor held in A (kept across calls, as A is)
    for i in range(nh):
        thb[i] = hth0[i] + np.dot(Q[i], q0)
    hasco = Co.shape[0] > 0
    # Co dq, updated with the steps of dq as sd (Co kq[1] first), and Co times a Newton step:
    # exact zeros without Co (then never touched again in this call)
    od, so = W[11, :r], W[12, :r]
    _damp_off(Co, kq[1], od)
    if not hasco:
        so[:] = 0.0
    for i in range(r):
        dg[i] = c0 + c2 * cd[i] + kd[i]
        rhs[i] = pext1[i] - kq[0, i] - cd[i] * kq[1, i] - od[i] - kd[i] * q0[i]
    # a stuck pallet is a mass on its support: lam = m c0 P dq + beta with
    # beta = m (P kq[0] + ag) (its velocity and acceleration are its support's),
    # so that Σ_stuck P_pᵀ beta_p = S kq[0] + ag_x g_x + ag_z g_z
    Ss = S[:r]
    x0 = np.empty(r)
    for i in range(r):
        x0[i] = -kq[0, i]
    sx = np.dot(Ss, x0)
    for i in range(r):
        rhs[i] += sx[i] - ag1[0] * S[r, i] - ag1[1] * S[r + 1, i]
    sl = np.empty(m, dtype=np.int64)  # the sliding pallets; a compact index a: rows 2a, 2a+1
    n_slide = 0
    for p in range(m):
        if not stuck[p]:
            sl[n_slide] = p
            for c in range(2):
                PF[2 * n_slide + c, :] = P[2 * p + c]
            n_slide += 1
    nf = 2 * n_slide
    PFs = PF[:nf]
    pq = np.dot(PFs, kq[1])
    for a in range(n_slide):
        p = sl[a]
        for c in range(2):
            j = 2 * p + c
            jf = 2 * a + c
            zf[jf] = kw[0, j] - pq[jf]
            lam[jf] = -mud[p] * N1[p] * dirn[j]  # first iterate: the current direction
    zf, lam, pd, ps = zf[:nf], lam[:nf], pd[:nf], ps[:nf]
    refac = True
    nonlin = n_slide > 0 or nh > 0
    if warm and nonlin:
        dq[:] = dq_start
        # within 0.1 % of the factorised step length, the matrix moves by about 0.2 %
        refac = not (fac[0] > 0.0 and abs(h - fac[0]) <= 1e-3 * h)
    else:
        fac[0] = -1.0
        # first iterate: the linear step with the friction of the start of the step
        res[:] = rhs - np.dot(lam, PFs)
        if nh > 0:
            _minus_qtz(res, Q, hz_c, res)
        _a_lin(A, S, c0, c2, cd, Co, kd)
        stats[2] += 1
        if not _chol(A):
            return 1
        _chol_solve(A, res)
        dq[:] = res
        kfac[:] = 0.0
        # the factor is exact while no pallet slides and every hinge stays on a branch of its
        # elastic stiffness: no refactorisation then (decided at the first iteration)
        refac = n_slide > 0
    converged = not nonlin
    last = 1e300
    # Semismooth Newton on dq: R = rhs - A_lin dq - sum_F P_pᵀ lam_p(y_p) = 0 with
    # y_p = zf_p - c2 P_p dq. R is minus the gradient of a strictly convex potential (the
    # friction term is a Huber function of y_p): Newton's steps are damped by backtracking on
    # it, which cures the cycling of plain Newton across the disc
    sd = np.empty(r)  # S dq, and pd = PF dq: updated with the steps of dq
    for _it in range(_NEWTON_MAX if nonlin else 0):
        if _it == 0:
            pd[:] = np.dot(PFs, dq)
            sd[:] = np.dot(Ss, dq)
            if hasco:
                _damp_off(Co, dq, od)
        # the hinges at this iterate: moments, corrections and tangents (th, dth: scratch)
        thsc = 1e-300
        hpot = 0.0
        for i in range(nh):
            th[i] = thb[i] + np.dot(Q[i], dq)
            mi, kt = _hyst_trial_at(hlaw[i], hpar, hst_c, i, th[i], hst_t)
            hM[i] = mi
            hz[i] = mi - hk[i] * th[i]
            dth[i] = kt - hk[i]
            if dth[i] != kfac[i]:
                refac = True  # a hinge changed branch: its tangent is not in the factor
            thsc = max(thsc, abs(th[i]) + abs(mi) / hk[i])
            hpot += abs(mi) + hk[i] * abs(th[i])
        for i in range(r):
            rlin[i] = rhs[i] - dg[i] * dq[i] - c0 * sd[i] - c2 * od[i]
        ymax = 0.0
        hub0 = 0.0
        ng = _frictions(n_slide, sl, h, c2, PFs, mass, mud, N1, zf, pd, lam, G, refac)
        for a in range(n_slide):
            p = sl[a]
            jx = 2 * a
            yx = zf[jx] - c2 * pd[jx]
            yz = zf[jx + 1] - c2 * pd[jx + 1]
            hub0 += _huber(yx, yz, 0.5 * h * mud[p] * N1[p] / mass[p], mass[p], h)
            ymax = max(ymax, abs(zf[jx]) + abs(zf[jx + 1]) + mud[p] * N1[p] * h / mass[p])
        res[:] = rlin - np.dot(lam, PFs)
        if nh > 0:
            _minus_qtz(res, Q, hz, res)
        if refac:
            _a_lin(A, S, c0, c2, cd, Co, kd)
            _syrk_lower(A, G, ng)
            for i in range(nh):  # the hinges' tangents: Qᵀ diag(k_t − k) Q (lower triangle)
                d = dth[i]
                if d != 0.0:
                    for a in range(r):
                        da = d * Q[i, a]
                        if da != 0.0:
                            for b in range(a + 1):
                                A[a, b] += da * Q[i, b]
            if nh > 0:
                kfac[:] = dth[:nh]
            stats[2] += 1
            if not _chol(A):
                return 1
            fac[0] = h
        stats[1] += 1
        stp[:] = res
        _chol_solve(A, stp)  # the Newton step
        # change of the potential along the step, without forming the potential itself
        # (its linear part is large and would cancel): a lin1 + a² lin2 / 2 + Δhuber / c2
        lin1 = -np.dot(rlin, stp)
        slope = -np.dot(res, stp)
        ss = np.dot(Ss, stp)
        if hasco:
            _damp_off(Co, stp, so)
        lin2 = 0.0
        for i in range(r):
            lin2 += stp[i] * (dg[i] * stp[i] + c0 * ss[i] + c2 * so[i])
        ps[:] = np.dot(PFs, stp)
        for i in range(nh):
            dth[i] = np.dot(Q[i], stp)
        hmax = 0.0
        for i in range(nh):
            hmax = max(hmax, abs(dth[i]))
        hpot *= hmax
        # a full step below the stopping tolerance is taken as it is: backtracking would
        # compare changes of the potential at the level of their round-off (at short
        # steps, where 4/h² magnifies it) and could stop on a damped step short of the root
        full = 0.0
        for jf in range(nf):
            full = max(full, abs(c2 * ps[jf]))
        full = full / max(ymax, 1e-300)
        for i in range(nh):
            full = max(full, abs(dth[i]) / thsc)
        if full > 1e-12:
            # and the round-off of lin1 (only the backtracking reads it): the terms of rlin
            # are far larger than rlin at short steps
            for i in range(r):
                hpot += abs(stp[i]) * (abs(rhs[i]) + dg[i] * abs(dq[i]) + c0 * abs(sd[i])
                                       + c2 * abs(od[i]))
        alpha = 1.0
        for _ls in range(40 if full > 1e-12 else 0):
            hub1 = 0.0
            for a in range(n_slide):
                p = sl[a]
                jx = 2 * a
                hub1 += _huber(zf[jx] - c2 * (pd[jx] + alpha * ps[jx]),
                               zf[jx + 1] - c2 * (pd[jx + 1] + alpha * ps[jx + 1]),
                               0.5 * h * mud[p] * N1[p] / mass[p], mass[p], h)
            for i in range(nh):  # the hinges' part of the potential: ∫ z dθ
                hub1 += c2 * _hyst_zwork(hlaw[i], hpar, hst_c, i, hk[i], th[i],
                                         alpha * dth[i], hst_t)
            dpi = alpha * lin1 + 0.5 * alpha * alpha * lin2 + (hub1 - hub0) / c2
            if dpi <= 1e-4 * alpha * slope + 1e-14 * (abs(hub0) / c2 + abs(lin2) + hpot):
                break
            alpha *= 0.5
        step = 0.0
        for i in range(r):
            dq[i] += alpha * stp[i]
            sd[i] += alpha * ss[i]
        if hasco:
            for i in range(r):
                od[i] += alpha * so[i]
        for jf in range(nf):
            pd[jf] += alpha * ps[jf]
            step = max(step, abs(c2 * alpha * ps[jf]))
        # relative to the scales: the pallets' velocities, the hinges' rotations
        step = step / max(ymax, 1e-300)
        for i in range(nh):
            step = max(step, abs(alpha * dth[i]) / thsc)
        # converged when this step, or the next one estimated from the contraction of the
        # last two full steps (Newton's is superlinear), is below 1e-12 (1e-11) of the scale
        if step <= 1e-12 or (
                alpha == 1.0 and last < 1e300 and step <= 0.1 * last
                and step * (step / last) <= 1e-11):
            converged = True
            break
        # the next iteration keeps this factor (a chord step) while the full steps are small
        # or contract fast: the Jacobian only moves with the sliding directions
        refac = not (alpha == 1.0 and ((last < 1e300 and step <= 0.2 * last)
                                       or _it == 0))
        last = step if alpha == 1.0 else 1e300
    if nh > 0:  # the hinges at the final iterate
        for i in range(r):
            x0[i] = q0[i] + dq[i]
        _hinge_eval(Q, hth0, hk, hlaw, hpar, hst_c, hst_t, x0, hM, hz)
    if n_slide > 0:
        _frictions(n_slide, sl, h, c2, PFs, mass, mud, N1, zf, pd, lam, G, False)
    # end state
    q1, qd1, qdd1 = T1[0], T1[1], T1[2]
    w1, wd1, wdd1, lam1, s1, vn1 = S1[0], S1[1], S1[2], S1[3], S1[4], S1[5]
    for i in range(r):
        q1[i] = q0[i] + dq[i]
        qd1[i] = c2 * dq[i] + kq[1, i]
        qdd1[i] = c0 * dq[i] + kq[0, i]
    vn1[:] = np.dot(P, qd1)
    a = 0
    for p in range(m):
        for c in range(2):
            j = 2 * p + c
            if stuck[p]:
                wd1[j] = vn1[j]
                wdd1[j] = c2 * (wd1[j] - kw[0, j]) - ag1[c]
                lam1[j] = mass[p] * (wdd1[j] + ag1[c])
            else:
                lam1[j] = lam[2 * a + c]
                wdd1[j] = -ag1[c] + lam1[j] / mass[p]
                wd1[j] = kw[0, j] + 0.5 * h * lam1[j] / mass[p]
            w1[j] = kw[1, j] + 0.5 * h * wd1[j]
            s1[j] = wd1[j] - vn1[j]
        if not stuck[p]:
            a += 1
    vmax = 0.0
    for j in range(m2):
        vmax = max(vmax, abs(wd1[j]) + abs(vn1[j]))
    for p in range(m):
        jx = 2 * p
        jz = jx + 1
        if stuck[p]:
            e[p] = np.sqrt(lam1[jx] ** 2 + lam1[jz] ** 2) - mus[p] * N1[p]
            # the second term: the force of a stuck pallet is a second difference of the
            # displacements, m (4/h²) dq + ..., whose round-off and Newton tolerance (1e-11 of
            # the velocities) grow as 1/h on short sub-steps
            tolF[p] = 1e-11 * mus[p] * max(N0[p], N1[p]) + 1e-11 * mass[p] * vmax / h + 1e-300
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
