"""The line kernel's two kinds of step (source shared by the numba and pure-Python backends).

A step's relations are handed to ``_kernel_hinge._nl_trial`` as ``sc = [a, v, β, κ]``, ``kq =
[A; V]`` and ``kw = [W; X]``: the end accelerations and velocities of the structure are
``q̈₁ = a Δq + A`` and ``q̇₁ = v Δq + V`` (``a = v²``), a slider's ``ẇ₁ = β λ₁/m + W`` and
``w₁ = X + κ ẇ₁``; equilibrium holds at the end of the step.

* ``_trap_coefs``: the trapezoidal rule (Newmark's average acceleration) over ``h``, the
  regular step (``docs/theory/stick_slip_engine.md`` §3).
* ``_composite``: after an event, Bathe's composite step (K.J. Bathe and M.M.I. Baig,
  *Computers & Structures* 83 (2005) 2513-2524; the TR-BDF2 of R.E. Bank et al., IEEE Trans.
  CAD 4 (1985)): a trapezoidal step to ``t + γH``, then the three-point backward difference
  ``ẋ₁ = c₁ x₀ + c₂ x_m + c₃ x₁`` (``c₁ = (1−γ)/(γH)``, ``c₂ = −1/((1−γ)γH)``, ``c₃ =
  (2−γ)/((1−γ)H)``) for the velocities and the accelerations (``_bdf_coefs``). It is second
  order and L-stable: a direction with ``ωH ≫ 1`` loses its residue within a step or two
  instead of keeping the trapezoidal rule's undamped period-2H alternation, so the jump of the
  contact forces at an event does not leave the stiff directions ringing, the stuck pallets'
  holding forces stay smooth and no spurious slip starts (``docs/theory/nonlinear_hinges.md``
  §5). With ``γ = 2 − √2`` both stages have the same effective stiffness ``K + vC + v²M``
  (``v = 2/(γH) = c₃``): one factorisation serves the whole step.
"""

# ruff: noqa: N803, N806  (matrix names follow the equations)

try:  # names injected by the loader when executed after ``_kernel_hinge.py``
    _nl_trial  # type: ignore[used-before-def]  # noqa: B018
except NameError:  # pragma: no cover - plain import of this file (pure-Python twin)
    from seisrack.dynamics._events import _JIT
    from seisrack.dynamics._hysteresis import HYST_S_THETA
    from seisrack.dynamics._kernel_hinge import _hinge_state, _nl_trial
    from seisrack.dynamics._linalg import _damp_mul, _dh_into, _mv


@_JIT
def _trap_coefs(h, w0, qd0, qdd0, wd0, wdd0, ag1, sc, kq, kw):
    """Relations of a trapezoidal step of length ``h``: ``q̇₁ = (2/h) Δq − q̇₀``, ``q̈₁ =
    (4/h²) Δq − (4/h) q̇₀ − q̈₀``; ``ẇ₁ = ẇ₀ + (h/2)(ẅ₀ + ẅ₁)``, ``w₁ = w₀ + (h/2)(ẇ₀ + ẇ₁)``."""
    v = 2.0 / h
    sc[0] = v * v
    sc[1] = v
    sc[2] = 0.5 * h
    sc[3] = 0.5 * h
    for i in range(qd0.shape[0]):
        kq[0, i] = -2.0 * v * qd0[i] - qdd0[i]
        kq[1, i] = -qd0[i]
    for j in range(w0.shape[0]):
        kw[0, j] = wd0[j] + 0.5 * h * (wdd0[j] - ag1)
        kw[1, j] = w0[j] + 0.5 * h * wd0[j]


#: the composite step's first stage ends at ``t + GAMMA H``: 2 − √2, where both stages share
#: one effective stiffness
GAMMA = 0.5857864376269049


