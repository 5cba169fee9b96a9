"""Newmark trial step of the line kernel, with nonlinear hinges and velocity-dependent friction
(issue #12) when there are any.

Same source for the numba build and the pure-Python twin (see ``_kernel_numba.py``). Called by
``run_kernel`` (``_kernel.py``) for every (sub)step, linear or not; the event core
(``_events.py``) and the driver locate stick/slip events inside the step. See
``docs/theory/nonlinear_hinges.md`` and ``docs/theory/stick_slip_engine.md`` §3.

Formulation, in the structure's mass-orthonormal coordinates ``q`` (``u = Φ q``):

* hinge ``i`` is a rotational spring between two DOFs (or a DOF and the ground) whose relative
  rotation is ``θ_i = θ0_i + Q_i q`` (``Q = Bᵀ Φ``; ``θ0`` its rotation in the static state
  the motion starts from, e.g. under gravity, since ``q`` is measured from that state). Its
  elastic stiffness ``k_i`` stays in the modal stiffness ``kd``; the law's moment ``M_i(θ_i)``
  enters as the correction ``z_i = M_i − k_i θ_i`` (zero while the hinge is elastic), applied
  as the generalized force ``Qᵀ z``;
* end-of-step equilibrium of an implicit step, average-acceleration Newmark (β = 1/4, γ = 1/2)
  or a stage of the composite step after an event (``_kernel_stage.py``):
  ``K̂ Δq = r − Pᵀ λ₁ − Qᵀ z(θ₁)`` with ``K̂ = K + v C + v² I`` (``v = 2/h`` for Newmark);
* unknowns ``x = [λ (m sliders), θ (n_h hinges)]``, residuals
  stuck ``j``: relative velocity ``s_j(x) = 0``; sliding ``j``: ``λ_j + N_j σ_j μ_j(|s_j|) = 0``;
  hinge ``i``: ``θ_i − θ0_i − Q_i (q₀ + Δq(x)) = 0``; solved by Newton with the laws' consistent
  tangents (``D = [P; Q]``); each Newton step is one solve with an n × n core, the tangent
  effective stiffness with the stuck pallets' masses (Woodbury; ``_nl_trial``), whose factors
  are kept while the step length, the contact state and the hinges' branches hold;
* velocity-dependent friction while sliding: ``μ(v) = μ_d + (μ_s − μ_d) e^(−a v)``, equal to
  μ_s at v = 0 (continuous with the static threshold) and to Coulomb's μ_d as ``a → ∞``.
"""

# ruff: noqa: N803, N806  (matrix names follow the equations)

import numpy as np

try:  # names injected by the loader when executed after ``_hysteresis.py`` and ``_linalg.py``
    _hyst_trial_at  # type: ignore[used-before-def]  # noqa: B018
except NameError:  # pragma: no cover - plain import of this file (pure-Python twin)
    from seisrack.dynamics._contact import _rank1, _step_end
    from seisrack.dynamics._events import _JIT
    from seisrack.dynamics._hysteresis import HYST_S_THETA, _hyst_trial_at
    from seisrack.dynamics._lapack import _chol, _chol_solve
    from seisrack.dynamics._linalg import (
        _damp_mul,
        _lu_into,
        _lu_solve,
        _modal_solve,
        _mtv,
        _mv,
    )

STATUS_NEWTON = 4
_NEWTON_MAX = 60
_NEWTON_DAMPED = 20  # after this many iterations the steps are halved (breaks branch cycling)
_REBUILD = 4000.0  # rank-one updates of the Newton core's hinge sum before it is rebuilt


@_JIT
def _mu_slide(mus, mud, rate, v):
    """Sliding friction coefficient at relative speed ``v`` >= 0 and its derivative."""
    if rate <= 0.0:
        return mud, 0.0
    e = np.exp(-rate * v)
    return mud + (mus - mud) * e, -rate * (mus - mud) * e


@_JIT
def _mu_now(mus, mud, rate, stuck, s, out):
    """Friction coefficient a sliding slider carries now (mu_s at zero speed when rate > 0)."""
    for j in range(mus.shape[0]):
        mu, _d = _mu_slide(mus[j], mud[j], rate[j], 0.0 if stuck[j] else abs(s[j]))
        out[j] = mu


