"""Regime map of the §II SDOF against mu/alpha (paper Fig. 6) and the continuous-sliding threshold.

Source: the paper's §II quotes 0.537 for the boundary between stick–slip and continuous sliding
and 1.0 for the onset of sliding (Eq. 2). The derivation of the threshold from Eqs 3–5 is in
docs/theory/sdof_threshold.md.
"""

from __future__ import annotations

import math

import pytest

from seisrack.sdof.regime import (
    continuous_sliding_threshold,
    continuous_sliding_threshold_closed,
    sdof_regime,
    threshold_by_simulation,
)

RHO = 2.0 / math.sqrt(4.0 + math.pi**2)


def test_threshold_matches_analytic_and_paper():
    thr = continuous_sliding_threshold()
    assert abs(thr - RHO) < 1e-6
    assert thr == pytest.approx(continuous_sliding_threshold_closed(), abs=1e-12)
    assert round(thr, 3) == 0.537  # paper §II


def test_threshold_by_simulated_bisection():
    assert abs(threshold_by_simulation(tol=1e-5) - RHO) < 2e-5


@pytest.mark.parametrize(
    ("rho", "regime"),
    [(0.1, "continuous-sliding"), (0.25, "continuous-sliding"), (0.5, "continuous-sliding"),
     (RHO - 2e-3, "continuous-sliding"), (RHO + 2e-3, "stick-slip"), (0.6, "stick-slip"),
     (0.75, "stick-slip"), (0.99, "stick-slip"), (1.0, "no-sliding"), (1.5, "no-sliding")],
)
def test_regime_map(rho, regime):
    assert sdof_regime(rho) == regime


def test_dynamic_below_static_lowers_threshold_value():
    # with mu_d < mu_s the reversal angle moves (Eq. C of the theory note): threshold rises
    assert continuous_sliding_threshold(0.5) > RHO
    thr = continuous_sliding_threshold(0.5)
    assert sdof_regime(thr - 0.01, 0.5 * (thr - 0.01)) == "continuous-sliding"
    assert sdof_regime(thr + 0.01, 0.5 * (thr + 0.01)) == "stick-slip"
