"""Regime map of the §II SDOF against mu/alpha (the paper's Fig. 6) and its computed threshold.

The regime is the steady behaviour after the first slip:

- ``"no-sliding"``: the block never slips (mu_s/alpha >= 1, Eq. 2);
- ``"stick-slip"``: it keeps sticking between sliding phases;
- ``"continuous-sliding"``: it stops sticking (reversals only).

The boundary between the last two is the value of mu/alpha at which the symmetric periodic
sliding orbit (reversals half a period apart) becomes unable to continue: see
``docs/theory/sdof_threshold.md``.
"""

from __future__ import annotations

import math
from typing import Literal

from scipy.optimize import brentq

from seisrack.errors import InputError
from seisrack.sdof.closed_form import solve_sdof

__all__ = [
    "Regime",
    "continuous_sliding_threshold",
    "continuous_sliding_threshold_closed",
    "sdof_regime",
    "threshold_by_simulation",
]

Regime = Literal["no-sliding", "stick-slip", "continuous-sliding"]


def _steady_residual(rho: float, dynamic_over_static: float = 1.0) -> float:
    """Reversal margin of the symmetric steady sliding orbit at mu_s/alpha = rho.

    Zero mean relative acceleration over half a period gives the reversal angle
    ``cos(theta_r) = pi mu_d / (2 alpha)`` (Eq. 3 minus Eq. 1.a integrated over pi/omega);
    the orbit reverses (does not stick) while ``sin(theta_r) > mu_s/alpha`` (Eq. 5).
    """
    c = 0.5 * math.pi * rho * dynamic_over_static
    if c >= 1.0:
        return -rho
    return math.sqrt(1.0 - c * c) - rho


def continuous_sliding_threshold(dynamic_over_static: float = 1.0) -> float:
    """mu_s/alpha below which the block slides continuously in steady state.

    Computed by Brent root finding on the steady-orbit reversal margin (paper: 0.537 for
    mu_s = mu_d). ``dynamic_over_static`` = mu_d/mu_s in (0, 1].
    """
    if not (math.isfinite(dynamic_over_static) and 0.0 < dynamic_over_static <= 1.0):
        raise InputError("dynamic_over_static", dynamic_over_static, "0 < mu_d/mu_s <= 1")
    return float(
        brentq(_steady_residual, 1e-12, 1.0, args=(dynamic_over_static,), xtol=1e-15, rtol=1e-15)
    )


def continuous_sliding_threshold_closed() -> float:
    """Closed form of the mu_s = mu_d threshold: 1/sqrt(1 + pi²/4) = 2/sqrt(4 + pi²)."""
    return 2.0 / math.sqrt(4.0 + math.pi**2)


def _regime_by_simulation(
    mu_over_alpha: float, mu_dynamic_over_alpha: float, n_periods: int
) -> Regime:
    sol = solve_sdof(1.0, mu_over_alpha, 1.0, float(n_periods), mu_dynamic=mu_dynamic_over_alpha)
    if not sol.events:
        return "no-sliding"
    tail = 0.5 * n_periods  # steady state judged on the second half of the run
    sticks = [t for t, kind in sol.events if kind == "stick" and t >= tail]
    return "stick-slip" if sticks else "continuous-sliding"


def sdof_regime(
    mu_over_alpha: float,
    mu_dynamic_over_alpha: float | None = None,
    *,
    n_periods: int = 400,
) -> Regime:
    """Steady regime of the §II SDOF (Fig. 6) by exact simulation over ``n_periods`` periods.

    The regime depends only on the ratios (time scales with 1/f, lengths with alpha g / omega²).
    """
    rho_d = mu_over_alpha if mu_dynamic_over_alpha is None else mu_dynamic_over_alpha
    for name, val in (("mu_over_alpha", mu_over_alpha), ("mu_dynamic_over_alpha", rho_d)):
        if not math.isfinite(val) or val < 0:
            raise InputError(name, val, "a finite number >= 0")
    if rho_d > mu_over_alpha:
        raise InputError("mu_dynamic_over_alpha", rho_d, f"<= mu_over_alpha = {mu_over_alpha}")
    if mu_over_alpha >= 1.0:
        return "no-sliding"
    return _regime_by_simulation(mu_over_alpha, rho_d, n_periods)


def threshold_by_simulation(tol: float = 1e-4, *, n_periods: int = 400) -> float:
    """Independent estimate of the threshold by bisection on the simulated regime (mu_s = mu_d)."""
    lo, hi = 0.3, 0.9  # continuous at lo, stick-slip at hi
    if sdof_regime(lo, n_periods=n_periods) != "continuous-sliding":  # pragma: no cover
        raise RuntimeError("bisection bracket lost at the lower end")
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        if sdof_regime(mid, n_periods=n_periods) == "continuous-sliding":
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)
