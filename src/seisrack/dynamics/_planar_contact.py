"""Friction of pallets that start to slide from zero relative velocity (source shared by the
numba and pure-Python backends; theory: ``docs/theory/planar_friction.md`` §3).

At an event, pallets released from stick (or stopped and sliding on) have no relative velocity:
their friction opposes their relative *acceleration*, which depends on every friction force
through the structure. With ``a = W lam + b`` (``W = diag(1/m) + P_R (I + S)^-1 P_Rᵀ``, SPD;
``b`` the relative accelerations with no friction on them), the forces are the minimiser of
``lam·W lam / 2 + b·lam`` over the friction discs |lam_p| <= mu_d N_p (the optimality
conditions say: ``a_p = -nu_p lam_p`` with ``nu_p >= 0``, or ``a_p = 0`` inside the disc). It
is the limit of the Newmark step's return map for a vanishing step, so the state decided at
an event is the one the next trial step starts from. Solved by block Gauss–Seidel, one pallet
(a 2 × 2 problem on a disc) at a time.
"""

# ruff: noqa: N803, N806  (matrix names follow the equations)

import numpy as np

try:  # names injected by the loader when executed after ``_planar_step.py``
    _chol_solve  # type: ignore[used-before-def]  # noqa: B018
except NameError:  # pragma: no cover - plain import of this file (pure-Python twin)
    from seisrack.dynamics._events import _JIT
    from seisrack.dynamics._lapack import _chol_solve

#: block Gauss–Seidel sweeps over the released pallets
_SWEEPS = 200


@_JIT
def _disc_min(w11, w12, w22, c1, c2, f):
    """Minimiser of lam·W lam / 2 + c·lam over |lam| <= f (W 2 × 2 SPD). Returns
    (lam_1, lam_2, inside)."""
    det = w11 * w22 - w12 * w12
    l1 = -(w22 * c1 - w12 * c2) / det
    l2 = -(w11 * c2 - w12 * c1) / det
    if l1 * l1 + l2 * l2 <= f * f:
        return l1, l2, True
    if f <= 0.0:  # no friction (mu_d = 0, or no contact force): the disc is a point
        return 0.0, 0.0, False
    # on the circle: lam = -(W + nu I)^-1 c with |lam| = f, nu > 0; in the eigenvectors of W
    # |lam(nu)|² = Σ d_i² / (w_i + nu)², decreasing in nu
    if w12 == 0.0:
        # already in its eigenvectors: exact zeros stay zero (one-axis problems)
        wa = w11
        wb = w22
        ca = 1.0
        sa = 0.0
    else:
        tr = 0.5 * (w11 + w22)
        dif = 0.5 * (w11 - w22)
        rad = np.sqrt(dif * dif + w12 * w12)
        wa = tr + rad
        wb = tr - rad
        ang = 0.5 * np.arctan2(w12, dif)
        ca = np.cos(ang)
        sa = np.sin(ang)
    da = ca * c1 + sa * c2
    db = -sa * c1 + ca * c2
    lo = 0.0
    hi = np.sqrt(c1 * c1 + c2 * c2) / f  # |lam(hi)| <= |c| / hi = f
    nu = lo
    for _ in range(100):
        xa = da / (wa + nu)
        xb = db / (wb + nu)
        nrm = np.sqrt(xa * xa + xb * xb)
        if nrm > f:
            lo = nu
        else:
            hi = nu
        # Newton on 1/|lam(nu)| - 1/f (nearly linear in nu)
        dn = -(xa * xa / (wa + nu) + xb * xb / (wb + nu)) / nrm  # d|lam|/dnu
        nxt = nu + (1.0 / nrm - 1.0 / f) * nrm * nrm / dn
        if not (lo < nxt < hi):
            nxt = 0.5 * (lo + hi)
        if abs(nxt - nu) <= 1e-15 * (abs(nu) + wa):
            nu = nxt
            break
        nu = nxt
    xa = -da / (wa + nu)
    xb = -db / (wb + nu)
    # back to the original axes, scaled onto the circle against round-off
    l1 = ca * xa - sa * xb
    l2 = sa * xa + ca * xb
    s = f / np.sqrt(l1 * l1 + l2 * l2)
    return l1 * s, l2 * s, False


@_JIT
def _released_forces(L, P, mass, mud, N, ag, qdd, rel, lam, inside):
    """Friction ``lam`` of the pallets ``rel`` (indices) sliding from zero relative velocity,
    and the structure's accelerations ``qdd`` (given without their friction, corrected in
    place). ``L``: Cholesky factor of I + S. ``inside[i]``: pallet ``rel[i]`` needs less than
    mu_d N to stay at zero relative acceleration (it sticks)."""
    r = L.shape[0]
    n = rel.shape[0]
    Y = np.empty((2 * n, r))
    for a in range(n):
        for c in range(2):
            row = Y[2 * a + c]
            j = 2 * rel[a] + c
            for i in range(r):
                row[i] = P[j, i]
            # forward substitution only: W = (L^-1 P_Rᵀ)ᵀ (L^-1 P_Rᵀ) + diag(1/m)
            for i in range(r):
                acc = row[i]
                for k in range(i):
                    acc -= L[i, k] * row[k]
                row[i] = acc / L[i, i]
    W = np.dot(Y, Y.T)
    b = np.empty(2 * n)
    x = np.zeros(2 * n)
    fmax = 0.0
    for a in range(n):
        p = rel[a]
        W[2 * a, 2 * a] += 1.0 / mass[p]
        W[2 * a + 1, 2 * a + 1] += 1.0 / mass[p]
        for c in range(2):
            j = 2 * p + c
            acc = 0.0
            for i in range(r):
                acc += P[j, i] * qdd[i]
            b[2 * a + c] = -ag[c] - acc
        fmax = max(fmax, mud[p] * N[p])
    for _sw in range(_SWEEPS):
        change = 0.0
        for a in range(n):
            p = rel[a]
            ia = 2 * a
            c1 = b[ia]
            c2 = b[ia + 1]
            for k in range(2 * n):
                if k != ia and k != ia + 1:
                    c1 += W[ia, k] * x[k]
                    c2 += W[ia + 1, k] * x[k]
            l1, l2, ins = _disc_min(W[ia, ia], W[ia, ia + 1], W[ia + 1, ia + 1], c1, c2,
                                    mud[p] * N[p])
            change = max(change, abs(l1 - x[ia]), abs(l2 - x[ia + 1]))
            x[ia] = l1
            x[ia + 1] = l2
            inside[a] = ins
        if change <= 1e-13 * fmax:
            break
    # qdd -= (I + S)^-1 P_Rᵀ lam_R
    corr = np.zeros(r)
    for a in range(n):
        p = rel[a]
        for c in range(2):
            j = 2 * p + c
            lam[j] = x[2 * a + c]
            for i in range(r):
                corr[i] += P[j, i] * x[2 * a + c]
    _chol_solve(L, corr)
    for i in range(r):
        qdd[i] -= corr[i]