@_JIT
def _hinge_state(Q, hth0, hk, hlaw, hpar, hst_c, q, hst_t, hM, hz):
    """Hinge rotations of ``q``: moments ``hM``, corrections ``hz`` and trial states."""
    for i in range(Q.shape[0]):
        th = hth0[i]
        for k in range(Q.shape[1]):
            th += Q[i, k] * q[k]
        Mi, _kt = _hyst_trial_at(hlaw[i], hpar, hst_c, i, th, hst_t)
        hM[i] = Mi
        hz[i] = Mi - hk[i] * th


@_JIT
def _minus_qtz(pe, Q, hz, out):
    """out = pe − Qᵀ z: the external load with the hinges' correction forces moved over."""
    for k in range(pe.shape[0]):
        acc = pe[k]
        for i in range(Q.shape[0]):
            acc -= Q[i, k] * hz[i]
        out[k] = acc


@_JIT
def _core_weights(Q, zp, om, Kc, cmeta):
    """Bring ``Kc[0] = Σ_i zp_i q_iᵀ q_i`` (``q_i``: hinge ``i``'s row of ``Q``; ``zp_i = k_t −
    k_i``, zero on its elastic branch) up to date by rank-one updates; ``om`` holds the weights
    it carries. Rebuilt from them every ``_REBUILD`` updates (bounds the round-off drift).
    Returns True when any weight changed."""
    changed = False
    for i in range(om.shape[0]):
        dw = zp[i] - om[i]
        if dw != 0.0:
            changed = True
            om[i] = zp[i]
            cmeta[1] += 1.0
            _rank1(Kc[0], Q[i], dw)
    if cmeta[1] > _REBUILD:
        Kc[0, :, :] = 0.0
        for i in range(om.shape[0]):
            if om[i] != 0.0:
                _rank1(Kc[0], Q[i], om[i])
        cmeta[1] = 0.0
    return changed


@_JIT
def _core_factor(kd, cd, Cq, diag, av, Ms_key, Kc, sw, D, piv):
    """Factors, into ``Kc[1]``, of the Newton core ``K̂ + av²(Ms_key − I) + Kc[0] +
    Σ_j sw_j p_j p_jᵀ`` (``K̂ = K + av C + av² I``, ``av`` the step's velocity coefficient:
    2/h for the trapezoidal rule): the structure's tangent effective stiffness with its stuck
    pallets' masses (``Ms_key``: the configuration mass ``I + Σ_stuck m_j p_j p_jᵀ``; ``sw``:
    sliding pallets' velocity-dependent friction). Cholesky (lower triangle) when it is positive
    definite, else LU with pivoting (softening tangents; ``piv[0] < 0`` marks the Cholesky
    factor). Returns False if singular."""
    n = kd.shape[0]
    A = Kc[1]
    c0 = av * av
    for lu in range(2):
        for r in range(n):
            for c in range(n if lu else r + 1):
                A[r, c] = c0 * Ms_key[r, c] + Kc[0, r, c]
                if not diag:
                    A[r, c] += av * Cq[r, c]
            A[r, r] += kd[r]
            if diag:
                A[r, r] += av * cd[r]
        for j in range(sw.shape[0]):
            if sw[j] != 0.0:
                _rank1(A, D[j], sw[j])
        if lu:
            return _lu_into(A, piv)
        if _chol(A):
            piv[0] = -1
            return True
    return False


@_JIT
def _core_solve(Kc, piv, x):
    """Solve the core's factors (``_core_factor``) for ``x`` in place."""
    if piv[0] < 0:
        _chol_solve(Kc[1], x)
    else:
        _lu_solve(Kc[1], piv, x)


