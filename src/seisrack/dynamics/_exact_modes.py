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
def _trial_exact(h, Eh, PS, NC, P, gpat, MM, on_struct, stuck, sig, T0, S0, SER, NN, e,
                 ag0, ag1, T1, S1, W, fresh):
    """Exact step of length h in a fixed contact state (E = propagator for h).

    Packed arguments (rows): PS = Ψ, Ψᵀ; NC = ν², c (modal stiffness and damping); MM = mass,
    mu_d of the sliders; T0, T1 = η, η̇, g (modal loads), x = Ψ η, xd = Ψ η̇ at the start
    and the end; S0, S1 = w, ẇ, λ, s; SER, NN: load series and normal forces, row 0 at the
    start, row ``e`` at the end; W: scratch η̈, Ψ η̈, structure load of the sliders.
    ``fresh``: T0's g and x already hold the start state's values (the previous sub-step's
    end, same configuration and contact state): they are not recomputed.

    A leaf (no call to another compiled function) with few arguments: numba keeps an atomic
    reference-count increment and decrement per array argument and call when the call is
    inlined (as this one is), so the ~35 separate arrays this step once took cost more than
    its arithmetic. Every sum is in dot-product order (bitwise as ``_mv``)."""
    n = NC.shape[1]
    m = MM.shape[1]
    npat = SER.shape[1]
    if not fresh:  # g0 = modal loads at the start (as g1 below), x0 = Ψ η0
        for i in range(n):
            W[2, i] = 0.0
        for j in range(m):
            if on_struct[j]:
                f = -MM[0, j] * ag0 if stuck[j] else MM[1, j] * NN[0, j] * sig[j]
                if f != 0.0:
                    for i in range(n):
                        W[2, i] += P[j, i] * f
        for k in range(n):
            acc = 0.0
            for c in range(npat):
                acc += gpat[k, c] * SER[0, c]
            T0[2, k] = acc
        for i in range(n):
            f = W[2, i]
            for k in range(n):
                T0[2, k] += PS[0, i, k] * f
        for k in range(n):
            T0[3, k] = 0.0
        for k in range(n):
            ek = T0[0, k]
            for i in range(n):
                T0[3, i] += PS[1, k, i] * ek
    # g1 = modal loads at the end (structure load of the sliders in W[2])
    for i in range(n):
        W[2, i] = 0.0
    for j in range(m):
        if on_struct[j]:
            f = -MM[0, j] * ag1 if stuck[j] else MM[1, j] * NN[e, j] * sig[j]
            if f != 0.0:
                for i in range(n):
                    W[2, i] += P[j, i] * f
    for k in range(n):
        acc = 0.0
        for c in range(npat):
            acc += gpat[k, c] * SER[e, c]
        T1[2, k] = acc
    for i in range(n):
        f = W[2, i]
        for k in range(n):
            T1[2, k] += PS[0, i, k] * f
    # exact modal step, loads linear from g0 to g1 over h (particular part A + B τ,
    # homogeneous part through E), then the accelerations and Ψ (η1, η̇1, η̈1)
    ih = 1.0 / h
    for k in range(n):
        s = (T1[2, k] - T0[2, k]) * ih
        iw = 1.0 / NC[0, k]  # one division per mode: a division costs ~10 multiplications
        B = s * iw
        A = (T0[2, k] - NC[1, k] * B) * iw
        y = T0[0, k] - A
        yd = T0[1, k] - B
        T1[0, k] = A + B * h + Eh[k, 0] * y + Eh[k, 1] * yd
        T1[1, k] = B + Eh[k, 2] * y + Eh[k, 3] * yd
        W[0, k] = T1[2, k] - NC[1, k] * T1[1, k] - NC[0, k] * T1[0, k]
        T1[3, k] = 0.0
        T1[4, k] = 0.0
        W[1, k] = 0.0
    for k in range(n):
        e0 = T1[0, k]
        e1 = T1[1, k]
        e2 = W[0, k]
        for i in range(n):
            T1[3, i] += PS[1, k, i] * e0
            T1[4, i] += PS[1, k, i] * e1
            W[1, i] += PS[1, k, i] * e2
    for j in range(m):
        if stuck[j]:
            d0 = 0.0
            d1 = 0.0
            v1 = 0.0
            a1_ = 0.0
            if on_struct[j]:
                for i in range(n):
                    p = P[j, i]
                    d0 += p * T0[3, i]
                    d1 += p * T1[3, i]
                    v1 += p * T1[4, i]
                    a1_ += p * W[1, i]
            S1[0, j] = S0[0, j] + (d1 - d0)
            S1[1, j] = v1
            S1[2, j] = MM[0, j] * (a1_ + ag1)
            S1[3, j] = 0.0
        else:
            lam0 = -MM[1, j] * NN[0, j] * sig[j]
            S1[2, j] = -MM[1, j] * NN[e, j] * sig[j]
            a0 = -ag0 + lam0 / MM[0, j]
            a1_ = -ag1 + S1[2, j] / MM[0, j]
            S1[1, j] = S0[1, j] + 0.5 * h * (a0 + a1_)
            S1[0, j] = S0[0, j] + h * S0[1, j] + h * h * (2.0 * a0 + a1_) / 6.0
            v1 = 0.0
            if on_struct[j]:
                for i in range(n):
                    v1 += P[j, i] * T1[4, i]
            S1[3, j] = S1[1, j] - v1
    # every array's last use here, in the one exit block: numba's reference-count pruning
    # then removes the increments and decrements of the arguments where it is not inlined
    return (Eh.shape[0] + PS.shape[0] + NC.shape[0] + P.shape[0] + gpat.shape[0] + npat
            + MM.shape[0] + on_struct.shape[0] + stuck.shape[0] + sig.shape[0] + T0.shape[0]
            + S0.shape[0] + SER.shape[0] + NN.shape[0] + T1.shape[0] + S1.shape[0] + W.shape[0])


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
    ih = 1.0 / h
    for k in range(n):
        c = cc[k]
        w = nu2[k]
        iw = 1.0 / w
        s = (g1[k] - g0[k]) * ih
        B = s * iw
        A = (g0[k] - c * B) * iw
        y0 = eta0[k] - A
        yd0 = etad0[k] - B
        y1 = Eh[k, 0] * y0 + Eh[k, 1] * yd0
        yd1 = Eh[k, 2] * y0 + Eh[k, 3] * yd0
        eta_h = A + B * h + y1
        d_eta = eta_h - eta0[k]
        int_y = -((yd1 - yd0) + c * (y1 - y0)) * iw
        int_eta = A * h + 0.5 * B * h * h + int_y
        mom = h * eta_h - int_eta  # ∫ τ η̇ dτ
        e_in += g0[k] * d_eta + s * mom
        # damping: c ∫ η̇² = c B² h + 2 c B (y1 - y0) + x0ᵀ (cW) x0
        if c != 0.0:
            R11 = Eh[k, 2] * Eh[k, 2]
            R12 = Eh[k, 2] * Eh[k, 3]
            R22 = Eh[k, 3] * Eh[k, 3] - 1.0
            w12 = -0.5 * R11 * iw
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
