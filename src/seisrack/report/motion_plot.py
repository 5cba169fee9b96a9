"""Figures of ground motions, like Fig. 15a (accelerogram) and Fig. 15b (spectrum vs target).

matplotlib is imported lazily; every function takes ``ax=None`` and returns the Axes; nothing here
calls ``show()``.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from seisrack.atomic import save_figure
from seisrack.motion.records import G, Record


def _axes(ax: Any) -> Any:
    if ax is not None:
        return ax
    import matplotlib

    if matplotlib.get_backend().lower() not in ("agg", "pdf", "svg", "ps", "cairo"):
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    _, ax = plt.subplots(figsize=(7.0, 3.2))
    return ax


def plot_accelerogram(record: Record, ax: Any = None, *, in_g: bool = True) -> Any:
    """Acceleration against time (Fig. 15a). Returns the Axes."""
    ax = _axes(ax)
    scale = 1.0 / G if in_g else 1.0
    ax.plot(record.time, record.accel * scale, lw=0.7, color="k")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("ground acceleration [g]" if in_g else "ground acceleration [m/s²]")
    ax.set_title(record.name)
    ax.grid(True, alpha=0.3)
    return ax


def plot_spectrum(
    periods: np.ndarray,
    psa: np.ndarray,
    ax: Any = None,
    *,
    target: Any = None,
    label: str = "record",
    in_g: bool = True,
) -> Any:
    """Pseudo-acceleration spectrum, with the target spectrum if given (Fig. 15b)."""
    ax = _axes(ax)
    scale = 1.0 / G if in_g else 1.0
    ax.plot(periods, np.asarray(psa) * scale, lw=1.0, label=label)
    if target is not None:
        ax.plot(periods, target.psa(periods) * scale, "k--", lw=1.2, label=target.name)
    ax.set_xlabel("period [s]")
    ax.set_ylabel("pseudo-acceleration [g]" if in_g else "pseudo-acceleration [m/s²]")
    ax.grid(True, alpha=0.3)
    ax.legend()
    return ax


def save(ax: Any, path: str) -> None:
    """Save the figure holding ``ax`` and close it."""
    import matplotlib.pyplot as plt

    fig = ax.figure
    fig.tight_layout()
    save_figure(fig, path, dpi=120)
    plt.close(fig)
