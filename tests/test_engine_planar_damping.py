"""The planar scheme with damping that is not diagonal in its basis (non-classical: a full
reduced matrix Φᵀ C Φ), as a1 K_E is in the modes of K_E + K_G on a rack with P-Δ.

References:
- no sliding (pallets held by mu = 50): the exact solution of the linear state-space system
  x' = A x + B a(t) for the ground accelerations a(t) linear between the samples, as the
  engine takes them: one matrix exponential per step of the augmented system [x, a, ȧ]
  (Van Loan, "Computing integrals involving the matrix exponential", IEEE TAC 23 (1978);
  scipy.linalg.expm), with the pallets' masses added to their supports. Newmark's average
  acceleration is of order 2 (Chopra, *Dynamics of Structures*, §5.4): measured errors
  4.66e-3, 1.18e-3, 2.97e-4 of the peak displacement at dt 4, 2, 1 ms (a fitted order of 1.99;
  Newmark's period error over 3 s), the energy balance closed to 1e-10;
- sliding along one axis: the 1D engine's Newmark path (:func:`seisrack.dynamics.simulate`
  with :class:`~seisrack.dynamics.Sliders`), which carries a dense modal damping matrix of its
  own (``_kernel.py``): equal to 1e-8 of the peak sliding;
- sliding in the plane: the energy balance input = kinetic + strain + damping + friction
  (Newmark's trapezoidal work identity; the located events leave a residue: measured 3.9e-6 of
  the input with this damping, 2.5e-6 with C = 0, 34 and 50 events), well below the work of the
  off-diagonal damping (1.3e-3 of the input), which a damping term with the diagonal of Φᵀ C Φ
  only would miss; and the pure-Python twin equal to the numba build.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import eigh, expm

from seisrack.dynamics import PlanarSliders, Sliders, _run_line, simulate

MU_HELD = 50.0


def _frame():
    """Two storeys in x and z (4 DOFs: x1, x2, z1, z2), coupled in plan by a spring between
    x2 and z2; non-proportional damping: a dashpot on x1 and one between x2 and z2, with a
    little stiffness-proportional damping."""
    M = np.diag([800.0, 800.0, 600.0, 600.0])
    k1, k2 = 2.0e6, 1.5e6
    kx = np.array([[k1 + k2, -k2], [-k2, k2]])
    K = np.zeros((4, 4))
    K[np.ix_([0, 1], [0, 1])] = kx
    K[np.ix_([2, 3], [2, 3])] = 1.7 * kx
    kc = 0.4e6
    K[np.ix_([1, 3], [1, 3])] += kc * np.array([[1.0, -1.0], [-1.0, 1.0]])
    C = 2e-4 * K
    C[0, 0] += 4.0e3
    C[np.ix_([1, 3], [1, 3])] += 3.0e3 * np.array([[1.0, -1.0], [-1.0, 1.0]])
    return M, C, K


def _ground(t):
    ax = 4.0 * np.sin(2 * np.pi * 1.3 * t) * np.exp(-0.3 * t)
    az = 3.0 * np.sin(2 * np.pi * 2.1 * t + 0.7) * np.exp(-0.2 * t)
    return np.column_stack([ax, az])


INFL = np.array([[1, 0], [1, 0], [0, 1], [0, 1]], dtype=float)


def test_the_damping_is_not_classical():
    M, C, K = _frame()
    _, phi = eigh(K, M)
    cq = phi.T @ C @ phi
    off = np.abs(cq - np.diag(np.diag(cq))).max()
    assert off > 0.2 * np.abs(np.diag(cq)).max()


def _exact_held(M, C, K, dx, dz, mass, dt, ag):
    """Displacements (n_t, n) of the structure with the pallets' masses on their supports,
    exact for ``ag`` (n_t, 2) linear between samples (augmented matrix exponential)."""
    n = M.shape[0]
    Mt = M.copy()
    for d, m in zip(np.concatenate([dx, dz]), np.concatenate([mass, mass]), strict=True):
        Mt[d, d] += m
    Mi = np.linalg.inv(Mt)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Mi @ K, -Mi @ C]])
    B = np.vstack([np.zeros((n, 2)), -INFL])  # -Mi Mt r = -r: every mass feels the ground
    s = 2 * n
    aug = np.zeros((s + 4, s + 4))
    aug[:s, :s] = A
    aug[:s, s:s + 2] = B
    aug[s:s + 2, s + 2:] = np.eye(2)
    E = expm(dt * aug)
    Phi, G0, G1 = E[:s, :s], E[:s, s:s + 2], E[:s, s + 2:]
    x = np.zeros(s)
    out = np.empty((ag.shape[0], n))
    out[0] = x[:n]
    for k in range(ag.shape[0] - 1):
        x = Phi @ x + G0 @ ag[k] + G1 @ ((ag[k + 1] - ag[k]) / dt)
        out[k + 1] = x[:n]
    return out


def test_no_sliding_converges_to_the_exact_solution_at_order_two():
    M, C, K = _frame()
    dx, dz, mass = np.array([0, 1]), np.array([2, 3]), np.array([400.0, 500.0])
    sl = PlanarSliders(dx, dz, mass, MU_HELD, MU_HELD)
    T = 3.0
    errs, dts = [], [0.004, 0.002, 0.001]
    for dt in dts:
        t = np.arange(0.0, T + dt / 2, dt)
        ag = _ground(t)
        h = simulate(M, C, K, sl, dt=dt, ground_accel=ag, influence=INFL, basis="full")
        assert np.abs(h.sliding).max() < 1e-12
        u = h.q @ h.phi.T
        ref = _exact_held(M, C, K, dx, dz, mass, dt, ag)
        peak = np.abs(ref).max()
        errs.append(np.abs(u - ref).max() / peak)
        # the energy balance closes with the full damping matrix
        assert h.energy_error() < 1e-10
    order = np.polyfit(np.log(dts), np.log(errs), 1)[0]
    assert 1.9 < order < 2.1, (errs, order)
    assert errs[-1] < 5e-4, errs


def _decoupled_frame():
    """x and z apart (no plan coupling), a non-proportional dashpot in each plane."""
    M = np.diag([800.0, 800.0, 600.0, 600.0])
    k1, k2 = 2.0e6, 1.5e6
    kx = np.array([[k1 + k2, -k2], [-k2, k2]])
    K = np.zeros((4, 4))
    K[np.ix_([0, 1], [0, 1])] = kx
    K[np.ix_([2, 3], [2, 3])] = 1.7 * kx
    C = 1e-3 * K
    C[0, 0] += 5.0e3
    C[2, 2] += 5.0e3
    return M, C, K


def test_one_axis_equals_the_1d_engine_with_its_dense_damping(monkeypatch):
    # the planar step is the trapezoidal rule throughout; the line kernel takes composite steps
    # after events unless told not to: the same scheme on both sides
    monkeypatch.setattr(_run_line, "COMPOSITE_STEPS", 0)
    M, C, K = _decoupled_frame()
    dt = 0.005
    t = np.arange(0, 8 + dt / 2, dt)
    ag = 5.0 * np.sin(2 * np.pi * 1.1 * t) * np.exp(-0.2 * t)
    mass, mus, mud = [400.0, 300.0, 500.0], [0.3, 0.25, 0.2], [0.25, 0.25, 0.15]
    dofx, dofz = [0, 1, 1], [2, 3, 3]
    hp = simulate(M, C, K, PlanarSliders(dofx, dofz, mass, mus, mud), dt=dt,
                  ground_accel=np.column_stack([ag, 0 * ag]), influence=INFL, basis="full")
    h1 = simulate(M[:2, :2], C[:2, :2], K[:2, :2], Sliders(dofx, mass, mus, mud), dt=dt,
                  ground_accel=ag, method="newmark", basis="full")
    peak = np.abs(h1.sliding).max()
    assert peak > 0.01
    assert np.abs(hp.sliding[:, :, 0] - h1.sliding).max() < 1e-8 * peak
    assert [(e.slider, e.kind) for e in hp.events] == [(e.slider, e.kind) for e in h1.events]
    # without the off-diagonal damping (the diagonal of Φᵀ C Φ only) the answer differs
    _, phi = eigh(K, M)
    cq = phi.T @ C @ phi
    C_diag = M @ phi @ np.diag(np.diag(cq)) @ phi.T @ M
    hd = simulate(M, C_diag, K, PlanarSliders(dofx, dofz, mass, mus, mud), dt=dt,
                  ground_accel=np.column_stack([ag, 0 * ag]), influence=INFL, basis="full")
    assert np.abs(hd.sliding[:, :, 0] - h1.sliding).max() > 1e-3 * peak


@pytest.fixture(scope="module")
def sliding_plane():
    M, C, K = _frame()
    dt = 0.004
    t = np.arange(0, 5 + dt / 2, dt)
    sl = PlanarSliders([[0], [1], [1]], [[2], [3], [3]], [400.0, 300.0, 500.0],
                       [0.3, 0.25, 0.2], [0.25, 0.2, 0.15])
    kw = dict(dt=dt, ground_accel=_ground(t), influence=INFL, basis="full")
    return M, C, K, sl, kw


def test_sliding_in_the_plane_closes_the_energy_balance(sliding_plane):
    M, C, K, sl, kw = sliding_plane
    h = simulate(M, C, K, sl, **kw)
    e = h.energy
    assert e["friction"][-1] > 0.05 * np.max(e["input"])
    assert e["damping"][-1] > 0.005 * np.max(e["input"])
    assert np.all(np.diff(e["damping"]) >= -1e-12 * np.max(np.abs(e["input"])))
    assert len(h.events) > 10
    tol = 1e-5
    assert h.energy_error() < tol
    # the damping work of the diagonal alone misses the rest's: the balance would not close
    _, phi = eigh(K, M)
    cq = phi.T @ C @ phi
    off = cq - np.diag(np.diag(cq))
    v = 0.5 * (h.qd[1:] + h.qd[:-1])
    w_off = np.sum(np.einsum("ti,ij,tj->t", np.diff(h.q, axis=0), off, v))
    assert abs(w_off) > 50 * tol * np.max(e["input"])


def test_python_twin_equals_numba(sliding_plane):
    pytest.importorskip("numba")
    M, C, K, sl, kw = sliding_plane
    t_end = 2.0
    n = int(round(t_end / kw["dt"])) + 1
    kw = {**kw, "ground_accel": kw["ground_accel"][:n]}
    a = simulate(M, C, K, sl, backend="numba", **kw)
    b = simulate(M, C, K, sl, backend="python", **kw)
    assert len(a.events) >= 3
    assert np.allclose(a.sliding, b.sliding, rtol=0, atol=1e-12)
    assert np.allclose(a.energy["damping"], b.energy["damping"], rtol=1e-12, atol=0)
