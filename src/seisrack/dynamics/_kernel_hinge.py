"""Newmark trial step with nonlinear hinges and velocity-dependent friction (issue #12).

Same source for the numba build and the pure-Python twin (see ``_kernel_numba.py``). Called by
``run_kernel`` (``_kernel.py``) in place of its linear ``_trial`` when the structure has
hinges with a hysteresis law or a slider has velocity-dependent friction; the event core
(``_events.py``) and the driver are unchanged, so stick/slip events are located inside the step
exactly as on the linear path. See ``docs/theory/nonlinear_hinges.md``.

Formulation, in the structure's mass-orthonormal coordinates ``q`` (``u = Φ q``):

* hinge ``i`` is a rotational spring between two DOFs (or a DOF and the ground) whose relative
  rotation is ``θ_i = θ0_i + Q_i q`` (``Q = Bᵀ Φ``; ``θ0`` its rotation in the static state
  the motion starts from, e.g. under gravity, since ``q`` is measured from that state). Its
  elastic stiffness ``k_i`` stays in the modal stiffness ``kd``; the law's moment ``M_i(θ_i)``
  enters as the correction ``z_i = M_i − k_i θ_i`` (zero while the hinge is elastic), applied
  as the generalized force ``Qᵀ z``;
* end-of-step equilibrium of average-acceleration Newmark (β = 1/4, γ = 1/2):
  ``K̂ Δq = r − Pᵀ λ₁ − Qᵀ z(θ₁)`` with ``K̂ = K + (2/h) C + (4/h²) I``;
* unknowns ``x = [λ (m sliders), θ (n_h hinges)]``, residuals
  stuck ``j``: relative velocity ``s_j(x) = 0``; sliding ``j``: ``λ_j + N_j σ_j μ_j(|s_j|) = 0``;
  hinge ``i``: ``θ_i − θ0_i − Q_i (q₀ + Δq(x)) = 0``; solved by Newton with the laws' consistent
  tangents (``D = [P; Q]``, ``GG = D K̂⁻¹ Dᵀ``: every block the Jacobian needs);
* velocity-dependent friction while sliding: ``μ(v) = μ_d + (μ_s − μ_d) e^(−a v)``, equal to
  μ_s at v = 0 (continuous with the static threshold) and to Coulomb's μ_d as ``a → ∞``.
"""

# ruff: noqa: N803, N806  (matrix names follow the equations)

import numpy as np

try:  # names injected by the loader when executed after ``_hysteresis.py`` and ``_linalg.py``
    _hyst_trial_at  # type: ignore[used-before-def]  # noqa: B018
except NameError:  # pragma: no cover - plain import of this file (pure-Python twin)
    from seisrack.dynamics._contact import _newmark_end
    from seisrack.dynamics._events import _JIT
    from seisrack.dynamics._hysteresis import HYST_S_THETA, _hyst_trial_at
    from seisrack.dynamics._linalg import _damp_mul, _modal_solve, _mv, _solve_into

