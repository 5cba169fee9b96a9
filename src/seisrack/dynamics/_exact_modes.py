"""Closed-form modal propagation (the trial step) and its exact work integrals (exact kernel,
part 1 of 3).

Source shared by the numba and pure-Python backends (see :mod:`seisrack.dynamics.kernels`):
executed after ``_events.py`` and ``_kernel.py`` in one namespace by ``_kernel_numba.py``.
Theory: ``docs/theory/stick_slip_engine.md`` §9.
"""

# ruff: noqa: N803, N806  (matrix names follow the equations)

import numpy as np

try:  # names injected by the loader
    _JIT  # type: ignore[used-before-def]  # noqa: B018
except NameError:  # pragma: no cover - plain import of this file (pure-Python twin)
    from seisrack.dynamics._events import _JIT

#: Gauss–Legendre 3-point nodes and weights on [0, 1] (energy quadrature)
_GL_X = np.array([0.5 - 0.1 * np.sqrt(15.0), 0.5, 0.5 + 0.1 * np.sqrt(15.0)])
_GL_W = np.array([5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0])


@_JIT
def _mode_matrix(nu2, c, h, E):
    """Homogeneous propagator of y'' + c y' + nu2 y = 0 over h: E = (E00, E01, E10, E11).

    One formula for every damping regime: with a = c/2 and b² = nu2 - a², the solution is
    e^{-a t} (C(t) y0 + S(t) (y0' + a y0)) with C = cos/cosh/1 and S = sin(bt)/b, sinh/b or t.
    Overdamped stiff modes are evaluated as sums of decaying exponentials (no overflow).
    """
    a = 0.5 * c
    b2 = nu2 - a * a
    x = b2 * h * h
    if abs(x) < 1e-3:
        # series in b² h² (cos / cosh and sin/b / sinh/b share it)
        eC = 1.0 - x / 2.0 + x * x / 24.0 - x * x * x / 720.0
        eS = h * (1.0 - x / 6.0 + x * x / 120.0 - x * x * x / 5040.0)
        ea = np.exp(-a * h)
        eC *= ea
        eS *= ea
    elif b2 > 0.0:
        b = np.sqrt(b2)
        ea = np.exp(-a * h)
        eC = ea * np.cos(b * h)
        eS = ea * np.sin(b * h) / b
    else:
        b = np.sqrt(-b2)
        # a - b >= 0 computed without cancellation: (a - b) = nu2 / (a + b)
        slow = nu2 / (a + b)
        e1 = np.exp(-slow * h)
        e2 = np.exp(-(a + b) * h)
        eC = 0.5 * (e1 + e2)
        eS = 0.5 * (e1 - e2) / b
    E[0] = eC + a * eS
    E[1] = eS
    E[2] = -nu2 * eS
    E[3] = eC - a * eS


@_JIT
def _mode_matrices(nu2, cc, h, E):
    for k in range(nu2.shape[0]):
        _mode_matrix(nu2[k], cc[k], h, E[k])


