"""Figure of the sliding reduction against μ/α (issue 24 item 2)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from matplotlib.axes import Axes

_STYLE = {"base_shear": ("o", "base shear"), "connector_moment": ("s", "connector moment"),
          "upright_moment": ("^", "upright moment")}


def plot_sliding_reduction(points: dict[str, Any], code: float | None = None, *,
                           ax: Axes | None = None) -> Axes:
    """Each run's peak with sliding pallets over the peak with rigid pallets, against μ/α.

    points: ``mu_over_alpha`` (n,) and one (n,) list of ratios per quantity (None = missing),
    as :func:`seisrack.studies.reduction_summary.reduction_summary` gives them; code: the
    reduction the code's unit-load factors assume (a dashed line). The line min(1, μ/α) is the
    pallet force cap of a rigid block (μ·m·g over m·α·g).
    """
    if ax is None:
        import matplotlib

        matplotlib.use("Agg", force=False)
        import matplotlib.pyplot as plt

        _, ax = plt.subplots(figsize=(6.4, 4.4))
    x = np.array([np.nan if v is None else v for v in points["mu_over_alpha"]], dtype=float)
    for key, (marker, label) in _STYLE.items():
        if key not in points:
            continue
        y = np.array([np.nan if v is None else v for v in points[key]], dtype=float)
        ax.plot(x, y, marker, mfc="none", ms=5, label=label)
    good = np.isfinite(x)
    top = max(1.5, float(np.nanmax(x[good])) * 1.05) if good.any() else 1.5
    grid = np.linspace(0.0, top, 100)
    ax.plot(grid, np.minimum(1.0, grid), "k-", lw=0.8, label="min(1, μ/α): pallet force cap")
    if code is not None:
        ax.axhline(code, color="C3", ls="--", lw=1.0,
                   label=f"code: E_D1·E_D2·E_D3 = {code:.2f} (assumed factors)")
    ax.set_xlim(0.0, top)
    ax.set_ylim(0.0, 1.3)
    ax.set_xlabel("μ / α  (α = rigid peak level acceleration / g)")
    ax.set_ylabel("peak with sliding / peak with rigid pallets [-]")
    ax.legend(fontsize="small", loc="lower right")
    ax.grid(True, alpha=0.3)
    return ax
