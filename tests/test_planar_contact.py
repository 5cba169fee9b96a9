"""Friction of pallets released from zero relative velocity at an event (issue 11, planar engine;
theory: ``docs/theory/planar_friction.md`` §3).

The forces minimise ``lam·W lam / 2 + b·lam`` over the friction discs |lam_p| <= mu_d N_p
(maximum dissipation at the acceleration level). References, independent of the kernel's
block Gauss–Seidel and secular-equation solver:
- scipy's SLSQP on the same convex problem with the disc constraints written as inequalities
  (its point may sit ~1e-9 outside a disc, so it is compared to 1e-5);
- for one pallet on its circle, a one-dimensional minimisation over the angle (exact);
- the optimality conditions themselves: the relative acceleration ``a = W lam + b`` is opposite
  to ``lam`` on the circle, and zero inside the disc.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import minimize, minimize_scalar

from seisrack.dynamics._planar_contact import _disc_min, _released_forces


def _slsqp(W, b, f):
    n = len(f)
    cons = [{"type": "ineq", "fun": (lambda x, p=p: f[p] ** 2 - x[2 * p] ** 2 - x[2 * p + 1] ** 2),
             "jac": (lambda x, p=p: np.array([-2 * x[2 * p] * (k == 2 * p)
                                              - 2 * x[2 * p + 1] * (k == 2 * p + 1)
                                              for k in range(2 * n)]))}
            for p in range(n)]
    res = minimize(lambda x: 0.5 * x @ W @ x + b @ x, np.zeros(2 * n), jac=lambda x: W @ x + b,
                   constraints=cons, method="SLSQP", options={"ftol": 1e-14, "maxiter": 500})
    # SLSQP may stop at its precision limit ("positive directional derivative"); what is
    # compared is its point, checked feasible here
    assert res.success or res.status == 8
    x = res.x
    assert np.all(np.hypot(x[0::2], x[1::2]) <= f * (1 + 1e-8))
    return x


def _objective(W, b, x):
    return 0.5 * x @ W @ x + b @ x


def _spd(rng, n, cond=30.0):
    q, _ = np.linalg.qr(rng.standard_normal((n, n)))
    return q @ np.diag(np.geomspace(1.0, cond, n)) @ q.T


@pytest.mark.parametrize("seed", range(8))
def test_disc_problem_matches_slsqp(seed):
    rng = np.random.default_rng(seed)
    W = _spd(rng, 2, cond=1.0 + 20.0 * rng.random())
    c = rng.standard_normal(2) * 3.0
    for f in (0.2, 1.0, 50.0):  # on the circle, near its edge, inside
        l1, l2, inside = _disc_min(W[0, 0], W[0, 1], W[1, 1], c[0], c[1], f)
        ref = _slsqp(W, c, np.array([f]))
        assert np.allclose([l1, l2], ref, atol=1e-5 * max(f, 1.0))
        if not inside:
            # exact reference on the circle: a one-dimensional minimisation over the angle
            def on_circle(t, f=f):
                return _objective(W, c, f * np.array([np.cos(t), np.sin(t)]))

            ts = np.linspace(0.0, 2.0 * np.pi, 20001)
            t0 = ts[np.argmin([on_circle(t) for t in ts])]
            best = minimize_scalar(on_circle, bracket=(t0 - 1e-3, t0, t0 + 1e-3), tol=1e-14)
            assert np.allclose([l1, l2], f * np.array([np.cos(best.x), np.sin(best.x)]),
                               atol=1e-7 * f)
            assert _objective(W, c, np.array([l1, l2])) <= best.fun + 1e-14 * abs(best.fun)
        assert inside == (np.hypot(*np.linalg.solve(W, c)) <= f)
        if not inside:
            assert np.hypot(l1, l2) == pytest.approx(f, rel=1e-13)


def test_disc_problem_keeps_an_axis_aligned_problem_on_its_axis():
    l1, l2, inside = _disc_min(2.0, 0.0, 5.0, -3.0, 0.0, 1.0)
    assert not inside and l2 == 0.0 and l1 == 1.0


@pytest.mark.parametrize("seed", range(6))
def test_released_forces_solve_the_coupled_problem(seed):
    rng = np.random.default_rng(100 + seed)
    r, m = 7, 4
    P = rng.standard_normal((2 * m, r)) * 0.3
    S = _spd(rng, r, cond=5.0) * 0.5
    L = np.linalg.cholesky(np.eye(r) + S)
    mass = rng.uniform(0.5, 2.0, m)
    mud = np.full(m, 0.3)
    N = mass * 9.81
    ag = rng.standard_normal(2) * 4.0
    qdd0 = rng.standard_normal(r)
    rel = np.array([0, 2, 3], dtype=np.int64)
    rows = np.ravel([[2 * p, 2 * p + 1] for p in rel])
    Minv = np.linalg.inv(np.eye(r) + S)
    W = P[rows] @ Minv @ P[rows].T + np.diag(np.repeat(1.0 / mass[rel], 2))
    b = -np.tile(ag, len(rel)) - P[rows] @ qdd0
    f = mud[rel] * N[rel]
    ref = _slsqp(W, b, f)

    lam = np.zeros(2 * m)
    qdd = qdd0.copy()
    inside = np.zeros(len(rel), dtype=bool)
    _released_forces(L, P, mass, mud, N, ag, qdd, rel, lam, inside)
    got = lam[rows]
    assert np.allclose(got, ref, atol=1e-5 * f.max())
    # optimality: a = W lam + b opposite to lam on the circle, zero inside
    a = (W @ got + b).reshape(-1, 2)
    for k, p in enumerate(rel):
        lk = got[2 * k: 2 * k + 2]
        if inside[k]:
            assert np.linalg.norm(lk) <= f[k] * (1 + 1e-12)
            assert np.linalg.norm(a[k]) <= 1e-9 * np.abs(b).max()
        else:
            assert np.linalg.norm(lk) == pytest.approx(f[k], rel=1e-12)
            cross = a[k, 0] * lk[1] - a[k, 1] * lk[0]
            assert abs(cross) <= 1e-9 * np.linalg.norm(a[k]) * f[k]
            assert a[k] @ lk <= 0.0
        assert p in rel
    # the structure's accelerations carry the released pallets' friction
    assert np.allclose(qdd, qdd0 - Minv @ (P[rows].T @ got), atol=1e-12 * np.abs(qdd0).max())