STATUS_NEWTON = 4
_NEWTON_MAX = 60
_NEWTON_DAMPED = 20  # after this many iterations the steps are halved (breaks branch cycling)


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
def _nl_trial(
    h, kd, cd, Cq, diag, D, HDt, GG, mass, mus, mud, rate, hth0, hk, hlaw, hpar, hst_c, hst_t,
    q0, qd0, qdd0, w0, wd0, wdd0, lam0, ag1, pext1, N1, stuck, sig,
    q1, qd1, qdd1, w1, wd1, wdd1, lam1, s1, hM, hz, wn, wx, J,
):
    """One Newmark step of length ``h`` with a fixed contact state and nonlinear hinges.

    ``D`` = [P; Q] ((m + n_h), n), ``HDt`` = K̂⁻¹ Dᵀ, ``GG`` = D K̂⁻¹ Dᵀ for this ``h``; Writes
    the end state, the hinges' trial states ``hst_t``, moments ``hM`` and corrections ``hz``.
    ``wn`` (3, n), ``wx`` (9, m + n_h) and ``J`` (m + n_h, m + n_h) are scratch.

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
    c1 = 4.0 / h
    c2 = 2.0 / h
    rhs, qhat, tmp = wn[0], wn[1], wn[2]
    dfree, b, x, zp, R, ds, y = wx[0], wx[1], wx[2], wx[3], wx[4], wx[5], wx[6]
    kt_lin, c_lin = wx[7], wx[8]  # each hinge's branch (tangent, intercept) of the last solve
    R2 = R.reshape((nx, 1))
    _damp_mul(cd, Cq, diag, qd0, rhs)
    for i in range(n):
        rhs[i] += pext1[i] - kd[i] * q0[i] + c1 * qd0[i] + qdd0[i]
    _modal_solve(kd, cd, Cq, diag, h, rhs, qhat)
    for i in range(n):
        tmp[i] = c2 * qhat[i] - qd0[i]
    # dfree: support velocities of the free prediction (then: free hinge rotations)
    _mv(D, tmp, dfree)
    for j in range(m):
        b[j] = wd0[j] + 0.5 * h * (wdd0[j] - ag1) - dfree[j]
    for i in range(n):
        tmp[i] = q0[i] + qhat[i]
    _mv(D, tmp, dfree)
    for i in range(nh):
        dfree[m + i] += hth0[i]
    for j in range(m):
        x[j] = lam0[j]
    for i in range(nh):  # linear prediction with the committed corrections
        acc = dfree[m + i]
        for j in range(m):
            acc -= GG[m + i, j] * lam0[j]
        for k in range(nh):
            acc -= GG[m + i, m + k] * hz[k]
        x[m + i] = acc
    smooth = False  # some sliding slider has velocity-dependent friction
    for j in range(m):
        if not stuck[j] and rate[j] > 0.0:
            smooth = True
    status = STATUS_NEWTON
    done = False
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
        for j in range(m):
            sj = b[j] + 0.5 * h * x[j] / mass[j]
            for k in range(m):
                sj += c2 * GG[j, k] * x[k]
            for k in range(nh):
                sj += c2 * GG[j, m + k] * hz[k]
            s1[j] = sj
            # ds_j / dx
            for k in range(m):
                ds[k] = c2 * GG[j, k]
            ds[j] += 0.5 * h / mass[j]
            for k in range(nh):
                ds[m + k] = c2 * GG[j, m + k] * zp[k]
            if stuck[j]:
                R[j] = sj
                for k in range(nx):
                    J[j, k] = ds[k]
            else:
                mu, dmu = _mu_slide(mus[j], mud[j], rate[j], abs(sj))
                R[j] = x[j] + N1[j] * sig[j] * mu
                f = N1[j] * sig[j] * dmu * (1.0 if sj >= 0.0 else -1.0)
                for k in range(nx):
                    J[j, k] = f * ds[k]
                J[j, j] += 1.0
        for i in range(nh):
            r = x[m + i] - dfree[m + i]
            for k in range(m):
                r += GG[m + i, k] * x[k]
                J[m + i, k] = GG[m + i, k]
            for k in range(nh):
                r += GG[m + i, m + k] * hz[k]
                J[m + i, m + k] = GG[m + i, m + k] * zp[k]
            J[m + i, m + i] += 1.0
            R[m + i] = r
        _solve_into(J, R2)  # R becomes the Newton step (negated)
        step = 0.5 if it >= _NEWTON_DAMPED else 1.0
        conv = True
        for k in range(nx):
            d = -step * R[k]
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
    _newmark_end(h, HDt, y, qhat, q0, qd0, qdd0, D[:m], mass, ag1, lam1, w0, wd0, wdd0, stuck,
                 q1, qd1, qdd1, w1, wd1, wdd1, s1, tmp, ds)
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
