"""The planar kernel's two kinds of step (source shared by the numba and pure-Python backends):
the trapezoidal rule, and after an event Bathe's composite step, as the line kernel takes them
(``_kernel_stage.py``, ``docs/theory/nonlinear_hinges.md`` §2; here
``docs/theory/planar_friction.md`` §7).

``_planar_step._trial`` takes a step's relations ``kq = [A; V]``, ``kw = [W; X]``: the end
accelerations and velocities of the structure ``q̈₁ = (2/h)² Δq + A``, ``q̇₁ = (2/h) Δq + V``,
a pallet's ``ẇ₁ = (h/2) λ₁/m + W`` and ``w₁ = X + (h/2) ẇ₁`` (one column per pallet and
direction). The trapezoidal rule over ``h`` (``_trap_rel``) and both stages of a composite step
of length ``H`` fit that form with ``h = γH``: the first stage is the trapezoidal rule to
``t + γH``, the second the three-point backward difference over ``t, t + γH, t + H``
(``_bdf_rel``), whose ``c₃ = 2/(γH)`` at ``γ = 2 − √2``. So one Newton matrix serves both
stages. The composite step is L-stable: a basis direction with ``ωH ≫ 1`` loses its period-2h
residue within a step or two after the jump of the pallets' forces at an event, instead of
keeping it undamped, so the stuck pallets' holding forces stay smooth.
"""

# ruff: noqa: N803, N806  (matrix names follow the equations)

import numpy as np

try:  # names injected by the loader when executed after ``_planar_axial.py``
    _trial_ax  # type: ignore[used-before-def]  # noqa: B018
except NameError:  # pragma: no cover - plain import of this file (pure-Python twin)
    from seisrack.dynamics._events import _JIT
    from seisrack.dynamics._planar_axial import _trial_ax

#: the composite step's first stage ends at ``t + GAMMA H`` (as ``_kernel_stage.GAMMA``)
GAMMA_PL = 0.5857864376269049


@_JIT
def _trap_rel(h, T0, S0, ag1, kq, kw):
    """Relations of a trapezoidal step of length ``h`` from (T0, S0): ``q̇₁ = (2/h) Δq − q̇₀``,
    ``q̈₁ = (4/h²) Δq − (4/h) q̇₀ − q̈₀``; ``ẇ₁ = ẇ₀ + (h/2)(ẅ₀ + ẅ₁)``, ``w₁ = w₀ + (h/2)(ẇ₀ +
    ẇ₁)`` with ``ẅ₁ = λ₁/m − a_g``."""
    c1 = 4.0 / h
    for i in range(kq.shape[1]):
        kq[0, i] = -c1 * T0[1, i] - T0[2, i]
        kq[1, i] = -T0[1, i]
    for j in range(kw.shape[1]):
        kw[0, j] = S0[1, j] + 0.5 * h * (S0[2, j] - ag1[j % 2])
        kw[1, j] = S0[0, j] + 0.5 * h * S0[1, j]


@_JIT
def _bdf_rel(H, T0, Tm, S0, Sm, ag1, kq, kw):
    """Relations of the composite step's second stage, from the mid state (Tm, Sm) at ``t +
    γH`` to ``t + H``, ``Δq`` from ``q_m``: ``q̇₁ = c₁ q₀ + c₂ q_m + c₃ q₁``, ``q̈₁ = c₁ q̇₀ +
    c₂ q̇_m + c₃ q̇₁``, the pallets' ``ẇ₁`` and ``ẅ₁`` likewise (``c₁ = (1 − γ)/(γH)``, ``c₃ =
    2/(γH)``, ``c₂ = −(c₁ + c₃)``)."""
    g = GAMMA_PL
    c1 = (1.0 - g) / (g * H)
    c3 = 2.0 / (g * H)
    c2 = -(c1 + c3)
    for i in range(kq.shape[1]):
        V = c1 * (T0[0, i] - Tm[0, i])
        kq[1, i] = V
        kq[0, i] = c1 * T0[1, i] + c2 * Tm[1, i] + c3 * V
    for j in range(kw.shape[1]):
        kw[0, j] = (-ag1[j % 2] - c1 * S0[1, j] - c2 * Sm[1, j]) / c3
        kw[1, j] = -(c1 * S0[0, j] + c2 * Sm[0, j]) / c3


