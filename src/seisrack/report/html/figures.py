"""Figures of the engineer's HTML report (matplotlib, imported lazily).

Every plotting function takes ``ax=None`` and returns the Axes; :func:`png_data_uri` turns a
figure into an inline base64 PNG. Nothing calls ``show()``.
"""

from __future__ import annotations

import base64
import io
from typing import Any

import numpy as np

#: pallet rectangle height drawn in the elevation [m] (a drawing convention, not an input)
PALLET_DRAW_HEIGHT = 0.35


def _axes(ax: Any, figsize: tuple[float, float] = (7.0, 4.0)) -> Any:
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots(figsize=figsize)
    return ax


def png_data_uri(fig: Any, dpi: int = 110) -> str:
    """``data:image/png;base64,...`` of a matplotlib figure (closed afterwards)."""
    import matplotlib.pyplot as plt

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi, bbox_inches="tight")
    plt.close(fig)
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode("ascii")


def plot_elevation(model: Any, spec: Any, peak_sliding: np.ndarray, utilisation: np.ndarray,
                   ax: Any = None) -> Any:
    """The rack's elevation with each pallet drawn as a rectangle coloured by its peak sliding.

    peak_sliding: (m,) [m]; utilisation: (m,) sliding / free distance (≥ 1: may fall, drawn
    with a thick red edge and hatched). A colour bar gives the sliding in mm.
    """
    import matplotlib as mpl
    from matplotlib.patches import Rectangle

    ax = _axes(ax, (8.0, 5.0))
    mesh = model.mesh
    front = np.asarray(model.element_side) == 0  # a 3D rack: its front frame, in elevation
    for i, j in mesh.elements[front]:
        ax.plot(*mesh.nodes[[i, j]][:, :2].T, color="0.35", lw=1.6, zorder=1)
    base = mesh.nodes[model.base_nodes[np.asarray(model.column_side) == 0]]
    ax.plot(base[:, 0], base[:, 1], "k^", ms=8, clip_on=False, zorder=2)
    mm = 1e3 * np.asarray(peak_sliding, dtype=float)
    vmax = float(mm.max()) if mm.size and mm.max() > 0 else 1.0
    norm = mpl.colors.Normalize(vmin=0.0, vmax=vmax)
    cmap = mpl.colormaps["viridis"]
    pallets = list(getattr(spec, "pallets", []) or [])
    node_xy = mesh.nodes[model.pallet_node[:, 0]][:, :2]
    for j in range(model.n_pallets):
        w = float(getattr(pallets[j], "width", 1.0)) if j < len(pallets) else 1.0
        x, y = node_xy[j]
        falls = bool(utilisation[j] >= 1.0)
        ax.add_patch(Rectangle((x - w / 2, y), w, PALLET_DRAW_HEIGHT,
                               facecolor=cmap(norm(mm[j])), alpha=0.9, zorder=3,
                               edgecolor="red" if falls else "black", lw=2.5 if falls else 0.6,
                               hatch="xx" if falls else None))
        ax.text(x, y + PALLET_DRAW_HEIGHT / 2, str(j + 1), ha="center", va="center",
                fontsize=7, color="white" if norm(mm[j]) < 0.6 else "black", zorder=4)
    sm = mpl.cm.ScalarMappable(norm=norm, cmap=cmap)
    ax.figure.colorbar(sm, ax=ax, label="peak sliding [mm]", shrink=0.85)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("height y [m]")
    ax.autoscale_view()
    return ax


def plot_modes(model: Any, modal: Any, n_shapes: int = 3) -> Any:
    """A figure with the first ``n_shapes`` mode shapes (returns the Figure)."""
    from seisrack.report.frame_plot import modes_figure

    return modes_figure(model, modal, n_shapes)


def components(motion: Any) -> list[tuple[str, str, np.ndarray]]:
    """(direction, record name, acceleration [m/s²]) of each component of a
    :class:`~seisrack.motion.components.GroundMotion` as run: down-aisle, then cross-aisle and
    vertical when there are."""
    out = [("down-aisle", motion.names[0], motion.x)]
    if motion.z is not None:
        out.append(("cross-aisle", motion.names[1] or "-", motion.z))
    if motion.v is not None:
        out.append(("vertical", motion.names[2], motion.v))
    return out


def plot_record(motion: Any) -> Any:
    """Ground acceleration [m/s²] against time [s], one panel per component. Returns the
    Figure."""
    import matplotlib.pyplot as plt

    comps = components(motion)
    fig, axes = plt.subplots(len(comps), 1, figsize=(8.0, 2.3 * len(comps)), squeeze=False,
                             sharex=True)
    t = np.arange(motion.n) * motion.dt
    for ax, (direction, name, a) in zip(axes[:, 0], comps, strict=True):
        ax.plot(t, a, lw=0.7, color="tab:blue")
        ax.set_ylabel("[m/s²]")
        ax.set_title(f"{direction}: {name}", fontsize=9)
        ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel("time [s]")
    fig.tight_layout()
    return fig


def plot_spectra(motion: Any, ax: Any = None, *, design: Any = None, periods_rack: Any = None,
                 damping: float = 0.05) -> Any:
    """5 %-damped pseudo-acceleration spectrum of each horizontal component [m/s²], with the
    design spectrum and the rack's periods (vertical lines) when given."""
    from seisrack.motion import response_spectrum

    ax = _axes(ax, (7.0, 3.6))
    T = np.geomspace(0.02, 4.0, 120)
    for k, (direction, name, a) in enumerate(components(motion)):
        if direction == "vertical":
            continue
        sp = response_spectrum(a, motion.dt, T, damping)
        ax.plot(T, sp.psa, color=f"C{k}", label=f"{direction} {name} ({100 * damping:g} %)")
    if design is not None:
        ax.plot(T, design.psa(T), "k--", label=getattr(design, "name", "design spectrum"))
    if periods_rack is not None:
        for k, p in enumerate(np.asarray(periods_rack)[:3]):
            ax.axvline(p, color="tab:red", lw=0.8, ls=":", label="rack periods" if k == 0
                       else None)
    ax.set_xscale("log")
    ax.set_xlabel("period T [s]")
    ax.set_ylabel("pseudo-acceleration Sa [m/s²]")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    return ax


def plot_histories_static(series: list[tuple[str, str, np.ndarray, dict[str, np.ndarray]]]
                          ) -> Any:
    """Static fallback of the interactive time histories: one panel per (title, unit, t, lines).
    Returns the Figure."""
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(len(series), 1, figsize=(8.0, 2.4 * len(series)), squeeze=False)
    for ax, (title, unit, t, lines) in zip(axes[:, 0], series, strict=True):
        for name, y in lines.items():
            ax.plot(t, y, lw=0.8, label=name)
        ax.set_title(title, fontsize=9)
        ax.set_ylabel(unit)
        ax.grid(alpha=0.3)
        if len(lines) > 1:
            ax.legend(fontsize=7, ncol=min(len(lines), 5))
    axes[-1, 0].set_xlabel("time [s]")
    fig.tight_layout()
    return fig