@_JIT
def _bdf_coefs(H, q0, qd0, qm, qdm, w0, wd0, wm, wdm, ag1, sc, kq, kw):
    """Relations of the composite step's second stage, from ``t + γH`` (state ``qm``, ...) to
    ``t + H``, with ``Δq`` measured from ``qm``: ``q̇₁ = c₁ q₀ + c₂ q_m + c₃ q₁ = c₃ Δq +
    c₁ (q₀ − q_m)`` (``c₁ + c₂ + c₃ = 0``), ``q̈₁ = c₁ q̇₀ + c₂ q̇_m + c₃ q̇₁``; a slider's
    ``ẅ₁ = c₁ ẇ₀ + c₂ ẇ_m + c₃ ẇ₁`` and ``ẇ₁ = c₁ w₀ + c₂ w_m + c₃ w₁``."""
    g = GAMMA
    c1 = (1.0 - g) / (g * H)
    c3 = 2.0 / (g * H)  # = (2 − γ)/((1 − γ)H) at γ = 2 − √2: the first stage's 2/(γH), bit for bit
    c2 = -(c1 + c3)  # = −1/((1 − γ)γH): the differences of a constant vanish exactly
    sc[0] = c3 * c3
    sc[1] = c3
    sc[2] = 1.0 / c3
    sc[3] = 1.0 / c3
    for i in range(q0.shape[0]):
        V = c1 * (q0[i] - qm[i])
        kq[1, i] = V
        kq[0, i] = c1 * qd0[i] + c2 * qdm[i] + c3 * V
    for j in range(w0.shape[0]):
        kw[0, j] = (-ag1 - c1 * wd0[j] - c2 * wdm[j]) / c3
        kw[1, j] = -(c1 * w0[j] + c2 * wm[j]) / c3


@_JIT
def _composite(
    H, kd, cd, Cq, diag, D, DH, mass, mus, mud, rate, hth0, hk, hlaw, hpar, hst_c, hst_m,
    hst_t, T0, S0, T1, S1, ag_m, pe_m, N_m, ag1, pe1, N1, stuck, sig, hz, hM_t, hz_t, hz_m,
    wn, wx, Ms_key, n_cfg, Kc, piv, om, cmeta, stats, sc, kq, kw,
):
    """Bathe's composite step of length ``H`` from the state ``T0`` (q, q̇, q̈), ``S0`` (w, ẇ,
    λ, s, ẅ) with a fixed contact state: the trapezoidal step to ``t + γH`` into rows 3-5 of
    ``T1`` and 5-9 of ``S1`` (the mid state, in the same layout), then the backward-difference
    stage into rows 0-2 and 0-4. ``ag_m``, ``pe_m``, ``N_m``: the excitation at ``t + γH``;
    ``hz``: the hinges' committed corrections; ``hst_m``, ``hz_m``: the hinges at the mid
    state (the second stage's committed state). ``DH`` is overwritten (``D K̂⁻¹``, the same
    for both stages). Returns ``_nl_trial``'s status."""
    _trap_coefs(GAMMA * H, S0[0], T0[1], T0[2], S0[1], S0[4], ag_m, sc, kq, kw)
    _dh_into(kd, cd, Cq, diag, sc[1], D, DH)
    hz_m[:] = hz
    st = _nl_trial(
        sc, kq, kw, kd, cd, Cq, diag, D, DH, mass, mus, mud, rate, hth0, hk, hlaw, hpar, hst_c,
        hst_m, T0[0], S0[2], ag_m, pe_m, N_m, stuck, sig,
        T1[3], T1[4], T1[5], S1[5], S1[6], S1[9], S1[7], S1[8], hM_t, hz_m, wn, wx, Ms_key,
        n_cfg, Kc, piv, om, cmeta, stats)
    if st != 0:
        return st
    _bdf_coefs(H, T0[0], T0[1], T1[3], T1[4], S0[0], S0[1], S1[5], S1[6], ag1, sc, kq, kw)
    hz_t[:] = hz_m
    return _nl_trial(
        sc, kq, kw, kd, cd, Cq, diag, D, DH, mass, mus, mud, rate, hth0, hk, hlaw, hpar, hst_m,
        hst_t, T1[3], S1[7], ag1, pe1, N1, stuck, sig,
        T1[0], T1[1], T1[2], S1[0], S1[1], S1[4], S1[2], S1[3], hM_t, hz_t, wn, wx, Ms_key,
        n_cfg, Kc, piv, om, cmeta, stats)


