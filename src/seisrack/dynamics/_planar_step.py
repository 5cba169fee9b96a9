"""The Newmark step of the planar stick–slip kernel with a fixed contact state (source
shared by the numba and pure-Python backends; theory: ``docs/theory/planar_friction.md`` §2).

``_trial`` advances the structure (basis coordinates) and the pallets by one (sub)step; a
sliding pallet's end force comes from the return map onto its friction disc, and the step
equation (the gradient of a convex potential) is solved by Newton's method with backtracking.
"""

# ruff: noqa: N803, N806  (matrix names follow the equations)

import numpy as np

try:  # names injected by the loader when executed after ``_events.py``
    _interp  # type: ignore[used-before-def]  # noqa: B018
except NameError:  # pragma: no cover - plain import of this file (pure-Python twin)
    from seisrack.dynamics._events import _JIT, _interp

_NEWTON_MAX = 40


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
