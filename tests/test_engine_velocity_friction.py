"""Velocity-dependent friction (issue #12): mu(v) = mu_d + (mu_s - mu_d) exp(-a |v|).

The law is OpenSees' VelDependent friction model (Constantinou et al. 1990, "Teflon bearings
in base isolation II: modeling", J. Struct. Eng. 116(2): mu = mu_fast - (mu_fast - mu_slow)
exp(-a |v|)) with mu_slow = mu_s and mu_fast = mu_d, plus a static threshold mu_s for sticking.

References:
- a block on a platform moving with the ground (the paper's §II set-up) solved independently
  here by event-driven integration (scipy ``solve_ivp``, DOP853, rtol 1e-12): while sliding
  ``s'' = -a_g - sign(s') mu(|s'|) g``; a slide ends when ``s'`` reaches 0, and the block sticks
  there when ``|a_g| <= mu_s g``, else slides on the other way. The engine's peak and final
  sliding must converge to it at order 2 (fitted over six steps);
- the Coulomb limit: as the rate a grows, the sliding tends to the Coulomb (mu_s, mu_d) run;
- a slider with mu_s = mu_d ignores the rate.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from seisrack.dynamics import Sliders, simulate
from seisrack.errors import InputError

G = 9.81
MU_S, MU_D, RATE = 0.35, 0.2, 8.0
A_G, W_G, T_END = 5.0, 2 * np.pi * 1.3, 4.0


def _ag(t):
    return A_G * np.sin(W_G * t) + 0.4 * A_G * np.sin(2.7 * W_G * t + 0.3)


def _mu(v, rate=RATE):
    return MU_D + (MU_S - MU_D) * np.exp(-rate * abs(v))


def _reference(rate=RATE):
    """Event-driven block: returns (t0, t1, dense sol or None for stick, stuck offset)."""
    t0, s0, phases = 0.0, 0.0, []
    # stuck until |a_g| first exceeds mu_s g
    tt = np.linspace(0.0, T_END, 400001)
    while t0 < T_END - 1e-12:
        over = np.flatnonzero((np.abs(_ag(tt)) > MU_S * G) & (tt > t0))
        if over.size == 0:
            phases.append((t0, T_END, None, s0))
            break
        k = over[0]
        t_slip = t0 if k == 0 or tt[k - 1] < t0 else float(
            __import__("scipy.optimize", fromlist=["brentq"]).brentq(
                lambda t: abs(_ag(t)) - MU_S * G, tt[k - 1], tt[k], xtol=1e-15))
        if t_slip > t0:
            phases.append((t0, t_slip, None, s0))
        sgn = -np.sign(_ag(t_slip))  # slides opposite to the ground acceleration
        y0 = [s0, 0.0]
        t0 = t_slip
        while True:
            def rhs(t, y, sgn=sgn):
                return [y[1], -_ag(t) - sgn * _mu(y[1], rate) * G]

            def stop(t, y):
                return y[1]

            stop.terminal = True
            stop.direction = -sgn
            # leave v = 0 first (the slip starts there)
            sol = solve_ivp(rhs, (t0, T_END), y0, events=[stop], rtol=1e-12, atol=1e-15,
                            dense_output=True, method="DOP853", first_step=1e-9)
            phases.append((t0, sol.t[-1], sol.sol, None))
            t0 = sol.t[-1]
            s0 = sol.y[0, -1]
            if sol.status != 1:
                return phases
            if abs(_ag(t0)) <= MU_S * G:
                break  # sticks
            sgn = -np.sign(_ag(t0))
            y0 = [s0, 0.0]
    return phases


def _sliding_at(phases, t):
    s = np.empty_like(t)
    for a, b, sol, stuck_at in phases:
        sel = (t >= a) & (t <= b)
        s[sel] = stuck_at if sol is None else sol(t[sel])[0]
    return s


def _run(dt, rate=RATE, mu_d=MU_D):
    t = np.arange(int(round(T_END / dt)) + 1) * dt
    sl = Sliders([-1], [10.0], MU_S, mu_d, friction_rate=rate)
    r = simulate(np.eye(1), np.zeros((1, 1)), np.eye(1), sl, dt=dt, ground_accel=_ag(t), g=G)
    return t, r


def test_block_converges_to_the_event_driven_reference():
    ref = _reference()
    assert sum(p[2] is not None for p in ref) >= 4  # several slides, both ways
    dts = [0.004 * 2.0**-k for k in range(6)]
    errs = []
    for dt in dts:
        t, r = _run(dt)
        assert r.status == "ok" and r.method == "newmark"
        s = r.sliding[:, 0]
        errs.append(float(np.max(np.abs(s - _sliding_at(ref, t)))))
        assert r.energy_error() < 1e-9
    order = np.polyfit(np.log(dts), np.log(errs), 1)[0]
    assert 1.8 < order < 2.6, (order, errs)
    peak = np.max(np.abs(_sliding_at(ref, np.linspace(0, T_END, 20001))))
    assert errs[-1] < 1e-5 * peak


def test_friction_force_follows_the_law_while_sliding():
    _, r = _run(0.001)
    v = r.sliding_velocity[:, 0]
    sliding = ~r.stuck[:, 0] & (np.abs(v) > 1e-6)
    lam = r.friction[sliding, 0]
    expected = -np.sign(v[sliding]) * _mu(v[sliding]) * 10.0 * G
    np.testing.assert_allclose(lam, expected, rtol=1e-9)
    # stuck: within the static bound
    assert np.all(np.abs(r.friction[r.stuck[:, 0], 0]) <= MU_S * 10.0 * G * (1 + 1e-9))


def test_coulomb_limit_and_equal_coefficients():
    dt = 1e-4  # resolves the weakening of the steepest law: dt g a (mu_s - mu_d) / 2 < 1
    _, coul = _run(dt, rate=0.0)
    diffs = []
    for rate in (1e2, 1e3, 1e4):
        _, r = _run(dt, rate=rate)
        diffs.append(np.max(np.abs(r.sliding - coul.sliding)))
    # the difference falls about as 1/a (the time spent above mu_d after each slip onset)
    assert diffs[0] > 4 * diffs[1] > 16 * diffs[2]
    assert diffs[2] < 5e-3 * np.max(np.abs(coul.sliding))
    _, same = _run(0.001, rate=50.0, mu_d=MU_S)
    _, plain = _run(0.001, rate=0.0, mu_d=MU_S)
    assert same.method == plain.method
    np.testing.assert_array_equal(same.sliding, plain.sliding)


def test_negative_rate_is_refused():
    with pytest.raises(InputError, match="friction_rate"):
        Sliders([0], [1.0], 0.3, 0.2, friction_rate=-1.0)


def test_rate_too_steep_for_the_step_is_refused():
    # dt g a (mu_s - mu_d) / 2 = 7.4: the discrete slide would not be unique
    with pytest.raises(InputError, match=r"friction_rate\[0\].*rate < 1359 s/m"):
        _run(0.001, rate=1e4)


def test_rack_names_the_pallet_whose_rate_is_too_steep():
    from pathlib import Path

    from seisrack.analysis import run_rack
    from seisrack.model import compile_rack, load_rack
    from seisrack.motion.records import load_builtin_record

    text = (Path(__file__).resolve().parents[1] / "examples" / "paper_rack.toml").read_text()
    text = text.replace("mu_dynamic = 0.6", "mu_dynamic = 0.45\nfriction_rate = 1e4")
    path = Path(__file__).resolve().parent / "_tmp_vel_rack.toml"
    try:
        path.write_text(text)
        model = compile_rack(load_rack(path))
    finally:
        path.unlink()
    assert np.all(model.pallet_friction_rate == 1e4)
    with pytest.raises(InputError, match=r"friction_rate of pallet [1-4] \(level 1\).*rate <"):
        run_rack(model, load_builtin_record("elcentro_1940_ns"), dt=0.005)