@_JIT
def _step(H, comp, kq, kw, kd, cd, Co, P, mass, mus, mud, S, T0, S0, N0, stuck, dirn,
          ag_m, pe_m, N_m, ag1, pext1, N1, T1, S1, e, tolF, dt, W, A, G, PF, stats, dq_start,
          warm, fac, Q, hth0, hk, hlaw, hpar, hst_c, hst_m, hst_t, hz_c, hz_m, hM, hz, HW,
          AA, AG, Ao, As, Ac, AXW, dn, gw, dqp):
    """A step of length ``H`` from (T0, S0) with a fixed contact state: the trapezoidal rule
    (``comp`` False: ``_trial_ax`` as it was), or the composite step, whose mid state goes to
    rows 3-5 of ``T1`` and 6-11 of ``S1`` (the layout of rows 0-2 and 0-5) and the hinges'
    states and corrections there to ``hst_m``, ``hz_m``. ``ag_m``, ``pe_m``, ``N_m``: the
    excitation at ``t + γH``; ``dqp`` (r,) scratch. Event values and their tolerances are the
    end state's. Returns ``_trial_ax``'s status."""
    if not comp:
        _trap_rel(H, T0, S0, ag1, kq, kw)
        return _trial_ax(H, kq, kw, kd, cd, Co, P, mass, mus, mud, S, T0, N0, stuck, dirn,
                         ag1, pext1, N1, T1, S1, e, tolF, dt, W, A, G, PF, stats, dq_start,
                         warm, fac, Q, hth0, hk, hlaw, hpar, hst_c, hst_t, hz_c, hM, hz, HW,
                         AA, AG, Ao, As, Ac, AXW, dn, gw)
    hm = GAMMA_PL * H
    Tm = T1[3:6]
    Sm = S1[6:12]
    _trap_rel(hm, T0, S0, ag_m, kq, kw)
    for i in range(dqp.shape[0]):
        dqp[i] = hm * T0[1, i] + 0.5 * hm * hm * T0[2, i]
    ok = _trial_ax(hm, kq, kw, kd, cd, Co, P, mass, mus, mud, S, T0, N0, stuck, dirn,
                   ag_m, pe_m, N_m, Tm, Sm, e, tolF, dt, W, A, G, PF, stats, dqp, True, fac,
                   Q, hth0, hk, hlaw, hpar, hst_c, hst_m, hz_c, hM, hz_m, HW,
                   AA, AG, Ao, As, Ac, AXW, dn, gw)
    if ok != 0:
        return ok
    _bdf_rel(H, T0, Tm, S0, Sm, ag1, kq, kw)
    hr = H - hm
    for i in range(dqp.shape[0]):
        dqp[i] = hr * Tm[1, i] + 0.5 * hr * hr * Tm[2, i]
    # the same step matrix as the first stage's (c₃ = 2/(γH)): Newton goes on with its factor
    return _trial_ax(hm, kq, kw, kd, cd, Co, P, mass, mus, mud, S, Tm, N_m, stuck, dirn,
                     ag1, pext1, N1, T1, S1, e, tolF, dt, W, A, G, PF, stats, dqp, True, fac,
                     Q, hth0, hk, hlaw, hpar, hst_m, hst_t, hz_m, hM, hz, HW,
                     AA, AG, Ao, As, Ac, AXW, dn, gw)


@_JIT
def _stage_work(Ta, Sa, Tb, Sb, pea, peb, ag_a, ag_b, cd, Co, P, mass, tmp, out):
    """Work over one stage from (Ta, Sa) to (Tb, Sb), each force a trapezoid of its two end
    values (the trapezoidal rule's energy identity): ``out[0]`` += input (modal loads and the
    pallets' ground inertia), ``out[1]`` += damping, ``out[2]`` += friction. ``ag_a``,
    ``ag_b`` (2,): the ground accelerations at the ends; ``tmp`` (r,) scratch."""
    r = Ta.shape[1]
    e_in = 0.0
    e_d = 0.0
    for i in range(r):
        dq = Tb[0, i] - Ta[0, i]
        e_in += dq * 0.5 * (pea[i] + peb[i])
        e_d += dq * cd[i] * 0.5 * (Ta[1, i] + Tb[1, i])
        tmp[i] = dq
    if Co.shape[0] > 0:  # the off-diagonal damping: dqᵀ Co (qd0 + qd1) / 2
        vm = np.empty(r)
        for i in range(r):
            vm[i] = 0.5 * (Ta[1, i] + Tb[1, i])
        e_d += np.dot(tmp, np.dot(Co, vm))
    vrel = np.dot(P, tmp)
    e_f = 0.0
    for p in range(mass.shape[0]):
        for c in range(2):
            j = 2 * p + c
            dw = Sb[0, j] - Sa[0, j]
            e_in -= mass[p] * dw * 0.5 * (ag_a[c] + ag_b[c])
            e_f -= 0.5 * (Sa[3, j] + Sb[3, j]) * (dw - vrel[j])
    out[0] += e_in
    out[1] += e_d
    out[2] += e_f


@_JIT
def _algorithmic_pl(Ta, Sa, Tb, Sb, mass):
    """Energy a backward-difference stage takes out beyond the physical terms (with
    equilibrium at both ends, ``Δqᵀ f̄ = ΔKE + ΔSE + damping + (Δqᵀ q̈̄ − q̇̄ᵀ Δq̇)`` for a
    mass-orthonormal ``q``, each pallet's ``m (Δw ẅ̄ − ẇ̄ Δẇ)`` likewise; the bracket vanishes
    on the trapezoidal rule): ``_kernel_stage._algorithmic`` in the planar layout."""
    e = 0.0
    for i in range(Ta.shape[1]):
        e += ((Tb[0, i] - Ta[0, i]) * 0.5 * (Ta[2, i] + Tb[2, i])
              - 0.5 * (Ta[1, i] + Tb[1, i]) * (Tb[1, i] - Ta[1, i]))
    for j in range(Sa.shape[1]):
        e += mass[j // 2] * ((Sb[0, j] - Sa[0, j]) * 0.5 * (Sa[2, j] + Sb[2, j])
                             - 0.5 * (Sa[1, j] + Sb[1, j]) * (Sb[1, j] - Sa[1, j]))
    return e
