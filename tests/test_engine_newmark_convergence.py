"""Second-order convergence of the engine's Newmark scheme on a linear MDOF (no sliding).

Source: Newmark (1959), average-acceleration rule (beta = 1/4, gamma = 1/2), second order
(Chopra, *Dynamics of Structures*, §5.4–5.5). The exact reference is the classical modal
solution (Chopra §12–13): with classical damping C = a0 M + a1 K, each mode of
(M, K) is a damped SDOF q'' + 2 xi w q' + w² q = p sin(W t) from rest, whose solution is the
steady-state harmonic plus the free decay that cancels it at t = 0.

Sliders with mu = 1e6 never slip, so they act as masses rigidly attached to their DOFs (the
exact solution uses M + their masses); the damping is then NOT diagonal in the engine's modal
basis (built from the structural M only), which exercises the dense-damping path. A second case
without sliders exercises the diagonal path. The order is measured by a log–log regression.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg

from seisrack.dynamics import Sliders, simulate

DTS = (0.008, 0.004, 0.002, 0.001)
DURATION = 2.0
W_LOAD = 2 * np.pi * 2.5  # rad/s
A_G = 2.0  # m/s², ground acceleration amplitude
F0 = 3000.0  # N on DOF 0

M = np.diag([200.0, 150.0, 100.0])
K = 1e5 * np.array([[2.0, -1.0, 0.0], [-1.0, 2.0, -1.0], [0.0, -1.0, 1.0]])
SLIDER_DOF = [0, 2]
SLIDER_MASS = [300.0, 250.0]


def _exact(M_tot, K, a0, a1, b, t):
    """u(t) of M_tot u'' + (a0 M_tot + a1 K) u' + K u = b sin(W t), from rest."""
    w2, phi = scipy.linalg.eigh(K, M_tot)
    w = np.sqrt(w2)
    xi = (a0 + a1 * w2) / (2 * w)
    p = phi.T @ b
    Z = p / (w2 - W_LOAD**2 + 2j * xi * w * W_LOAD)
    wd = w * np.sqrt(1 - xi**2)
    A = -Z.imag
    B = (-W_LOAD * Z.real + xi * w * A) / wd
    tt = t[:, None]
    q = (Z[None, :] * np.exp(1j * W_LOAD * tt)).imag + np.exp(-xi * w * tt) * (
        A * np.cos(wd * tt) + B * np.sin(wd * tt)
    )
    return q @ phi.T


@pytest.mark.parametrize("with_sliders", [True, False], ids=["stuck-sliders", "bare"])
def test_newmark_second_order(with_sliders):
    M_tot = M.copy()
    if with_sliders:
        for d, m in zip(SLIDER_DOF, SLIDER_MASS, strict=True):
            M_tot[d, d] += m
        sl = Sliders(dof=SLIDER_DOF, mass=SLIDER_MASS, mu_static=1e6)
    else:
        sl = Sliders(dof=[], mass=[], mu_static=[])
    a0, a1 = 0.4, 1e-3
    C = a0 * M_tot + a1 * K
    r = np.ones(3)
    b = -M_tot @ r * A_G  # stuck sliders feel the ground acceleration too
    b[0] += F0
    errors = []
    for dt in DTS:
        n = int(round(DURATION / dt))
        t = np.arange(n + 1) * dt
        force = np.zeros((n + 1, 3))
        force[:, 0] = F0 * np.sin(W_LOAD * t)
        res = simulate(M, C, K, sl, dt=dt, ground_accel=A_G * np.sin(W_LOAD * t), influence=r,
                       force=force, backend="numba")
        assert res.status == "ok" and res.events == []
        u_ex = _exact(M_tot, K, a0, a1, b, t)
        errors.append(float(np.max(np.abs(res.u - u_ex)) / np.max(np.abs(u_ex))))
        if with_sliders:
            assert np.all(res.stuck)
            assert np.max(np.abs(res.sliding)) <= 1e-12 * np.max(np.abs(u_ex))
    order = np.polyfit(np.log(DTS), np.log(errors), 1)[0]
    assert 1.8 <= order <= 2.3, f"measured order {order:.3f}, errors {errors}"
    assert errors[-1] < 1e-3