@_JIT
def _nl_trial(
    sc, kq, kw, kd, cd, Cq, diag, D, DH, mass, mus, mud, rate, hth0, hk, hlaw, hpar, hst_c,
    hst_t, q0, lam0, ag1, pext1, N1, stuck, sig,
    q1, qd1, qdd1, w1, wd1, wdd1, lam1, s1, hM, hz, wn, wx, Ms_key, n_cfg, Kc, piv, om, cmeta,
    stats,
):
    """One implicit (sub)step with a fixed contact state and nonlinear hinges: a trapezoidal
    step, or a stage of the composite step after an event (``_kernel_stage.py``), given by
    its relations ``sc``, ``kq``, ``kw`` (as ``_contact._step_end``; ``av = sc[1]`` is 2/h
    on the trapezoidal rule).

    ``D`` = [P; Q] ((m + n_h), n), ``DH`` = D K̂⁻¹ for this step (``K̂ = K + av C + av² I``).
    Writes the end state, the hinges' trial states ``hst_t``, moments ``hM`` and corrections
    ``hz``. ``wn`` (4, n) and ``wx`` (12, m + n_h) are scratch. ``Ms_key``: the configuration
    mass of the stuck pallets (``_contact._cfg_update``), ``n_cfg`` its change count; ``Kc``
    (2, n, n), ``piv`` (n,), ``om`` (n_h,) and ``cmeta`` (3,) the Newton core's cache (zeros
    at the start of a run), kept across calls. ``stats`` counts the trial (0), its Newton
    iterations (1) and factorisations of the core (2).

    The Newton matrix is ``J = E + R_D D K̂⁻¹ Dᵀ Z`` (diagonal ``E``, ``R_D``, ``Z``: a stuck
    pallet's row holds ``β/m_j`` and ``av``; a sliding pallet's ``1`` and its friction's
    slope; a hinge's ``1``, ``1`` and column weight ``k_t − k_i``), so by Woodbury's identity
    each Newton step is one solve with the n × n core ``K̂ + Dᵀ Z E⁻¹ R_D D`` (the tangent
    effective stiffness with the stuck pallets' masses): O((m + n_h) n) a step while the core's
    factors hold (same step length, contact state and hinge branches), never a dense matrix
    of the pallets and hinges.

    Every hysteresis law is piecewise linear, so once an iterate lands on the same branch (same
    tangent and intercept of every hinge) as the linearisation it came from, it solves the
    step exactly (up to round-off): the iteration stops there. Otherwise (velocity-dependent
    friction while sliding) it stops when the Newton step is below 1e-12 of the unknowns.
    Returns STATUS_OK (0) or STATUS_NEWTON when the iteration did not converge.
    """
    n = kd.shape[0]
    m = mass.shape[0]
    nh = hk.shape[0]
    nx = m + nh
    c2 = sc[1]
    hb = sc[2]
    rhs, qhat, tmp, u = wn[0], wn[1], wn[2], wn[3]
    dfree, b, x, zp, R, g, y, Ei, Rd, sw = (wx[0], wx[1], wx[2], wx[3], wx[4], wx[5], wx[6],
                                             wx[7], wx[8], wx[9])
    kt_lin, c_lin = wx[10], wx[11]  # each hinge's branch (tangent, intercept) of the last solve
    _damp_mul(cd, Cq, diag, kq[1], rhs)
    for i in range(n):
        rhs[i] = pext1[i] - kd[i] * q0[i] - kq[0, i] - rhs[i]
    _modal_solve(kd, cd, Cq, diag, c2, rhs, qhat)
    for i in range(n):
        tmp[i] = c2 * qhat[i] + kq[1, i]
    # dfree: support velocities of the free prediction (then: free hinge rotations)
    _mv(D, tmp, dfree)
    for j in range(m):
        b[j] = kw[0, j] - dfree[j]
    for i in range(n):
        tmp[i] = q0[i] + qhat[i]
    _mv(D, tmp, dfree)
    for i in range(nh):
        dfree[m + i] += hth0[i]
    for j in range(m):
        x[j] = lam0[j]
        y[j] = lam0[j]
    for i in range(nh):
        y[m + i] = hz[i]
    _mtv(DH, y, u)  # linear prediction of the rotations with the committed corrections
    _mv(D, u, g)
    for i in range(nh):
        x[m + i] = dfree[m + i] - g[m + i]
    smooth = False  # some sliding slider has velocity-dependent friction
    for j in range(m):
        if not stuck[j] and rate[j] > 0.0:
            smooth = True
    status = STATUS_NEWTON
    done = False
    stats[0] += 1
    for it in range(_NEWTON_MAX):
        same = it > 0 and not smooth
        for i in range(nh):
            th = x[m + i]
            Mi, kt = _hyst_trial_at(hlaw[i], hpar, hst_c, i, th, hst_t)
            hM[i] = Mi
            hz[i] = Mi - hk[i] * th
            zp[i] = kt - hk[i]
            c = Mi - kt * th
            if same and (kt != kt_lin[i]
                         or abs(c - c_lin[i]) > 1e-12 * (abs(Mi) + abs(kt * th) + 1e-300)):
                same = False
            kt_lin[i] = kt
            c_lin[i] = c
        if done or same:
            status = 0
            break
        # residuals: g = D K̂⁻¹ Dᵀ [λ; z]
        for j in range(m):
            y[j] = x[j]
        for i in range(nh):
            y[m + i] = hz[i]
        _mtv(DH, y, u)
        _mv(D, u, g)
        fresh = False  # the core carries velocity-dependent slopes: factor it for this iterate
        for j in range(m):
            sj = b[j] + hb * x[j] / mass[j] + c2 * g[j]
            s1[j] = sj
            sw[j] = 0.0
            if stuck[j]:
                R[j] = sj
                Ei[j] = hb / mass[j]
                Rd[j] = c2
            else:
                mu, dmu = _mu_slide(mus[j], mud[j], rate[j], abs(sj))
                R[j] = x[j] + N1[j] * sig[j] * mu
                f = N1[j] * sig[j] * dmu * (1.0 if sj >= 0.0 else -1.0)
                Ei[j] = 1.0 + f * hb / mass[j]
                Rd[j] = f * c2
                if f != 0.0:
                    sw[j] = Rd[j] / Ei[j]
                    fresh = True
        for i in range(nh):
            R[m + i] = x[m + i] - dfree[m + i] + g[m + i]
            Ei[m + i] = 1.0
            Rd[m + i] = 1.0
        changed = _core_weights(D[m:], zp[:nh], om, Kc, cmeta)
        if fresh or changed or cmeta[0] != c2 or cmeta[2] != n_cfg:
            ok = _core_factor(kd, cd, Cq, diag, c2, Ms_key, Kc, sw[:m], D, piv)
            stats[2] += 1
            cmeta[0] = c2 if ok and not fresh else 0.0
            cmeta[2] = n_cfg
            if not ok:
                break
        # Newton step (Woodbury): t = −E⁻¹R; Δ = t − E⁻¹ R_D D core⁻¹ Dᵀ Z t
        for a in range(nx):
            y[a] = -R[a] / Ei[a]
        for a in range(m, nx):
            R[a] = y[a] * zp[a - m]  # R is free now: Z t
        for a in range(m):
            R[a] = y[a]
        _mtv(D, R, u)
        _core_solve(Kc, piv, u)
        stats[1] += 1
        _mv(D, u, g)
        step = 0.5 if it >= _NEWTON_DAMPED else 1.0
        conv = True
        for k in range(nx):
            d = step * (y[k] - Rd[k] / Ei[k] * g[k])
            scale = abs(x[k]) + (1e-300 if k >= m else mus[k] * N1[k] + 1e-300)
            if abs(d) > 1e-12 * scale and abs(d) > 1e-16:
                conv = False
            x[k] += d
        done = conv and it > 0  # evaluate the hinges at the final x, then stop
    # x is final and the hinges (hM, hz, hst_t) were evaluated at it
    for j in range(m):
        y[j] = x[j]
        lam1[j] = x[j]
    for i in range(nh):
        y[m + i] = hz[i]
    _step_end(sc, kq, kw, DH, y, qhat, q0, D[:m], mass, ag1, lam1, stuck,
              q1, qd1, qdd1, w1, wd1, wdd1, s1, tmp, g[:m])
    return status


@_JIT
def _hinge_commit(Q, hth0, hk, hlaw, hpar, hst_c, hst_t, q1, hM, hz, hM_t, hz_t, fresh):
    """Commit the hinges at the accepted end state ``q1``; returns the correction forces' work
    ``∫ z dθ`` over the sub-step (trapezoid, as Newmark's energy identity needs).

    ``fresh``: the accepted state is the last trial's, whose hinge states ``hst_t``, ``hM_t``,
    ``hz_t`` are current; otherwise (an event was located, the accepted state may be an earlier
    trial) they are recomputed at ``q1`` (the laws depend only on the committed state and θ).
    """
    if not fresh:
        _hinge_state(Q, hth0, hk, hlaw, hpar, hst_c, q1, hst_t, hM_t, hz_t)
    work = 0.0
    for i in range(hk.shape[0]):
        work += 0.5 * (hz[i] + hz_t[i]) * (hst_t[i, HYST_S_THETA] - hst_c[i, HYST_S_THETA])
        hM[i] = hM_t[i]
        hz[i] = hz_t[i]
        for c in range(hst_c.shape[1]):
            hst_c[i, c] = hst_t[i, c]
    return work