@_JIT
def _trial_exact(h, Eh, psi, psiT, nu2, cc, P, gpat, mass, mud, on_struct, stuck, sig,
                 eta0, etad0, w0, wd0, ser0, ser1, ag0, ag1, N0, N1, g0, g1,
                 eta1, etad1, w1, wd1, lam1, s1, etadd, x0, x1, xd1, xdd, fq, fresh):
    """Exact step of length h in a fixed contact state (E = propagator for h).

    ``fresh``: g0 and x0 = Ψ η0 already hold the start state's values (the previous
    sub-step's end, same configuration and contact state): they are not recomputed.
    A leaf (the modal loads, the closed-form modal step and the products with Ψ written out,
    each sum in dot-product order): numba then drops the reference counting of its ~35
    array arguments, which a call to another compiled function keeps (an atomic increment
    and decrement per array and call: most of this step's cost)."""
    n = nu2.shape[0]
    m = mass.shape[0]
    npat = ser0.shape[0]
    if not fresh:  # g0 = _loads(t0), x0 = Ψ η0
        for i in range(n):
            fq[i] = 0.0
        for j in range(m):
            if on_struct[j]:
                f = -mass[j] * ag0 if stuck[j] else mud[j] * N0[j] * sig[j]
                if f != 0.0:
                    for i in range(n):
                        fq[i] += P[j, i] * f
        for k in range(n):
            acc = 0.0
            for c in range(npat):
                acc += gpat[k, c] * ser0[c]
            g0[k] = acc
            x0[k] = 0.0
        for i in range(n):
            f = fq[i]
            for k in range(n):
                g0[k] += psi[i, k] * f
        for k in range(n):
            e = eta0[k]
            for i in range(n):
                x0[i] += psiT[k, i] * e
    # g1 = _loads(t1)
    for i in range(n):
        fq[i] = 0.0
    for j in range(m):
        if on_struct[j]:
            f = -mass[j] * ag1 if stuck[j] else mud[j] * N1[j] * sig[j]
            if f != 0.0:
                for i in range(n):
                    fq[i] += P[j, i] * f
    for k in range(n):
        acc = 0.0
        for c in range(npat):
            acc += gpat[k, c] * ser1[c]
        g1[k] = acc
    for i in range(n):
        f = fq[i]
        for k in range(n):
            g1[k] += psi[i, k] * f
    # exact modal step, loads linear from g0 to g1 over h (particular part A + B τ,
    # homogeneous part through E), then the accelerations and Ψ (η1, η̇1, η̈1)
    for k in range(n):
        s = (g1[k] - g0[k]) / h
        B = s / nu2[k]
        A = (g0[k] - cc[k] * B) / nu2[k]
        y = eta0[k] - A
        yd = etad0[k] - B
        eta1[k] = A + B * h + Eh[k, 0] * y + Eh[k, 1] * yd
        etad1[k] = B + Eh[k, 2] * y + Eh[k, 3] * yd
        etadd[k] = g1[k] - cc[k] * etad1[k] - nu2[k] * eta1[k]
        x1[k] = 0.0
        xd1[k] = 0.0
        xdd[k] = 0.0
    for k in range(n):
        e = eta1[k]
        ed = etad1[k]
        edd = etadd[k]
        for i in range(n):
            x1[i] += psiT[k, i] * e
            xd1[i] += psiT[k, i] * ed
            xdd[i] += psiT[k, i] * edd
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
    # every array's last use here, in the one exit block: numba's reference-count pruning
    # then removes the increments and decrements of the arguments (see the docstring)
    return (Eh.shape[0] + psi.shape[0] + psiT.shape[0] + nu2.shape[0] + cc.shape[0]
            + P.shape[0] + gpat.shape[0] + mass.shape[0] + mud.shape[0] + on_struct.shape[0]
            + stuck.shape[0] + sig.shape[0] + eta0.shape[0] + etad0.shape[0] + w0.shape[0]
            + wd0.shape[0] + ser0.shape[0] + ser1.shape[0] + N0.shape[0] + N1.shape[0]
            + g0.shape[0] + g1.shape[0] + eta1.shape[0] + etad1.shape[0] + w1.shape[0]
            + wd1.shape[0] + lam1.shape[0] + s1.shape[0] + etadd.shape[0] + x0.shape[0]
            + x1.shape[0] + xd1.shape[0] + xdd.shape[0] + fq.shape[0])


