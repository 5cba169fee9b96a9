"""Exact §II SDOF solution (paper Eqs 1–5) against an independent numerical integration.

Source: the paper's §II: stick phase Eq. 1 with the bound Eq. 2, sliding Eq. 3, re-stick time
Eq. 4 (relative velocity zero), re-stick condition Eq. 5 (here with the static coefficient).
The check integrates the relative motion with SciPy's ``solve_ivp`` (DOP853, rtol 1e-13) and
its event location, sharing no code with ``seisrack.sdof.closed_form``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from seisrack.errors import InputError
from seisrack.sdof.closed_form import solve_sdof

G = 9.81


def _numerical_events(alpha: float, mu_s: float, mu_d: float, f: float, T: float):
    w = 2 * math.pi * f
    t, y, d = 0.0, np.zeros(2), 0
    events: list[tuple[float, str]] = []
    while t < T:
        if d == 0:
            def ev(tt, yy):
                return G * (mu_s - alpha * abs(math.sin(w * tt)))

            ev.terminal, ev.direction = True, -1
            sol = solve_ivp(lambda tt, yy: np.zeros(2), (t, T), y, events=ev, max_step=0.01 / f,
                            rtol=1e-13, atol=1e-15)
            if sol.status == 0:
                break
            t = float(sol.t_events[0][0])
            d = 1 if math.sin(w * t) > 0 else -1
            events.append((t, "slip"))
        else:
            def rhs(tt, yy, d=d):
                return [yy[1], G * (alpha * math.sin(w * tt) - d * mu_d)]

            def ev(tt, yy, d=d):
                return d * yy[1]

            ev.terminal, ev.direction = True, -1
            sol = solve_ivp(rhs, (t, T), y, method="DOP853", events=ev, rtol=1e-13, atol=1e-15,
                            max_step=0.01 / f, first_step=1e-3 / f)
            if sol.status == 0:
                break
            t = float(sol.t_events[0][0])
            y = np.array([sol.y_events[0][0][0], 0.0])
            if alpha * abs(math.sin(w * t)) <= mu_s:
                events.append((t, "stick"))
                d = 0
            else:
                events.append((t, "reverse"))
                d = -d
    return events


@pytest.mark.parametrize(
    ("alpha", "mu_s", "mu_d", "f"),
    [(0.5, 0.3, 0.3, 1.0), (0.5, 0.2, 0.2, 2.0), (1.0, 0.25, 0.25, 0.5), (0.4, 0.3, 0.18, 1.5),
     (0.8, 0.6, 0.6, 1.0)],
)
def test_event_times_match_independent_integration(alpha, mu_s, mu_d, f):
    T = 4.0 / f
    ref = _numerical_events(alpha, mu_s, mu_d, f, T)
    sol = solve_sdof(alpha, mu_s, f, T, mu_dynamic=mu_d)
    assert [k for _, k in sol.events] == [k for _, k in ref]
    assert len(ref) >= 4
    for (t1, _), (t2, _) in zip(sol.events, ref, strict=True):
        assert abs(t1 - t2) <= 1e-9 * t2


def test_first_slip_is_arcsin():  # Eq. 2: alpha sin(w t0) = mu
    sol = solve_sdof(0.5, 0.3, 1.0, 2.0)
    assert sol.events[0] == (pytest.approx(math.asin(0.6) / (2 * math.pi), rel=1e-15), "slip")


def test_eq4_root_for_first_sliding_phase():
    # Eq. 4 with theta measured so that its root is the re-stick angle: K - (mu/alpha) wt = cos wt
    alpha, mu, f = 1.0, 0.6, 1.0
    r = mu / alpha
    sol = solve_sdof(alpha, mu, f, 1.0)
    th0 = math.asin(r)
    th1 = 2 * math.pi * sol.events[1][0]
    # Eq. 4 in the paper's form, with K = r asin r + sqrt(1 - r²)
    K = r * math.asin(r) + math.sqrt(1 - r * r)
    assert K - r * th1 == pytest.approx(math.cos(th1), abs=1e-12)
    assert th1 > th0


def test_stuck_means_zero_relative_velocity_and_bound_respected():
    sol = solve_sdof(0.6, 0.4, 1.0, 5.0, mu_dynamic=0.3, mass=2.0)
    t = np.linspace(0, 5, 20001)
    stuck = sol.is_stuck(t)
    assert stuck.any() and (~stuck).any()
    assert np.all(sol.sliding_velocity(t)[stuck] == 0.0)
    assert np.all(np.abs(sol.friction(t)) <= 0.4 * 2.0 * G * (1 + 1e-12))
    # sliding friction is mu_d N opposing the relative velocity
    sl = ~stuck
    v = sol.sliding_velocity(t)[sl]
    F = sol.friction(t)[sl]
    assert np.allclose(np.abs(F), 0.3 * 2.0 * G)
    assert np.all(F * v <= 1e-12)


def test_displacement_continuous_and_consistent_with_velocity():
    sol = solve_sdof(0.5, 0.2, 1.0, 3.0)
    t = np.linspace(0, 3, 300001)
    x = sol.displacement(t)
    v = sol.velocity(t)
    dxdt = np.gradient(x, t)
    assert np.max(np.abs(dxdt - v)[1:-1]) < 5e-5  # kinks at events: O(h) in the difference
    for te, _ in sol.events:  # continuity of the sliding at each event
        assert sol.sliding(te - 1e-12) == pytest.approx(sol.sliding(te + 1e-12), abs=1e-10)


def test_no_sliding_when_mu_exceeds_alpha():
    sol = solve_sdof(0.3, 0.31, 1.0, 10.0)
    assert sol.events == [] and sol.sliding_phases == 0
    assert sol.sliding(7.3) == 0.0


@pytest.mark.parametrize(
    ("kw", "field"),
    [({"alpha": 0.0}, "alpha"), ({"alpha": float("nan")}, "alpha"), ({"mu": -0.1}, "mu"),
     ({"mu_dynamic": 0.4}, "mu_dynamic"), ({"duration": 0.0}, "duration"),
     ({"frequency": -1.0}, "frequency"), ({"frequency": float("inf")}, "frequency")],
)
def test_bad_input_names_field(kw, field):
    args = {"alpha": 0.5, "mu": 0.3, "frequency": 1.0, "duration": 1.0}
    args.update(kw)
    mu_d = args.pop("mu_dynamic", None)
    with pytest.raises(InputError) as exc:
        solve_sdof(args["alpha"], args["mu"], args["frequency"], args["duration"], mu_dynamic=mu_d)
    assert exc.value.field == field
