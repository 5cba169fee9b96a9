"""The first trial of an event location on a line (``seisrack.dynamics._events._first_trial``),
and the later trials of a slip onset in the plane (``_propose3`` with its third point).

Reference: closed-form roots. A sliding slider's stop function ``e = -sig s`` is, over a
sub-step with a linearly varying acceleration, a quadratic in the fraction θ of the step; the
first trial is the root of the quadratic through its value and slope at the start and its
value at the end, so on an exact quadratic it lands on the root itself (where the regula
falsi's straight line through the ends does not). A stuck slider's first trial is that
straight line (its force's slope at the start is not known). The earliest root of several
violated functions is taken, as ``solve_ivp`` does for several events.

A stuck pallet's onset function |λ| − μ_s N is smooth across its root, so its later trials use
inverse quadratic interpolation through the bracket's two ends and the replaced end (the
interpolation of Brent's method: R. P. Brent, Algorithms for Minimization without
Derivatives, 1973, ch. 4): exact when θ is a quadratic in the function's value, and of order
about 1.84 on a smooth function (the positive root of p³ = p² + p + 1), measured here.
"""

from __future__ import annotations

import numpy as np

from seisrack.dynamics._events import (
    _accept_values,
    _conv_limit,
    _first_trial,
    _iqi,
    _keep_old,
    _propose3,
)


def _call(stuck, sig, e_lo, e_hi, arel, hrem=0.005):
    m = len(stuck)
    tolF = np.full(m, 1e-14)
    return _first_trial(np.array(stuck), np.array(sig, dtype=float), np.array(e_lo, dtype=float),
                        np.array(e_hi, dtype=float), tolF, np.full(m, 0.3), np.full(m, 1000.0),
                        np.array(arel, dtype=float), hrem)


def test_sliding_stop_on_an_exact_quadratic_is_found_at_once():
    # s(θ) = v0 + a0 h θ + b θ²: v0 = 1 m/s, a0 h = -3 m/s, b = 1 m/s → e = -s(θ), root
    # θ* = (3 - √5) / 2; the straight line through e(0) = -1 and e(1) = 1 gives 0.5
    h = 0.005
    for sig in (1.0, -1.0):
        th = _call([False], [sig], [-1.0], [1.0], [sig * -3.0 / h], hrem=h)
        assert abs(th - (3.0 - np.sqrt(5.0)) / 2.0) < 1e-9


def test_stuck_slider_takes_the_straight_line():
    # aimed at the middle of a stuck slider's acceptance window (1e-10 mu_s N wide): 4e-9 later
    assert abs(_call([True], [1.0], [-3.0], [1.0], [123.0]) - 0.75) < 1e-8


def test_earliest_root_of_several_and_non_violated_ignored():
    h = 0.005
    th = _call([True, False, False], [1.0, 1.0, 1.0], [-1.0, -1.0, -5.0], [3.0, 1.0, -1.0],
               [0.0, -3.0 / h, -1.0 / h], hrem=h)
    assert abs(th - 0.25) < 1e-8  # the stuck one's 0.25 before the slider's 0.382
    # a slope that does not decelerate falls back on the straight line, kept inside (0, 1)
    assert abs(_call([False], [1.0], [-1.0], [1.0], [+2.0 / h], hrem=h) - 0.5) < 1e-9
    assert 0.0 < _call([False], [1.0], [0.0], [1.0], [0.0]) < 1e-5


def test_inverse_quadratic_is_exact_on_an_inverse_quadratic():
    # theta(f) = 0.3 + 0.5 f - 0.2 f²: its value at f = 0 is 0.3, from any three points
    fs = np.array([-0.4, 0.1, 0.9])
    th = 0.3 + 0.5 * fs - 0.2 * fs**2
    assert abs(_iqi(th[0], fs[0], th[1], fs[1], th[2], fs[2]) - 0.3) < 1e-14
    assert _iqi(0.1, 1.0, 0.2, 1.0, 0.3, 2.0) == -1.0  # two equal values: no interpolant


def _locate(stuck, f):
    """The planar kernel's location loop (``_kernel_planar.run_planar``) on one event function
    ``f(theta)``, the full trial at theta = 1 violating; returns the trial fractions."""
    mus, N1 = np.array([0.5]), np.array([1.0])
    tolF = np.array([1e-15])
    e_lo, e_hi = np.array([f(0.0)]), np.array([f(1.0)])
    e_old = np.empty(1)
    br = np.array([0.0, 1.0, 1.0, 1.0, 0.0, 0.0])
    st = np.array([stuck])
    z = np.zeros((1, 1))
    th_old = -1.0
    trials = []
    for _ in range(60):
        th = _propose3(br, st, e_lo, e_hi, e_old, th_old, tolF, mus, N1, 0.005, 0.005, 1e-6)
        if th < 0.0:
            break
        trials.append(th)
        e_try = np.array([f(th)])
        th_old = _keep_old(br, e_try, tolF, e_lo, e_hi, e_old)
        _accept_values(br, th, e_try, tolF, e_lo, e_hi, z, z, z.copy(), z.copy())
    assert 0.0 < e_hi[0] <= _conv_limit(True, mus[0], N1[0], tolF[0])
    return np.array(trials)


def test_slip_onset_converges_superlinearly():
    # a smooth onset, curved over the step (the regula falsi's line from the ends misses it by
    # a third of the step): |lam| - mu_s N = 0.5 (e^(3 theta) - 2) / 7; the location aims at
    # the middle of the acceptance window (tolF, conv_limit], whose root is this one's
    tol = 1e-15
    tgt = tol + 0.5 * (_conv_limit(True, 0.5, 1.0, tol) - tol)
    root = np.log(2.0 + 14.0 * tgt) / 3.0

    def f(th):
        return 0.5 * (np.exp(3.0 * th) - 2.0) / 7.0

    trials = _locate(True, f)
    err = np.abs(trials - root)
    assert len(trials) <= 7
    # the order p = log(e_k+1 / e_k) / log(e_k / e_k-1) of successive errors above round-off,
    # the median of the last three (1.80 measured; the same-side secant alone: 1.38, in 9
    # trials)
    e = err[err > 1e-13]
    orders = np.log(e[2:] / e[1:-1]) / np.log(e[1:-1] / e[:-2])
    assert np.median(orders[-3:]) >= 1.7, (err, orders)