@_JIT
def _hinge_commit2(Q, hth0, hk, hlaw, hpar, hst_c, hst_m, hst_t, qm, q1, hM, hz, hM_t, hz_t,
                   hz_m):
    """``_kernel_hinge._hinge_commit`` for a composite step: the hinges' states recomputed at
    its mid state ``qm`` (from the committed ones), then at its end ``q1`` (from the mid ones),
    committed; returns the correction forces' work ``∫ z dθ`` (trapezoid over each stage, as
    the energy identity of each stage needs)."""
    _hinge_state(Q, hth0, hk, hlaw, hpar, hst_c, qm, hst_m, hM_t, hz_m)
    _hinge_state(Q, hth0, hk, hlaw, hpar, hst_m, q1, hst_t, hM_t, hz_t)
    work = 0.0
    for i in range(hk.shape[0]):
        th0 = hst_c[i, HYST_S_THETA]
        thm = hst_m[i, HYST_S_THETA]
        work += (0.5 * (hz[i] + hz_m[i]) * (thm - th0)
                 + 0.5 * (hz_m[i] + hz_t[i]) * (hst_t[i, HYST_S_THETA] - thm))
        hM[i] = hM_t[i]
        hz[i] = hz_t[i]
        for c in range(hst_c.shape[1]):
            hst_c[i, c] = hst_t[i, c]
    return work


@_JIT
def _stage_energy(q0, qd0, q1, qd1, w0, w1, lam0, lam1, pe0, pe1, ag0, ag1, P, mass, cd, Cq,
                  diag, tmpn, tmpn2, tmpm, out):
    """Energy increments of one stage (trapezoid of the end values, as the trapezoidal rule's
    identity needs): ``out[0]`` += input, ``out[1]`` += damping, ``out[2]`` += friction."""
    n = q0.shape[0]
    for i in range(n):
        tmpn[i] = qd0[i] + qd1[i]
    _damp_mul(cd, Cq, diag, tmpn, tmpn2)
    dq_in = 0.0
    dd = 0.0
    for i in range(n):
        dqi = q1[i] - q0[i]
        dq_in += dqi * 0.5 * (pe0[i] + pe1[i])
        dd += dqi * 0.5 * tmpn2[i]
        tmpn[i] = dqi
    _mv(P, tmpn, tmpm)
    fr = 0.0
    for j in range(mass.shape[0]):
        dwj = w1[j] - w0[j]
        dq_in -= mass[j] * dwj * 0.5 * (ag0 + ag1)
        fr -= 0.5 * (lam0[j] + lam1[j]) * (dwj - tmpm[j])
    out[0] += dq_in
    out[1] += dd
    out[2] += fr


@_JIT
def _algorithmic(q0, qd0, qdd0, q1, qd1, qdd1, w0, wd0, wdd0, w1, wd1, wdd1, mass):
    """Energy a stage takes out beyond the physical terms: with equilibrium at both of its
    ends, ``Δqᵀ f̄ = ΔKE + ΔSE + Δqᵀ C q̇̄ + Δqᵀ q̈̄ − q̇̄ᵀ Δq̇`` (mass-orthonormal ``q``; the
    sliders' ``m (Δw ẅ̄ − ẇ̄ Δẇ)`` likewise) for any scheme; the last two terms vanish on the
    trapezoidal rule (``Δq = h q̇̄``, ``Δq̇ = h q̈̄``) and are this function's value."""
    e = 0.0
    for i in range(q0.shape[0]):
        e += ((q1[i] - q0[i]) * 0.5 * (qdd0[i] + qdd1[i])
              - 0.5 * (qd0[i] + qd1[i]) * (qd1[i] - qd0[i]))
    for j in range(w0.shape[0]):
        e += mass[j] * ((w1[j] - w0[j]) * 0.5 * (wdd0[j] + wdd1[j])
                        - 0.5 * (wd0[j] + wd1[j]) * (wd1[j] - wd0[j]))
    return e
