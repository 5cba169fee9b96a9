"""Plan figure of a warehouse (issue 24 item 4): each rack row as its footprint, optionally
coloured by a value per row (e.g. a fall probability, once warehouse studies run)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from matplotlib.axes import Axes


def plot_warehouse_plan(warehouse: Any, values: dict[tuple[str, int], float] | None = None, *,
                        label: str = "", ax: Axes | None = None) -> Axes:
    """Footprints of every row of ``warehouse`` (:class:`~seisrack.studies.warehouse.Warehouse`)
    in plan [m], X along the record's first component; ``values``: {(group, index): value in
    [0, 1]} colours the rows (grey without), with a colour bar titled ``label``."""
    import matplotlib

    if ax is None:
        matplotlib.use("Agg", force=False)
        import matplotlib.pyplot as plt

        _, ax = plt.subplots(figsize=(7.0, 5.0))
    from matplotlib.patches import Polygon

    cmap = matplotlib.colormaps["viridis"]
    for p in warehouse.placements():
        c = p["corners"]
        v = None if values is None else values.get((p["group"], p["index"]))
        face = "0.85" if v is None else cmap(float(np.clip(v, 0.0, 1.0)))
        ax.add_patch(Polygon(c, closed=True, fc=face, ec="k", lw=0.8))
        ax.annotate("", xy=c[1], xytext=c[0],
                    arrowprops={"arrowstyle": "->", "lw": 0.6, "color": "k"})
        centre = c.mean(axis=0)
        ax.text(centre[0], centre[1], f"{p['group']}{p['index'] + 1}", ha="center",
                va="center", fontsize="x-small")
    allc = np.concatenate([p["corners"] for p in warehouse.placements()])
    pad = 0.05 * max(np.ptp(allc[:, 0]), np.ptp(allc[:, 1]), 1.0)
    ax.set_xlim(allc[:, 0].min() - pad, allc[:, 0].max() + pad)
    ax.set_ylim(allc[:, 1].min() - pad, allc[:, 1].max() + pad)
    ax.set_aspect("equal")
    ax.set_xlabel("X [m] (record component 1)")
    ax.set_ylabel("Y [m] (record component 2)")
    if values is not None:
        sm = matplotlib.cm.ScalarMappable(cmap=cmap, norm=matplotlib.colors.Normalize(0, 1))
        ax.figure.colorbar(sm, ax=ax, label=label)
    ax.set_title(warehouse.title or "warehouse", fontsize="small")
    return ax
