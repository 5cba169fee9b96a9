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

__all__ = ["DRAWN_STATUSES", "fit_is_drawable", "plot_fragility", "plot_ida"]


def _axes(ax: Any) -> Any:
    if ax is not None:
        return ax
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    _, ax = plt.subplots(figsize=(6.4, 4.4))
    return ax


#: fit statuses whose (theta, beta) describe a curve worth drawing
DRAWN_STATUSES = ("ok", "ida_moments", "ida_censored")


def fit_is_drawable(theta: float, beta: float, status: str | None = None) -> bool:
    """Whether a lognormal curve can honestly be drawn for this fit: a finite θ > 0 and
    β > 0, and a status that describes a curve (not "separated", "underdetermined", ...)."""
    return (status is None or status in DRAWN_STATUSES) and bool(
        np.isfinite(theta) and theta > 0 and np.isfinite(beta) and beta > 0)


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
    status: str | None = None,
    ax: Axes | None = None,
) -> Axes:
    """Observed fraction exceeding per stripe (markers), fitted lognormal, optional band.

    im, fraction: (m,) stripe intensity [IM units] and fraction of runs exceeding [-];
    band: (lo, hi) on ``grid`` (pointwise bootstrap percentiles); status: the fit's status
    (:class:`seisrack.studies.fragility.FragilityFit`). A fit that describes no curve
    ("separated": a step with β undetermined, "underdetermined", "failed", ...) is not drawn
    as one: the observed fractions are joined by a dashed line and the legend says why, and
    for a step its θ is marked (a step drawn to probability 1 would contradict a stripe
    observed at, say, 0.33).
    """
    from seisrack.lognormal import fragility_curve

    ax = _axes(ax)
    im = np.asarray(im, dtype=float)
    frac = np.asarray(fraction, dtype=float)
    if grid is None:
        top = max(float(np.max(im)) if im.size else 1.0, theta if np.isfinite(theta) else 0.0)
        grid = np.linspace(0.0, 1.5 * top, 200)[1:]
    if fit_is_drawable(theta, beta, status):
        (line,) = ax.plot(grid, fragility_curve(grid, theta, beta), label=label or None)
        c = line.get_color()
        if band is not None and np.all(np.isfinite(band[0])):
            ax.fill_between(grid, band[0], band[1], color=c, alpha=0.2, lw=0)
        ax.plot(im, frac, "o", color=c, mfc="none")
    else:
        order = np.argsort(im)
        good = order[np.isfinite(frac[order])]
        why = {"separated": "fit separated: a step, β undetermined",
               "underdetermined": "fit underdetermined: θ and β not both estimable"}.get(
            status or "", f"no fitted curve ({status or 'no fit'})")
        name = label.removesuffix(": fitted") if label else ""
        (line,) = ax.plot(im[good], frac[good], "o--", mfc="none", lw=1,
                          label=f"{name + ': ' if name else ''}observed; {why}")
        if status == "separated" and np.isfinite(theta) and theta > 0:
            ax.axvline(theta, color=line.get_color(), ls=":", lw=1,
                       label=f"θ ≈ {theta:.3g} (where the step lies)")
    ax.set_xlabel(im_label)
    ax.set_ylabel("P(exceed) [-]")
    ax.set_ylim(-0.02, 1.02)
    ax.set_xlim(left=0.0)
    if label or ax.get_legend_handles_labels()[0]:
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
