"""Regression: a sliding phase of the paper's §II block (Degée & Denoël, Eqs 3–5) never ends at
its own start.

With mu_s = mu_d the slip starts exactly on a critical angle of the relative velocity
(sin theta = mu/alpha). An absolute 1e-15 rad guard let round-off at theta ~ 30 rad end the
phase at once (a spurious stick of half a period, visible in the regime map after ~5 periods).
"""

import numpy as np
import pytest

from seisrack.sdof.closed_form import solve_sdof


@pytest.mark.parametrize("ratio", np.linspace(0.55, 0.99, 23).tolist())
def test_no_zero_length_sliding_phase(ratio):
    sol = solve_sdof(1.0, ratio, 1.0, 30.0)
    lengths = [p.t_end - p.t_start for p in sol.phases[:-1] if p.direction != 0]
    assert lengths and min(lengths) > 1e-6


def test_stick_slip_orbit_is_periodic_late_in_the_run():
    # mu/alpha = 0.7 is in the stick-slip regime: one slip and one stick per half period
    sol = solve_sdof(1.0, 0.7, 1.0, 6.0)
    late = [k for t, k in sol.events if t > 4.5]
    assert late == ["stick", "slip", "stick", "slip", "stick", "slip"]
