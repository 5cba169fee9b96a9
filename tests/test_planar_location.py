"""First trial of a planar event location (``_planar_events._first_guess``).

Reference: the closed-form root of a quadratic. A sliding pallet's stop function is modelled
over the sub-step by the quadratic through its start value, its start slope
``hrem (mu_d N / m + d0·(a_g + P q̈))`` (docs/theory/planar_friction.md §3) and its end value;
when the function *is* that quadratic, the first trial must land on its root, which the
straight line through the two ends (the Illinois estimate) misses. A stuck pallet keeps the
straight line, and so does a sliding one whose start slope is not positive.
"""

from __future__ import annotations

import numpy as np
import pytest

from seisrack.dynamics import _planar_events as twin

HREM = 0.005  # s, the sub-step
MASS, MUD, N0 = 100.0, 0.3, 981.0  # kg, -, N
PQDD = (1.5, -0.7)  # m/s², the support's acceleration (P q̈ with P = I)
AG = (0.4, 2.0)  # m/s², the ground's


def _backends():
    from seisrack.dynamics import _planar_numba as compiled

    return [pytest.param(compiled, id="numba"), pytest.param(twin, id="python")]


def _args(e0: float, e1: float, stuck: bool, dirn=(1.0, 0.0)):  # noqa: ANN001, ANN202
    return (np.array([stuck]), np.array(dirn), np.array([e0]), np.array([e1]),
            np.array([1e-30]), np.array([MASS]), np.array([MUD]), np.array([N0]), np.eye(2),
            np.array(PQDD), np.array(AG), HREM)


def _slope(dirn=(1.0, 0.0)) -> float:  # noqa: ANN001
    """de/dθ at the start: the sub-step times the deceleration relative to the support."""
    return HREM * (MUD * N0 / MASS + sum(d * (a + p) for d, a, p in zip(dirn, AG, PQDD,
                                                                       strict=True)))


@pytest.mark.parametrize("mod", _backends())
@pytest.mark.parametrize("dirn", [(1.0, 0.0), (0.6, 0.8)])
@pytest.mark.parametrize("curv", [-0.5, -0.2, 0.0, 0.4])
def test_sliding_pallet_lands_on_the_quadratic_root(mod, dirn, curv):
    d = _slope(dirn)
    e0 = -0.3 * d
    c = curv * d
    e1 = e0 + d + c  # e(θ) = e0 + d θ + c θ² at θ = 1
    root = -e0 / d if c == 0.0 else (-d + np.sqrt(d * d - 4 * c * e0)) / (2 * c)
    assert 0.0 < root < 1.0
    th = mod._first_guess(*_args(e0, e1, False, dirn))
    assert th == pytest.approx(root, rel=1e-9)
    if c != 0.0:
        assert abs(-e0 / (e1 - e0) - root) > 0.02  # the straight line misses it


@pytest.mark.parametrize("mod", _backends())
def test_stuck_pallet_keeps_the_straight_line(mod):
    th = mod._first_guess(*_args(-0.3, 0.9, True))
    assert th == pytest.approx(0.25, rel=1e-12)


@pytest.mark.parametrize("mod", _backends())
def test_no_positive_start_slope_keeps_the_straight_line(mod):
    # sliding along -x with light friction: mu_d N/m = 0.098 m/s² against d0·(a_g + P q̈)
    # = -1.9 m/s², so that the start slope is negative
    args = list(_args(-0.3, 0.9, False, (-1.0, 0.0)))
    args[6] = np.array([0.01])
    th = mod._first_guess(*args)
    assert th == pytest.approx(0.25, rel=1e-12)


@pytest.mark.parametrize("mod", _backends())
def test_earliest_root_wins(mod):
    d = _slope()
    stuck = np.array([False, True])
    dirn = np.array([1.0, 0.0, 1.0, 0.0])
    e_lo = np.array([-0.3 * d, -0.5])
    e_hi = np.array([-0.3 * d + d - 0.5 * d, 0.5])  # roots: the quadratic's, 0.5 (line)
    P = np.eye(4)
    th = mod._first_guess(stuck, dirn, e_lo, e_hi, np.full(2, 1e-30), np.full(2, MASS),
                          np.full(2, MUD), np.full(2, N0), P, np.array([*PQDD, *PQDD]),
                          np.array(AG), HREM)
    c = -0.5 * d
    root = (-d + np.sqrt(d * d - 4 * c * (-0.3 * d))) / (2 * c)
    assert th == pytest.approx(min(root, 0.5), rel=1e-9)
