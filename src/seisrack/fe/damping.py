"""Classical viscous damping matrices (Chopra, *Dynamics of Structures*, 4th ed., §11.4).

For C = a0·M + a1·K the modal damping ratio at circular frequency ω is
ξ(ω) = a0 / (2ω) + a1·ω / 2  (Chopra Eq. 11.4.9).
"""

from __future__ import annotations

import math

import numpy as np

from seisrack.errors import InputError


def stiffness_proportional(ratio: float, period: float) -> tuple[float, float]:
    """(a0, a1) giving ``ratio`` at ``period`` [s] with C = a1·K: a1 = 2ξ/ω (Chopra Eq. 11.4.4)."""
    omega = 2.0 * math.pi / period
    return 0.0, 2.0 * ratio / omega


def rayleigh(pairs: tuple[tuple[float, float], ...]) -> tuple[float, float]:
    """(a0, a1) matching two (period [s], ratio) pairs (Chopra Eq. 11.4.10)."""
    (t1, x1), (t2, x2) = pairs
    w1, w2 = 2.0 * math.pi / t1, 2.0 * math.pi / t2
    a = np.array([[1.0 / (2.0 * w1), w1 / 2.0], [1.0 / (2.0 * w2), w2 / 2.0]])
    a0, a1 = np.linalg.solve(a, np.array([x1, x2]))
    if a0 < 0 or a1 < 0:
        raise InputError("damping.pairs", [list(p) for p in pairs],
                         "pairs giving non-negative Rayleigh coefficients a0 and a1",
                         hint="The ratio at the longer period is too small relative to the "
                              "other; a negative coefficient would add energy")
    return float(a0), float(a1)


def modal_ratio(a0: float, a1: float, period: float | np.ndarray) -> float | np.ndarray:
    """Damping ratio of C = a0·M + a1·K at ``period`` [s]."""
    omega = 2.0 * np.pi / np.asarray(period, dtype=float)
    return a0 / (2.0 * omega) + a1 * omega / 2.0
