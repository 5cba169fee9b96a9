"""The first trial of an event location on a line (``seisrack.dynamics._events._first_trial``).

Reference: closed-form roots. A sliding slider's stop function ``e = -sig s`` is, over a
sub-step with a linearly varying acceleration, a quadratic in the fraction θ of the step; the
first trial is the root of the quadratic through its value and slope at the start and its
value at the end, so on an exact quadratic it lands on the root itself (where the regula
falsi's straight line through the ends does not). A stuck slider's first trial is that
straight line (its force's slope at the start is not known). The earliest root of several
violated functions is taken, as ``solve_ivp`` does for several events.
"""

from __future__ import annotations

import numpy as np

from seisrack.dynamics._events import _first_trial


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
