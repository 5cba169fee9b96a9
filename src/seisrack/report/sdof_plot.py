"""Figures for the §II SDOF: analogues of the paper's Figs 5 and 7 (displacement, velocity,
friction force of support and block). Matplotlib is imported lazily; nothing is shown."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from seisrack.atomic import save_figure

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from seisrack.sdof.closed_form import SdofSolution

__all__ = ["plot_sdof", "save_sdof_figure"]


def _axes(ax: Any) -> Any:
    if ax is not None:
        return ax
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    _, ax = plt.subplots()
    return ax


def plot_sdof(
    sol: SdofSolution, quantity: str = "displacement", ax: Axes | None = None, n: int = 4001
) -> Axes:
    """One panel: ``quantity`` in {"displacement", "velocity", "friction"} versus time."""
    ax = _axes(ax)
    t = np.linspace(0.0, sol.duration, n)
    if quantity == "displacement":
        ax.plot(t, sol.support_displacement(t), label="1: support")
        ax.plot(t, sol.displacement(t), label="2: mass")
        ax.set_ylabel("displacement [m]")
    elif quantity == "velocity":
        ax.plot(t, sol.support_velocity(t), label="1: support")
        ax.plot(t, sol.velocity(t), label="2: mass")
        ax.set_ylabel("velocity [m/s]")
    elif quantity == "friction":
        ax.plot(t, sol.friction(t) / (sol.mass * sol.g), label="F / (M g)")
        ax.axhline(sol.mu_static, ls=":", c="k", lw=0.8)
        ax.axhline(-sol.mu_static, ls=":", c="k", lw=0.8)
        ax.set_ylabel("friction / (M g) [-]")
    else:
        raise ValueError(f"unknown quantity {quantity!r}")
    for tev, kind in sol.events:
        ax.axvline(tev, lw=0.4, c={"slip": "r", "stick": "g", "reverse": "b"}[kind], alpha=0.4)
    ax.set_xlabel("time [s]")
    ax.legend(loc="best", fontsize="small")
    return ax


def save_sdof_figure(sol: SdofSolution, path: str | Path) -> Path:
    """Three stacked panels (displacement, velocity, friction) written to ``path``."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(3, 1, sharex=True, figsize=(7, 8))
    for ax, q in zip(axes, ("displacement", "velocity", "friction"), strict=True):
        plot_sdof(sol, q, ax=ax)
    axes[0].set_title(
        f"mu/alpha = {sol.mu_static / sol.alpha:.3g}, f = {sol.frequency:g} Hz, "
        f"alpha = {sol.alpha:g}"
    )
    fig.tight_layout()
    path = Path(path)
    save_figure(fig, path, dpi=120)
    plt.close(fig)
    return path
