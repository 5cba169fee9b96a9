"""The line kernel's composite step after an event (``dynamics/_kernel_stage.py``: Bathe's
scheme, a trapezoidal step to t + γH, γ = 2 − √2, then the three-point backward difference)
on a single oscillator ``q̈ + 2ζω q̇ + ω² q = 0``, through the same pure-Python functions the
kernel runs.

References: the exact free vibration of the damped oscillator (closed form); the scheme's
published properties (K.J. Bathe and M.M.I. Baig, "On a composite implicit time integration
procedure for nonlinear dynamics", Computers & Structures 83 (2005) 2513-2524): second-order
accuracy, and a spectral radius that falls to zero as ωH grows (L-stability), where the
trapezoidal rule keeps a modulus of one. Measured here: orders 2.01, 2.01, 2.00 on the
oscillator (H from 1/15 to 1/123 of its period); a direction displaced off its equilibrium
keeps 4.5e-3 of its displacement after one step at ωH = 1e2 and 4.5e-7 at ωH = 1e4 (the
trapezoidal rule: −0.9992 and −1.0000), and its velocity stays 4.8 q₀/H, not growing with ω;
with the stage energy ``_algorithmic`` the balance closes to round-off.
"""

from __future__ import annotations

import numpy as np
import pytest

from seisrack.dynamics import _kernel_stage as ks
from seisrack.dynamics._hysteresis import HYST_NSTATE


class _Oscillator:
    """Arrays of a one-direction structure without pallets or hinges, as the kernel holds
    them, and its steps."""

    def __init__(self, omega: float, zeta: float) -> None:
        self.kd = np.array([omega * omega])
        self.cd = np.array([2.0 * zeta * omega])
        self.z0 = np.zeros(0)
        self.hst = np.zeros((0, HYST_NSTATE))
        self.D = np.zeros((0, 1))

    def _buffers(self):  # noqa: ANN202
        T1 = np.zeros((6, 1))  # noqa: N806
        S1 = np.zeros((10, 0))  # noqa: N806
        return T1, S1

    def _common(self):  # noqa: ANN202
        z = self.z0
        return dict(
            Cq=np.zeros((1, 1)), diag=True, mass=z, mus=z, mud=z, rate=z, hth0=z, hk=z,
            hlaw=np.zeros(0, dtype=np.int64), hpar=np.zeros((0, 8)),
            stuck=np.zeros(0, dtype=np.bool_), sig=z,
        )

    def composite(self, H: float, T0: np.ndarray) -> tuple[np.ndarray, np.ndarray]:  # noqa: N803
        c = self._common()
        T1, S1 = self._buffers()  # noqa: N806
        S0 = np.zeros((5, 0))  # noqa: N806
        stats = np.zeros(4, dtype=np.int64)
        st = ks._composite(
            H, self.kd, self.cd, c["Cq"], c["diag"], self.D, np.zeros((0, 1)), c["mass"],
            c["mus"], c["mud"], c["rate"], c["hth0"], c["hk"], c["hlaw"], c["hpar"],
            self.hst.copy(), self.hst.copy(), self.hst.copy(), T0, S0, T1, S1, 0.0,
            np.zeros(1), self.z0, 0.0, np.zeros(1), self.z0, c["stuck"], c["sig"], self.z0,
            self.z0.copy(), self.z0.copy(), self.z0.copy(), np.zeros((4, 1)),
            np.zeros((12, 0)), np.eye(1), 0.0, np.zeros((2, 1, 1)),
            np.zeros(1, dtype=np.int64), self.z0.copy(), np.zeros(3), stats, np.zeros(4),
            np.zeros((2, 1)), np.zeros((2, 0)))
        assert st == 0
        return T1, S1

    def trapezoid(self, h: float, T0: np.ndarray) -> np.ndarray:  # noqa: N803
        c = self._common()
        sc, kq, kw = np.zeros(4), np.zeros((2, 1)), np.zeros((2, 0))
        ks._trap_coefs(h, self.z0, T0[1], T0[2], self.z0, self.z0, 0.0, sc, kq, kw)
        DH = np.zeros((0, 1))  # noqa: N806
        T1 = np.zeros((3, 1))  # noqa: N806
        e = self.z0
        st = ks._nl_trial(
            sc, kq, kw, self.kd, self.cd, c["Cq"], c["diag"], self.D, DH, c["mass"], c["mus"],
            c["mud"], c["rate"], c["hth0"], c["hk"], c["hlaw"], c["hpar"], self.hst.copy(),
            self.hst.copy(), T0[0], e, 0.0, np.zeros(1), e, c["stuck"], c["sig"],
            T1[0], T1[1], T1[2], e.copy(), e.copy(), e.copy(), e.copy(), e.copy(), e.copy(),
            e.copy(), np.zeros((4, 1)), np.zeros((12, 0)), np.eye(1), 0.0,
            np.zeros((2, 1, 1)), np.zeros(1, dtype=np.int64), e.copy(), np.zeros(3),
            np.zeros(4, dtype=np.int64))
        assert st == 0
        return T1