@_JIT
def _energy_substep(h, Eh, psi, nu2, cc, P, eta0, etad0, g0, g1, mass, mud, on_struct, stuck,
                    sig, w0, wd0, ag0, ag1, N0, N1, out, fq, f0, fs):
    """Input, damping and friction work over a sub-step, in closed form.

    Per mode (η̈ + c η̇ + ν² η = g0 + s τ, particular part A + B τ, homogeneous part y):
    ∫ (l0 + l1 τ) η̇ dτ = l0 Δη + l1 (h η(h) - ∫η), with ∫y = -(Δẏ + c Δy)/ν² from the mode
    equation, and c ∫ η̇² = c B² h + 2 c B Δy + x0ᵀ (c W) x0, where W is the 2x2 Gramian
    ∫ e^{Jᵀτ} e2 e2ᵀ e^{Jτ} dτ solved from its Lyapunov equation (written for c W, so that an
    undamped mode gives 0 without dividing by c). Slider terms are polynomials in τ
    (3-point Gauss–Legendre is exact for them). Powers: gᵀη̇ is the structural input (it
    includes the stuck sliders' inertia); the sliding forces inside g are moved to friction.
    """
    n = nu2.shape[0]
    m = mass.shape[0]
    e_in = 0.0
    e_d = 0.0
    e_f = 0.0
    # sliding forces on the structure, λ_j(τ) = l0_j + ls_j τ, as modal loads f0 + fs τ
    # (written out so that this function stays a leaf, see ``_trial_exact``: a call to
    # another compiled function keeps numba's reference counting of every array argument;
    # nothing to add when every slider on the structure sticks, the usual case)
    any_sliding = False
    for j in range(m):
        if on_struct[j] and not stuck[j]:
            any_sliding = True
    for k in range(n):
        f0[k] = 0.0
        fs[k] = 0.0
    if any_sliding:
        for side in range(2):
            a = 1.0 if side == 0 else 1.0 / h
            b = 0.0 if side == 0 else -1.0 / h
            for i in range(n):
                fq[i] = 0.0
            for j in range(m):
                if on_struct[j] and not stuck[j]:
                    Na = N0[j] if side == 0 else N1[j]
                    c = -mud[j] * sig[j] * (a * Na + b * N0[j])
                    for i in range(n):
                        fq[i] += P[j, i] * c
            for i in range(n):
                f = fq[i]
                if side == 0:
                    for k in range(n):
                        f0[k] += psi[i, k] * f
                else:
                    for k in range(n):
                        fs[k] += psi[i, k] * f
    for k in range(n):
        c = cc[k]
        w = nu2[k]
        s = (g1[k] - g0[k]) / h
        B = s / w
        A = (g0[k] - c * B) / w
        y0 = eta0[k] - A
        yd0 = etad0[k] - B
        y1 = Eh[k, 0] * y0 + Eh[k, 1] * yd0
        yd1 = Eh[k, 2] * y0 + Eh[k, 3] * yd0
        eta_h = A + B * h + y1
        d_eta = eta_h - eta0[k]
        int_y = -((yd1 - yd0) + c * (y1 - y0)) / w
        int_eta = A * h + 0.5 * B * h * h + int_y
        mom = h * eta_h - int_eta  # ∫ τ η̇ dτ
        e_in += g0[k] * d_eta + s * mom
        # damping: c ∫ η̇² = c B² h + 2 c B (y1 - y0) + x0ᵀ (cW) x0
        if c != 0.0:
            R11 = Eh[k, 2] * Eh[k, 2]
            R12 = Eh[k, 2] * Eh[k, 3]
            R22 = Eh[k, 3] * Eh[k, 3] - 1.0
            w12 = -R11 / (2.0 * w)
            cw22 = w12 - 0.5 * R22
            cw12 = c * w12
            cw11 = c * R12 + w * cw22 + c * c * w12
            e_d += (c * B * B * h + 2.0 * c * B * (y1 - y0)
                    + cw11 * y0 * y0 + 2.0 * cw12 * y0 * yd0 + cw22 * yd0 * yd0)
        # sliding forces on the structure: their power leaves the input, enters friction
        if any_sliding:
            work = f0[k] * d_eta + fs[k] * mom  # Σ_j ∫ λ_j v_support dτ
            e_in += work
            e_f += work
    for j in range(m):
        if stuck[j]:
            continue  # stuck on the structure: inside g; stuck on the ground: no motion
        l0 = -mud[j] * N0[j] * sig[j]
        l1 = -mud[j] * N1[j] * sig[j]
        a0 = -ag0 + l0 / mass[j]
        for p in range(3):
            x = _GL_X[p]
            tau = x * h
            wgt = _GL_W[p] * h
            ag_t = ag0 + x * (ag1 - ag0)
            lam_t = l0 + x * (l1 - l0)
            wd_t = wd0[j] + 0.5 * tau * (a0 + (-ag_t + lam_t / mass[j]))
            e_in -= wgt * mass[j] * ag_t * wd_t
            e_f -= wgt * lam_t * wd_t
    out[0] = e_in
    out[1] = e_d
    out[2] = e_f
