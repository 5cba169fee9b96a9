"""Figures of a study: fragility curves on stripes, and IDA curves.

Every function takes ``ax=None`` and returns the Axes; matplotlib is imported lazily (Agg when no
backend is chosen) and nothing is shown.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = ["plot_fragility", "plot_ida"]


def _axes(ax: Any) -> Any:
    if ax is not None:
        return ax
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    _, ax = plt.subplots(figsize=(6.4, 4.4))
    return ax


def plot_fragility(
    im: Sequence[float],
    fraction: Sequence[float],
    theta: float,
    beta: float,
    *,
    band: tuple[np.ndarray, np.ndarray] | None = None,
    grid: np.ndarray | None = None,
    label: str = "",
    im_label: str = "IM [m/s²]",
    ax: Axes | None = None,
) -> Axes:
    """Observed fraction exceeding per stripe (markers), fitted lognormal, optional band.

    im, fraction: (m,) stripe intensity [IM units] and fraction of runs exceeding [-];
    band: (lo, hi) on ``grid`` (pointwise bootstrap percentiles).
    """
    from seisrack.lognormal import fragility_curve

    ax = _axes(ax)
    im = np.asarray(im, dtype=float)
    if grid is None:
        top = max(float(np.max(im)) if im.size else 1.0, theta if np.isfinite(theta) else 0.0)
        grid = np.linspace(0.0, 1.5 * top, 200)[1:]
    (line,) = ax.plot(grid, fragility_curve(grid, theta, beta), label=label or None)
    c = line.get_color()
    if band is not None and np.all(np.isfinite(band[0])):
        ax.fill_between(grid, band[0], band[1], color=c, alpha=0.2, lw=0)
    ax.plot(im, fraction, "o", color=c, mfc="none")
    ax.set_xlabel(im_label)
    ax.set_ylabel("P(exceed) [-]")
    ax.set_ylim(-0.02, 1.02)
    ax.set_xlim(left=0.0)
    if label:
        ax.legend(loc="best", fontsize="small")
    return ax


def plot_ida(
    curves: Sequence[dict],
    *,
    edp: str = "peak_sliding_max_m",
    edp_label: str = "peak sliding [m]",
    im_label: str = "IM [m/s²]",
    threshold: float | None = None,
    ax: Axes | None = None,
) -> Axes:
    """IDA curves: one line per record, the response ``edp`` on x and IM on y.

    curves: dicts with ``"im"`` (s,) and ``edp`` (s,) lists, as in the summary's ``ida``.
    """
    ax = _axes(ax)
    for cv in curves:
        ax.plot(cv[edp], cv["im"], "-o", ms=3, lw=1)
    if threshold is not None:
        ax.axvline(threshold, ls=":", c="k", lw=0.8)
    ax.set_xlabel(edp_label)
    ax.set_ylabel(im_label)
    return ax
