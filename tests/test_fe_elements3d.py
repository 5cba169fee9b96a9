"""3D beam-column element (:mod:`seisrack.fe.elements3d`) against closed forms.

References:
- static cantilever: tip deflection P L³ / (3 E I) in each principal plane, tip rotation
  P L² / (2 E I), twist T L / (G J), axial P L / (E A) (Timoshenko & Gere, *Mechanics of
  Materials*; exact for the cubic-Hermite element with any mesh);
- cantilever natural frequencies: Euler–Bernoulli ω_n = (β_n L)² √(E I / (ρ A L⁴)), β₁L =
  1.875104069, β₂L = 4.694091133 (Blevins, *Formulas for Natural Frequency and Mode Shape*,
  1979, Table 8-1); St Venant torsion ω_n = (2n − 1) π / (2 L) · √(G J / (ρ Ip)) (Blevins
  Table 8-19). The consistent-mass Hermite element converges as h⁴ in bending frequency, the
  linear torsion element as h² (Strang & Fix, *An Analysis of the Finite Element Method*, 1973,
  §6.3: eigenvalue error O(h^{2(p+1−m)}) for degree p, energy order m); the measured orders
  are regressed on log h.
- a member along an arbitrary direction, with any vecxz, gives the same frequencies
  (rotation invariance of Tᵀ k T).
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg

from seisrack.fe.elements3d import (
    beam_matrices_3d,
    local_axes,
    local_consistent_mass_3d,
    local_stiffness_3d,
    truss_matrices_3d,
)

E, NU, RHO = 210e9, 0.3, 7850.0
G = E / (2 * (1 + NU))
A, IY, IZ, J = 6e-4, 2.0e-7, 5.0e-7, 3.0e-9
LEN = 2.0


def _cantilever(n: int, direction=(1.0, 0.0, 0.0), vecxz=(0.0, 0.0, 1.0), Ip=None):
    d = np.asarray(direction, float)
    d = d / np.linalg.norm(d)
    X = np.linspace(0.0, LEN, n + 1)[:, None] * d
    one = np.ones(n)
    k, m = beam_matrices_3d(X[:-1], X[1:], np.asarray(vecxz, float), E=E * one, G=G * one,
                            A=A * one, Iy=IY * one, Iz=IZ * one, J=J * one, rho=RHO * one,
                            Ip=None if Ip is None else Ip * one)
    N = 6 * (n + 1)
    dofs = (6 * np.arange(n)[:, None] + np.arange(12)[None, :])
    K, M = np.zeros((N, N)), np.zeros((N, N))
    np.add.at(K, (dofs[:, :, None], dofs[:, None, :]), k)
    np.add.at(M, (dofs[:, :, None], dofs[:, None, :]), m)
    return K[6:, 6:], M[6:, 6:]  # node 0 clamped


def test_stiffness_symmetric_and_rigid_body_free():
    k = local_stiffness_3d(*(np.array([v]) for v in (E, G, A, IY, IZ, J, LEN)))[0]
    assert np.allclose(k, k.T)
    # rigid translation along each axis and a rigid rotation about z (v = θ x) carry no force
    for rb in np.eye(6)[:3]:
        assert np.allclose(k @ np.tile(rb, 2), 0.0, atol=1e-6)
    rot_z = np.zeros(12)
    rot_z[[5, 11]] = 1.0
    rot_z[7] = LEN
    rot_y = np.zeros(12)
    rot_y[[4, 10]] = 1.0
    rot_y[8] = -LEN  # θy = −dw/dx
    assert np.allclose(k @ rot_z, 0.0, atol=1e-3)
    assert np.allclose(k @ rot_y, 0.0, atol=1e-3)
    m = local_consistent_mass_3d(np.array([RHO]), np.array([A]), np.array([IY + IZ]),
                                 np.array([LEN]))[0]
    assert np.allclose(m, m.T)
    for d in range(3):  # a rigid translation carries the member's whole mass
        r = np.zeros(12)
        r[[d, d + 6]] = 1.0
        assert r @ m @ r == pytest.approx(RHO * A * LEN)


def test_cantilever_static_closed_forms():
    K, _ = _cantilever(3)
    P, T = 1000.0, 50.0
    tip = K.shape[0] - 6
    for dof, I_, rot in ((1, IZ, 5), (2, IY, 4)):
        f = np.zeros(K.shape[0])
        f[tip + dof] = P
        u = np.linalg.solve(K, f)
        assert u[tip + dof] == pytest.approx(P * LEN**3 / (3 * E * I_), rel=1e-10)
        sign = 1.0 if dof == 1 else -1.0
        assert u[tip + rot] == pytest.approx(sign * P * LEN**2 / (2 * E * I_), rel=1e-10)
    f = np.zeros(K.shape[0])
    f[tip + 3] = T
    f[tip + 0] = P
    u = np.linalg.solve(K, f)
    assert u[tip + 3] == pytest.approx(T * LEN / (G * J), rel=1e-10)
    assert u[tip + 0] == pytest.approx(P * LEN / (E * A), rel=1e-10)


def _bending_freqs(n: int, I_: float, **kw) -> np.ndarray:
    K, M = _cantilever(n, **kw)
    w = np.sqrt(scipy.linalg.eigh(K, M, eigvals_only=True))
    exact1 = 1.875104069**2 * np.sqrt(E * I_ / (RHO * A * LEN**4))
    return w[np.argmin(np.abs(w - exact1))]


def _order(hs, errs) -> float:
    return float(np.polyfit(np.log(hs), np.log(errs), 1)[0])


@pytest.mark.parametrize("I_", [IY, IZ])
def test_bending_frequency_convergence_order_4(I_):
    exact = 1.875104069**2 * np.sqrt(E * I_ / (RHO * A * LEN**4))
    ns = [2, 4, 8, 16]
    errs = [abs(_bending_freqs(n, I_) / exact - 1.0) for n in ns]
    assert errs[-1] < 1e-6
    order = _order([LEN / n for n in ns], errs)
    assert 3.7 < order < 4.3, order


def test_torsion_frequency_convergence_order_2():
    Ip = IY + IZ
    exact = np.pi / (2 * LEN) * np.sqrt(G * J / (RHO * Ip))
    ns = [4, 8, 16, 32]
    errs = []
    for n in ns:
        K, M = _cantilever(n)
        tw = np.arange(3, K.shape[0], 6)  # twist DOFs alone (uncoupled)
        w = np.sqrt(scipy.linalg.eigh(K[np.ix_(tw, tw)], M[np.ix_(tw, tw)],
                                      eigvals_only=True))
        errs.append(abs(w[0] / exact - 1.0))
    assert errs[-1] < 1e-3
    order = _order([LEN / n for n in ns], errs)
    assert 1.9 < order < 2.1, order


def test_rotated_member_same_frequencies():
    K0, M0 = _cantilever(6)
    w0 = np.sqrt(scipy.linalg.eigh(K0, M0, eigvals_only=True))
    K1, M1 = _cantilever(6, direction=(0.3, -1.2, 0.7), vecxz=(1.0, 0.4, -0.2))
    # vecxz rotated with the member: project a vector that keeps the same principal axes
    d = np.array([0.3, -1.2, 0.7]) / np.linalg.norm([0.3, -1.2, 0.7])
    lam = local_axes(np.zeros((1, 3)), d[None], np.array([1.0, 0.4, -0.2]))[0]
    K1, M1 = _cantilever(6, direction=d, vecxz=lam[2])
    w1 = np.sqrt(scipy.linalg.eigh(K1, M1, eigvals_only=True))
    assert np.allclose(w1, w0, rtol=1e-9)
    # vertical member, vecxz along global z (the rack's uprights)
    K2, M2 = _cantilever(6, direction=(0.0, 1.0, 0.0), vecxz=(0.0, 0.0, 1.0))
    w2 = np.sqrt(scipy.linalg.eigh(K2, M2, eigvals_only=True))
    assert np.allclose(w2, w0, rtol=1e-9)


def test_local_axes_opensees_convention():
    lam = local_axes(np.zeros((1, 3)), np.array([[0.0, 3.0, 0.0]]), np.array([0.0, 0.0, 1.0]))
    # column along Y with vecxz = Z: local y = Z × Y = −X, local z = x × y = Z
    assert np.allclose(lam[0], [[0, 1, 0], [-1, 0, 0], [0, 0, 1]])
    with pytest.raises(ValueError, match="parallel"):
        local_axes(np.zeros((1, 3)), np.array([[0.0, 0.0, 1.0]]), np.array([0.0, 0.0, 2.0]))


def test_truss_axial_and_mass():
    xi, xj = np.zeros((1, 3)), np.array([[1.0, 2.0, 2.0]])
    k, m = truss_matrices_3d(xi, xj, E=np.array([E]), A=np.array([A]), rho=np.array([RHO]))
    n = np.array([1.0, 2.0, 2.0]) / 3.0
    u = np.concatenate([np.zeros(3), 1e-3 * n])
    assert k[0] @ u == pytest.approx(np.concatenate([-n, n]) * E * A / 3.0 * 1e-3)
    assert np.allclose(k[0] @ np.concatenate([np.zeros(3), np.cross(n, [0, 0, 1])]), 0.0)
    assert m[0].sum() == pytest.approx(3 * RHO * A * 3.0)  # mass in each of 3 directions
