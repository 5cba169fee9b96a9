"""Figures of validation examples 2 and 3 (like the paper's Figs 11b and 12b).

Matplotlib is imported lazily; functions take ``ax=None`` and return the Axes; nothing is shown.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from seisrack.atomic import save_figure

if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = ["plot_example_displacement", "plot_example_sliding", "save_validation_figures"]


def _axes(ax: Any) -> Any:
    if ax is not None:
        return ax
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    _, ax = plt.subplots()
    return ax


def _history(entry: dict[str, Any]) -> Any:
    return entry.get("_engine") or entry["_reference"]


def plot_example_displacement(
    results: dict[str, dict[str, Any]], dof: int = 0, ax: Axes | None = None, label: str = "M1"
) -> Axes:
    """Displacement of one structural DOF for every mu of one example (Fig. 12b style).

    ``results``: one example's ``{mu: entry}`` from ``run_validation(keep_histories=True)``.
    """
    ax = _axes(ax)
    for mu, entry in results.items():
        h = _history(entry)
        ax.plot(h.t, h.u[:, dof], lw=0.8, label=f"mu = {mu}")
    ax.set_xlabel("time [s]")
    ax.set_ylabel(f"displacement of {label} [m]")
    ax.legend(loc="best", fontsize="small")
    return ax


def plot_example_sliding(results: dict[str, dict[str, Any]], ax: Axes | None = None) -> Axes:
    """Relative sliding of the supported mass for every mu (Fig. 11b style)."""
    ax = _axes(ax)
    for mu, entry in results.items():
        h = _history(entry)
        ax.plot(h.t, h.sliding[:, 0], lw=0.8, label=f"mu = {mu}")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("sliding relative to support [m]")
    ax.legend(loc="best", fontsize="small")
    return ax


def save_validation_figures(results: dict[str, dict[str, Any]], out_dir: Path) -> list[Path]:
    """Write ``example2.png`` (M1, M2, sliding) and ``example3.png`` (M1, sliding)."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    paths = []
    for name, res in results.items():
        n_dof = len(next(iter(res.values()))["max_abs_displacement_m"])
        fig, axes = plt.subplots(n_dof + 1, 1, sharex=True, figsize=(7, 2.6 * (n_dof + 1)))
        for j in range(n_dof):
            plot_example_displacement(res, dof=j, ax=axes[j], label=f"M{j + 1}")
        plot_example_sliding(res, ax=axes[-1])
        axes[0].set_title(name)
        fig.tight_layout()
        p = out_dir / f"{name}.png"
        save_figure(fig, p, dpi=110)
        plt.close(fig)
        paths.append(p)
    return paths