def _start(osc: _Oscillator, q0: float, v0: float) -> np.ndarray:
    """State rows q, q̇, q̈ with the acceleration from equilibrium."""
    return np.array([[q0], [v0], [-osc.kd[0] * q0 - osc.cd[0] * v0]])


def _exact(omega: float, zeta: float, t: float) -> float:
    wd = omega * np.sqrt(1.0 - zeta * zeta)
    return float(np.exp(-zeta * omega * t) * (np.cos(wd * t) + zeta * omega / wd * np.sin(wd * t)))


def test_composite_step_is_second_order_on_the_damped_oscillator():
    omega, zeta, t_end = 2.0 * np.pi, 0.05, 1.3
    osc = _Oscillator(omega, zeta)
    errs = []
    for n in (20, 40, 80, 160):
        T = _start(osc, 1.0, 0.0)  # noqa: N806
        for _ in range(n):
            T1, _S1 = osc.composite(t_end / n, T)  # noqa: N806
            T = T1[:3].copy()  # noqa: N806
        errs.append(abs(T[0, 0] - _exact(omega, zeta, t_end)))
    orders = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.all(orders > 1.9), (errs, orders)


@pytest.mark.parametrize("omega_h", [1e2, 1e4])
def test_composite_step_damps_a_stiff_direction_where_the_trapezoid_keeps_it(omega_h):
    H = 0.005  # noqa: N806
    osc = _Oscillator(omega_h / H, 0.0)
    T = _start(osc, 1.0, 0.0)  # noqa: N806  (a direction displaced off its equilibrium)
    T1, _S1 = osc.composite(H, T)  # noqa: N806
    # Bathe & Baig: spectral radius -> 0 as omega H grows (about 5 / (omega H) here)
    assert abs(T1[0, 0]) < 6.0 / omega_h
    # no overshoot growing with omega: the velocity stays of the order of q0 / H
    assert abs(T1[1, 0]) < 6.0 / H
    T2, _S2 = osc.composite(H, T1[:3].copy())  # noqa: N806
    assert abs(T2[0, 0]) < (6.0 / omega_h) ** 2 + 1e-12
    # the trapezoidal rule keeps the residue: q alternates with modulus one
    Tt = osc.trapezoid(H, T)  # noqa: N806
    assert abs(abs(Tt[0, 0]) - 1.0) < 1e-3


def test_stage_energy_closes_the_balance_of_a_composite_step():
    """Free vibration: no input, so ΔKE + ΔSE + damping + the algorithmic term = 0."""
    omega, zeta, H = 30.0, 0.02, 0.02  # noqa: N806
    osc = _Oscillator(omega, zeta)
    T = _start(osc, 0.3, 1.5)  # noqa: N806
    z = np.zeros(0)
    total = 0.0
    e0 = 0.5 * T[1, 0] ** 2 + 0.5 * osc.kd[0] * T[0, 0] ** 2
    for _ in range(25):
        T1, _S1 = osc.composite(H, T)  # noqa: N806
        out = np.zeros(3)
        qd_a, qd_m, qd_b = T[1], T1[4], T1[1]
        ks._stage_energy(T[0], qd_a, T1[3], qd_m, z, z, z, z, np.zeros(1), np.zeros(1), 0.0,
                         0.0, np.zeros((0, 1)), z, osc.cd, np.zeros((1, 1)), True,
                         np.zeros(1), np.zeros(1), z, out)
        ks._stage_energy(T1[3], qd_m, T1[0], qd_b, z, z, z, z, np.zeros(1), np.zeros(1), 0.0,
                         0.0, np.zeros((0, 1)), z, osc.cd, np.zeros((1, 1)), True,
                         np.zeros(1), np.zeros(1), z, out)
        alg = ks._algorithmic(T1[3], T1[4], T1[5], T1[0], T1[1], T1[2], z, z, z, z, z, z, z)
        total += out[1] + alg
        T = T1[:3].copy()  # noqa: N806
    e1 = 0.5 * T[1, 0] ** 2 + 0.5 * osc.kd[0] * T[0, 0] ** 2
    assert abs(e1 - e0 + total) < 1e-12 * e0
    assert total > 0.0
