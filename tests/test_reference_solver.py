"""Event-driven reference solver (seisrack.dynamics.reference) against closed forms.

Sources: the paper's §II closed-form sliding block (Eqs 1–5), reproduced with the reference
solver's prescribed-support mode (slider on the ground, dof = -1); the textbook harmonic
response of a damped linear SDOF from rest (Chopra, Dynamics of Structures, §3.2) for example 3
with mu = 10, where the supported mass never slides; the paper's §III.B remark that example 2
with mu = 0.5 shows 4 sliding phases.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from seisrack.dynamics.reference import simulate_reference
from seisrack.errors import InputError
from seisrack.paper.examples import example2, example3, run_reference
from seisrack.sdof.closed_form import solve_sdof

G = 9.81


@pytest.mark.parametrize(("rho_s", "rho_d"), [(0.6, 0.6), (0.4, 0.4), (0.25, 0.25), (0.6, 0.45)])
def test_prescribed_support_matches_closed_form(rho_s, rho_d):
    alpha, f, T, m = 0.5, 1.0, 4.0, 3.0
    w = 2 * math.pi * f
    ref = simulate_reference(
        np.zeros((0, 0)), None, None, [-1], [m], rho_s * alpha, rho_d * alpha, duration=T,
        ground_accel=lambda t: -alpha * G * math.sin(w * t), save_dt=1e-3,
    )
    cf = solve_sdof(alpha, rho_s * alpha, f, T, mu_dynamic=rho_d * alpha, mass=m)
    assert [e.kind for e in ref.events] == [k for _, k in cf.events]
    for e, (t, _) in zip(ref.events, cf.events, strict=True):
        assert abs(e.time_s - t) <= 1e-9 * t
    assert np.max(np.abs(ref.sliding[:, 0] - cf.sliding(ref.t))) < 1e-9
    assert np.max(np.abs(ref.friction[:, 0] - cf.friction(ref.t))) < 1e-6 * m * G


def _linear_sdof_from_rest(m, c, k, A, W, t):
    """u(t) of m u'' + c u' + k u = -m A sin(W t), u(0) = u'(0) = 0 (Chopra §3.2)."""
    # particular solution X sin + Y cos
    a11, a12 = k - m * W**2, -c * W
    a21, a22 = c * W, k - m * W**2
    X, Y = np.linalg.solve([[a11, a12], [a21, a22]], [-m * A, 0.0])
    wn = math.sqrt(k / m)
    z = c / (2 * m * wn)
    wd = wn * math.sqrt(1 - z * z)
    B1 = -Y
    B2 = (-X * W + z * wn * B1) / wd
    e = np.exp(-z * wn * t)
    return X * np.sin(W * t) + Y * np.cos(W * t) + e * (B1 * np.cos(wd * t) + B2 * np.sin(wd * t))


def test_example3_mu10_is_the_linear_two_mass_response():
    ex = example3()
    ref = run_reference(ex, 10.0)
    assert ref.events == [] and ref.stuck.all()
    u = _linear_sdof_from_rest(1050.0, 250.0, 1.2e5, 0.3 * G, 2 * math.pi * 1.5, ref.t)
    assert np.max(np.abs(ref.u[:, 0] - u)) < 1e-9 * np.max(np.abs(u))
    assert np.max(np.abs(ref.sliding)) == 0.0
    # the friction is what holds M2: m2 (u'' + a_g)
    ag = 0.3 * G * np.sin(2 * math.pi * 1.5 * ref.t)
    assert np.allclose(ref.friction[:, 0], 1000.0 * (ref.a[:, 0] + ag), atol=1e-6)


def test_example2_mu05_has_four_sliding_phases():
    ref = run_reference(example2(), 0.5)
    assert ref.sliding_phases(0) == 4  # paper §III.B.2
    _check_physics(ref, np.array([0.5]), np.array([0.5]), np.array([500.0]), np.array([1]))


def test_example2_mu1_never_slides():
    ref = run_reference(example2(), 1.0)
    assert ref.events == [] and ref.stuck.all()


def _check_physics(ref, mu_s, mu_d, mass, dof):
    N = mass * G
    assert np.all(np.abs(ref.friction) <= mu_s * N * (1 + 1e-9) + 1e-9)
    # stuck => zero relative velocity; sliding => |F| = mu_d N opposing the relative velocity
    node_v = np.where(dof[None, :] >= 0, ref.v[:, np.maximum(dof, 0)], 0.0) if ref.v.size else 0.0
    rel_v = ref.slider_v - node_v
    assert np.all(np.abs(rel_v[ref.stuck]) <= 1e-9)
    sl = ~ref.stuck
    if sl.any():
        Fs = ref.friction[sl]
        assert np.allclose(np.abs(Fs), np.broadcast_to(mu_d * N, ref.stuck.shape)[sl])
        assert np.all(Fs * rel_v[sl] <= 1e-9)


@settings(max_examples=12, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow])
@given(
    n=st.integers(1, 3),
    m=st.integers(1, 2),
    seed=st.integers(0, 2**16),
    amp=st.floats(0.5, 8.0),
    freq=st.floats(0.5, 3.0),
)
def test_friction_bound_never_exceeded_random_structures(n, m, seed, amp, freq):
    rng = np.random.default_rng(seed)
    ms = rng.uniform(50, 500, n)
    ks = rng.uniform(2e4, 2e5, n)
    K = np.zeros((n, n))
    for i in range(n):  # a shear chain from the ground
        K[i, i] += ks[i]
        if i + 1 < n:
            K[i, i] += ks[i + 1]
            K[i, i + 1] = K[i + 1, i] = -ks[i + 1]
    M = np.diag(ms)
    C = 0.01 * K / math.sqrt(np.max(ks / ms))
    dof = rng.integers(0, n, m)
    mass = rng.uniform(50, 800, m)
    mu_s = rng.uniform(0.05, 0.6, m)
    mu_d = mu_s * rng.uniform(0.6, 1.0, m)
    w = 2 * math.pi * freq
    ref = simulate_reference(
        M, C, K, dof, mass, mu_s, mu_d, duration=1.5, save_dt=2e-3,
        ground_accel=lambda t: amp * math.sin(w * t), rtol=1e-9, atol=1e-12,
    )
    _check_physics(ref, mu_s, mu_d, mass, dof)


@pytest.mark.xfail(strict=True, reason="known limitation of the reference solver (found "
                   "2026-11-23 by a random example): slider 1's relative velocity grazes zero "
                   "(down at t = 0.4475 s, back up before 0.4535 s, dipping to -1.4e-3 m/s); "
                   "both crossings fall inside one DOP853 step (max_step 10 ms), so solve_ivp "
                   "sees no sign change and the slider slides on with the friction pushing it "
                   "for about 6 ms")
def test_friction_opposes_sliding_two_sliders_on_one_dof_known_bug():
    test_friction_bound_never_exceeded_random_structures.hypothesis.inner_test(
        n=1, m=2, seed=16364, amp=3.90625, freq=2.0234375)


def test_vertical_acceleration_changes_normal_force():
    av = 0.5 * G
    ref = simulate_reference(
        np.zeros((0, 0)), None, None, [-1], [1.0], 0.2, 0.2, duration=1.0,
        ground_accel=lambda t: 0.5 * G * math.sin(2 * math.pi * t), vertical_accel=lambda t: av,
    )
    sl = ~ref.stuck[:, 0]
    assert sl.any()
    assert np.allclose(np.abs(ref.friction[sl, 0]), 0.2 * (G + av))


@pytest.mark.parametrize(
    ("kw", "field"),
    [({"slider_dof": [5]}, "slider_dof"), ({"mu_static": -0.1}, "mu_static"),
     ({"mu_dynamic": 0.9}, "mu_dynamic"), ({"duration": 0.0}, "duration"),
     ({"slider_mass": [0.0]}, "slider_mass"), ({"K": np.ones((2, 2))}, "K")],
)
def test_bad_input(kw, field):
    args = dict(M=np.eye(1), C=None, K=np.eye(1), slider_dof=[0], slider_mass=[1.0],
                mu_static=0.5, mu_dynamic=0.5, duration=1.0)
    args.update(kw)
    with pytest.raises(InputError) as exc:
        simulate_reference(**args)
    assert exc.value.field == field
