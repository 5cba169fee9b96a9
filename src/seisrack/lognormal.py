"""The lognormal fragility function (Baker 2015, Eq. 1), shared by the study statistics and
the figures: P(exceed | IM = x) = Φ(ln(x/θ)/β)."""

from __future__ import annotations

import math

import numpy as np
from scipy import special


def fragility_curve(x, theta: float, beta: float) -> np.ndarray:
    """Phi(ln(x/theta)/beta) at intensities x; beta = 0 gives the step at theta."""
    x = np.asarray(x, dtype=float)
    if not (theta > 0) or not math.isfinite(theta) or not (beta >= 0):
        return np.full(x.shape, np.nan)
    if beta == 0:
        return (x >= theta).astype(float)
    return special.ndtr(np.log(x / theta) / beta)
