"""Exact piecewise-analytic stick–slip solution of the paper's §II SDOF sliding block.

A mass rests on a rigid support whose acceleration is ``a_s(t) = -alpha g sin(omega t)``
(``omega = 2 pi f``); support and mass start from rest, stuck. Notation (SI):

- ``u(t)``: support displacement, ``x(t)``: absolute mass displacement, ``s = x - u``: sliding.
- friction ``F``: horizontal force of the support ON the mass [N].

Stick phases follow Eq. 1 (``x`` moves with ``u``) while ``|F| <= mu_s M g`` (Eq. 2 with the
static coefficient). Sliding phases have the constant friction ``-d mu_d M g`` of Eq. 3, ``d`` the
sign of the relative velocity. A sliding phase ends when the relative velocity vanishes (Eq. 4,
solved here in its general form ``s_dot(t) = 0`` by bracketing + Brent); the mass then sticks if
``alpha |sin omega t1| <= mu_s`` (Eq. 5 with ``mu_s``), otherwise it slides back (a reversal).

Between successive zeros of ``d s_ddot`` (known in closed form: ``sin omega t = d mu_d / alpha``)
the relative velocity is monotone, so every root is bracketed exactly, never by sampling.
See ``docs/theory/sdof_threshold.md``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import brentq

from seisrack.errors import InputError

__all__ = [
    "SdofPhase",
    "SdofSolution",
    "solve_sdof",
    "validate_sdof_inputs",
]

_XTOL = 1e-13  # absolute tolerance on the phase angle omega*t in Brent's method [rad]


@dataclass(frozen=True)
class SdofPhase:
    """One phase of constant contact state.

    ``direction`` is 0 when stuck, else the sign of the relative velocity while sliding.
    ``s0`` is the sliding displacement at ``t_start`` [m].
    """

    t_start: float
    t_end: float
    direction: int
    s0: float


@dataclass(frozen=True)
class SdofSolution:
    """Closed-form solution of the §II SDOF; evaluate it at any times with the methods.

    ``events``: list of ``(time_s, kind)`` with kind in {"slip", "stick", "reverse"}.
    ``phases``: consecutive :class:`SdofPhase` covering ``[0, duration]``.
    """

    alpha: float
    mu_static: float
    mu_dynamic: float
    frequency: float
    duration: float
    g: float
    mass: float
    events: list[tuple[float, str]] = field(default_factory=list)
    phases: list[SdofPhase] = field(default_factory=list)

    @property
    def omega(self) -> float:
        return 2.0 * math.pi * self.frequency

    # -- support motion (Eq. 1 with t0 = 0, from rest) -------------------------------------
    def support_displacement(self, t: np.ndarray | float) -> np.ndarray:
        """``u(t)`` [m]."""
        t = np.asarray(t, dtype=float)
        w, ag = self.omega, self.alpha * self.g
        return ag / w**2 * np.sin(w * t) - ag / w * t

    def support_velocity(self, t: np.ndarray | float) -> np.ndarray:
        """``u_dot(t)`` [m/s]."""
        t = np.asarray(t, dtype=float)
        w, ag = self.omega, self.alpha * self.g
        return ag / w * (np.cos(w * t) - 1.0)

    def support_acceleration(self, t: np.ndarray | float) -> np.ndarray:
        """``u_ddot(t) = -alpha g sin(omega t)`` [m/s²]."""
        t = np.asarray(t, dtype=float)
        return -self.alpha * self.g * np.sin(self.omega * t)

    # -- relative (sliding) motion ----------------------------------------------------------
    def _phase_index(self, t: np.ndarray) -> np.ndarray:
        starts = np.array([p.t_start for p in self.phases])
        return np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(starts) - 1)

    def _eval(self, t: np.ndarray | float, which: str) -> np.ndarray:
        t = np.asarray(t, dtype=float)
        idx = self._phase_index(t)
        t0 = np.array([p.t_start for p in self.phases])[idx]
        d = np.array([p.direction for p in self.phases], dtype=float)[idx]
        s0 = np.array([p.s0 for p in self.phases])[idx]
        w, ag, mg = self.omega, self.alpha * self.g, self.mu_dynamic * self.g
        tau = t - t0
        sliding = d != 0.0
        if which == "s":  # integral of the velocity below
            val = s0 + np.where(
                sliding,
                -d * mg * tau**2 / 2
                + ag / w * np.cos(w * t0) * tau
                - ag / w**2 * (np.sin(w * t) - np.sin(w * t0)),
                0.0,
            )
        elif which == "v":  # Eq. 3 minus Eq. 1: s_dot = -d mu_d g tau + ag/w (cos wt0 - cos wt)
            val = np.where(sliding, -d * mg * tau + ag / w * (np.cos(w * t0) - np.cos(w * t)), 0.0)
        else:  # friction force on the mass: M x_ddot (Eq. 1.a when stuck, Eq. 3.a when sliding)
            val = self.mass * np.where(sliding, -d * mg, -ag * np.sin(w * t))
        return val

    def sliding(self, t: np.ndarray | float) -> np.ndarray:
        """Relative displacement ``s = x - u`` [m]."""
        return self._eval(t, "s")

    def sliding_velocity(self, t: np.ndarray | float) -> np.ndarray:
        """Relative velocity ``s_dot`` [m/s]."""
        return self._eval(t, "v")

    def displacement(self, t: np.ndarray | float) -> np.ndarray:
        """Absolute mass displacement ``x`` [m]."""
        return self.support_displacement(t) + self.sliding(t)

    def velocity(self, t: np.ndarray | float) -> np.ndarray:
        """Absolute mass velocity ``x_dot`` [m/s]."""
        return self.support_velocity(t) + self.sliding_velocity(t)

    def friction(self, t: np.ndarray | float) -> np.ndarray:
        """Horizontal force of the support on the mass [N]."""
        return self._eval(t, "f")

    def is_stuck(self, t: np.ndarray | float) -> np.ndarray:
        """True where the mass is stuck."""
        t = np.asarray(t, dtype=float)
        d = np.array([p.direction for p in self.phases])[self._phase_index(t)]
        return d == 0

    @property
    def sliding_phases(self) -> int:
        """Number of sliding phases (a reversal starts a new one)."""
        return sum(1 for p in self.phases if p.direction != 0)


def validate_sdof_inputs(
    alpha: float, mu_static: float, mu_dynamic: float, frequency: float, duration: float, g: float
) -> None:
    """Raise :class:`InputError` naming the first bad field."""
    for name, val in (
        ("alpha", alpha),
        ("mu", mu_static),
        ("mu_dynamic", mu_dynamic),
        ("frequency", frequency),
        ("duration", duration),
        ("g", g),
    ):
        if not isinstance(val, int | float) or not math.isfinite(val):
            raise InputError(name, val, "a finite number")
    if alpha <= 0:
        raise InputError("alpha", alpha, "alpha > 0")
    if mu_static < 0:
        raise InputError("mu", mu_static, "mu >= 0")
    if mu_dynamic < 0:
        raise InputError("mu_dynamic", mu_dynamic, "mu_dynamic >= 0")
    if mu_dynamic > mu_static:
        raise InputError("mu_dynamic", mu_dynamic, f"mu_dynamic <= mu (static) = {mu_static}")
    if frequency <= 0:
        raise InputError("frequency", frequency, "frequency > 0")
    if duration <= 0:
        raise InputError("duration", duration, "duration > 0")
    if g <= 0:
        raise InputError("g", g, "g > 0")


def _next_slip_angle(theta1: float, r: float) -> tuple[float, int]:
    """First angle > theta1 where |sin| rises through r < 1 (asin r + k pi), with its direction."""
    a = math.asin(r)
    k = math.floor((theta1 - a) / math.pi) + 1
    theta = a + k * math.pi
    if theta <= theta1:  # guard against rounding in floor
        k += 1
        theta += math.pi
    return theta, (1 if k % 2 == 0 else -1)


def _end_of_sliding(theta0: float, d: int, rho_d: float, theta_max: float) -> float | None:
    """Angle at which the dimensionless relative velocity returns to zero, or None.

    ``h(th) = d * s_dot * omega/(alpha g) = -rho_d (th - theta0) + d (cos theta0 - cos th)``;
    ``h' = d sin th - rho_d`` vanishes where ``sin th = d rho_d`` so ``h`` is monotone between
    those angles; a root is bracketed by the first local minimum with ``h < 0``.
    """

    def h(th: float) -> float:
        return -rho_d * (th - theta0) + d * (math.cos(theta0) - math.cos(th))

    b = math.asin(d * rho_d)  # in [-pi/2, pi/2]
    # critical angles b + 2k pi and pi - b + 2k pi, visited in increasing order after theta0
    k = math.floor((theta0 - b) / (2.0 * math.pi)) - 1
    lo = theta0
    while True:
        for c in sorted((b + 2 * math.pi * k, math.pi - b + 2 * math.pi * k)):
            # a sliding phase that starts at sin(theta0) = mu_s/alpha = mu_d/alpha begins ON a
            # critical angle; skip it with a tolerance relative to theta (an absolute 1e-15 fails
            # once theta0 ~ 30 rad, ending the phase at its start: a spurious stick)
            if c <= theta0 + 1e-12 * max(1.0, abs(theta0)):
                continue
            if lo > theta_max + 2.0 * math.pi:
                return None
            if h(c) < 0.0:
                return brentq(h, lo, c, xtol=_XTOL, rtol=4 * np.finfo(float).eps, maxiter=200)
            lo = c
        k += 1


def solve_sdof(
    alpha: float,
    mu: float,
    frequency: float,
    duration: float,
    *,
    mu_dynamic: float | None = None,
    g: float = 9.81,
    mass: float = 1.0,
) -> SdofSolution:
    """Solve the §II SDOF exactly on ``[0, duration]``.

    Args:
        alpha: support acceleration amplitude in g (> 0).
        mu: static friction coefficient mu_s (slip onset, Eq. 2 and Eq. 5).
        frequency: support frequency f [Hz].
        duration: analysis length [s].
        mu_dynamic: sliding coefficient mu_d (Eq. 3); defaults to ``mu``.
        g: gravity [m/s²]; mass: block mass [kg] (only scales the friction force).
    """
    mu_d = mu if mu_dynamic is None else mu_dynamic
    validate_sdof_inputs(alpha, mu, mu_d, frequency, duration, g)
    if not (math.isfinite(mass) and mass > 0):
        raise InputError("mass", mass, "mass > 0")
    w = 2.0 * math.pi * frequency
    theta_end = w * duration
    rho_s, rho_d = mu / alpha, mu_d / alpha
    ag = alpha * g
    events: list[tuple[float, str]] = []
    phases: list[SdofPhase] = []

    def s_slide(theta0: float, d: int, s0: float, th: float) -> float:
        tau = (th - theta0) / w
        return (
            s0
            - d * mu_d * g * tau**2 / 2
            + ag / w * math.cos(theta0) * tau
            - ag / w**2 * (math.sin(th) - math.sin(theta0))
        )

    if rho_s == 0.0 and rho_d == 0.0:
        # frictionless: the block never moves (x = 0) and slides for ever (direction is the
        # sign of s_dot = -u_dot >= 0)
        events.append((0.0, "slip"))
        phases.append(SdofPhase(0.0, duration, 1, 0.0))
        return SdofSolution(alpha, mu, mu_d, frequency, duration, g, mass, events, phases)

    theta, s, state = 0.0, 0.0, 0  # angle, sliding, 0 = stuck / ±1 = sliding direction
    while theta < theta_end:
        if state == 0:
            if rho_s >= 1.0:  # Eq. 2 can never be violated
                phases.append(SdofPhase(theta / w, duration, 0, s))
                break
            th_slip, d = _next_slip_angle(theta, rho_s)
            if th_slip >= theta_end:
                phases.append(SdofPhase(theta / w, duration, 0, s))
                break
            phases.append(SdofPhase(theta / w, th_slip / w, 0, s))
            events.append((th_slip / w, "slip"))
            theta, state = th_slip, d
        else:
            th1 = _end_of_sliding(theta, state, rho_d, theta_end)
            if th1 is None or th1 >= theta_end:
                phases.append(SdofPhase(theta / w, duration, state, s))
                break
            phases.append(SdofPhase(theta / w, th1 / w, state, s))
            s = s_slide(theta, state, s, th1)
            sin1 = math.sin(th1)
            if abs(sin1) <= rho_s:  # Eq. 5 with mu_s: the static bound can hold the block
                events.append((th1 / w, "stick"))
                theta, state = th1, 0
            else:  # the required force exceeds mu_s M g: slide back (sign of sin, see Eq. 2)
                events.append((th1 / w, "reverse"))
                theta, state = th1, (1 if sin1 > 0 else -1)
    return SdofSolution(alpha, mu, mu_d, frequency, duration, g, mass, events, phases)
