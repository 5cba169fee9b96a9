"""The study summary's figures of issue 24: ``sliding_reduction.png`` and ``risk.png``.

Each function writes its figure into the summary folder when the summary has the data, and
returns ``{files key: path}`` (empty otherwise). matplotlib is imported lazily (Agg).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from seisrack.atomic import save_figure


def save_reduction_figure(folder: Path, summary: dict[str, Any]) -> dict[str, str]:
    """One panel per group with a sliding reduction: ratio against μ/α."""
    red = [g for g in summary["groups"] if "sliding_reduction" in g]
    if not red:
        return {}
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    from seisrack.report.sliding_reduction_plot import plot_sliding_reduction

    fig, axes = plt.subplots(1, len(red), figsize=(6.4 * len(red), 4.4), squeeze=False)
    for ax, g in zip(axes[0], red, strict=True):
        sr = g["sliding_reduction"]
        plot_sliding_reduction(sr["points"], sr["code_nominal"]["down-aisle"], ax=ax)
        ax.set_title(Path(g["rack"]).name, fontsize="small")
    fig.tight_layout()
    path = folder / "sliding_reduction.png"
    save_figure(fig, path, dpi=120)
    plt.close(fig)
    return {"sliding_reduction_png": str(path)}


def save_risk_figure(folder: Path, summary: dict[str, Any]) -> dict[str, str]:
    """The hazard curve and the fragilities (with ``study summary --hazard``)."""
    if "risk" not in summary:
        return {}
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    from seisrack.report.risk_plot import plot_risk

    ax = plot_risk(summary["risk"])
    path = folder / "risk.png"
    save_figure(ax.figure, path, dpi=120, bbox_inches="tight")
    plt.close(ax.figure)
    return {"risk_png": str(path)}
