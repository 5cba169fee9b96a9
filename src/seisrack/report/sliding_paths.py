"""Figures of a 3D rack time history: where the pallets slide in plan, and when.

- :func:`plot_sliding_paths`: a plan view of each loaded beam level (x down-aisle along the
  rack, z cross-aisle: front beam at z = 0, rear beam at z = depth) with every pallet's
  footprint and the path of its centre, magnified so that small sliding is visible; the fall
  limits are dashed on each footprint and fallen pallets are red.
- :func:`plot_pallet_histories`: sliding down-aisle and cross-aisle against time of the pallets
  that slide most, with the cross-aisle fall limits dashed.
- :func:`save_rack3d_figures`: both as PNG files in an output folder.

matplotlib is imported lazily (Agg backend unless an interactive one is already chosen, as in
:mod:`seisrack.report.rack_plot`); nothing here calls ``show()``.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from seisrack.analysis.rack3d import RackResponse3D
from seisrack.atomic import save_figure

#: file names written by :func:`save_rack3d_figures`
RACK3D_FIGURES = ("sliding_paths.png", "pallet_sliding.png")
#: pallet width along the beams [m] when none is given (the spec's width is not on the model)
DEFAULT_WIDTH = 0.8
#: the largest sliding path is drawn about this long [m] by the default magnification
_SHOWN_PEAK = 0.3


def _pyplot() -> Any:
    import matplotlib

    if matplotlib.get_backend().lower() not in ("agg", "pdf", "svg", "ps", "cairo"):
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def default_magnify(peak: float) -> float:
    """Magnification (one significant digit) that draws a peak sliding ``peak`` [m] about
    0.3 m long; 1 when the sliding is already that large (or zero)."""
    if not np.isfinite(peak) or peak <= 0 or peak >= _SHOWN_PEAK:
        return 1.0
    return max(1.0, float(f"{_SHOWN_PEAK / peak:.1g}"))


def _fall_map(resp: RackResponse3D) -> dict[int, Any]:
    return {f.pallet: f for f in resp.falls}


def plot_sliding_paths(
    resp: RackResponse3D, model: Any, *, magnify: float | None = None,
    widths: Sequence[float] | np.ndarray | None = None,
) -> Any:
    """Plan view of the sliding path of every pallet, one panel per loaded level (top level on
    top). Returns the Figure.

    model: the :class:`~seisrack.model.frame_model3d.FrameModel3D` that was run.
    magnify: factor on the sliding (and on the fall limits, so that the two compare);
        default :func:`default_magnify` of the largest peak sliding magnitude.
    widths: (m,) pallet widths along the beams [m] (default 0.8 m each).
    The fall limits are dashed where the magnified path of the centre would make the pallet
    fall (centre − front limit, centre + rear limit).
    """
    plt = _pyplot()
    from matplotlib.patches import Rectangle

    m = resp.n_pallets
    peak = float(np.max(resp.peak_sliding[:, 2])) if m else 0.0
    mag = default_magnify(peak) if magnify is None else float(magnify)
    w = np.full(m, DEFAULT_WIDTH) if widths is None else np.asarray(widths, dtype=float)
    depth = float(model.depth)
    zc = depth / 2
    px = np.asarray(model.nodes)[np.asarray(model.pallet_node)[:, 0], 0]
    pdep = np.where(np.isfinite(model.pallet_depth), model.pallet_depth, depth)
    up_x = np.asarray(model.upright_x)
    levels = sorted({int(v) for v in resp.pallet_level}, reverse=True) or [1]
    falls = _fall_map(resp)
    fig, axes = plt.subplots(len(levels), 1, squeeze=False,
                             figsize=(max(6.0, 1.6 * (up_x[-1] - up_x[0]) + 2.0),
                                      1.0 + 2.6 * len(levels)))
    for ax, lv in zip(axes[:, 0], levels, strict=True):
        for z in (0.0, depth):
            ax.plot([up_x[0], up_x[-1]], [z, z], color="0.3", lw=2.0, zorder=1)
        ax.plot(np.repeat(up_x, 2), np.tile([0.0, depth], up_x.size), "s", color="0.2",
                ms=5, zorder=2, label="uprights")
        for p in np.flatnonzero(resp.pallet_level == lv):
            fall = falls.get(int(p))
            colour = "red" if fall is not None else "C0"
            x0, hw, hd = px[p], w[p] / 2, pdep[p] / 2
            ax.add_patch(Rectangle((x0 - hw, zc - hd), w[p], pdep[p], fill=fall is not None,
                                   fc=(1.0, 0.0, 0.0, 0.08), ec=colour, lw=1.0, zorder=3))
            for lim, sign in ((resp.fall_front[p], -1.0), (resp.fall_rear[p], 1.0)):
                if np.isfinite(lim):
                    ax.plot([x0 - hw, x0 + hw], [zc + sign * mag * lim] * 2, ls="--",
                            color=colour, lw=0.8, zorder=3)
            u = resp.sliding[:, p, :]
            ax.plot(x0 + mag * u[:, 0], zc + mag * u[:, 1], color=colour, lw=0.7, zorder=4)
            ax.plot([x0], [zc], "+", color="k", ms=6, zorder=5)
            ax.text(x0 - hw + 0.02, zc + hd - 0.02, str(p + 1), fontsize=7, va="top",
                    color=colour, zorder=5)
            if fall is not None:
                fx = x0 + mag * np.interp(fall.time_s, resp.t, u[:, 0])
                fz = zc + mag * np.interp(fall.time_s, resp.t, u[:, 1])
                ax.plot([fx], [fz], "x", color="red", ms=8, mew=2, zorder=6)
                ax.annotate(f"falls {fall.side}\nt = {fall.time_s:.2f} s", (fx, fz),
                            xytext=(6, -4), textcoords="offset points", fontsize=7,
                            color="red", va="top", zorder=6)
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_ylabel("cross-aisle z [m]")
        height = (f", at {resp.level_y[lv - 1]:.2f} m"
                  if 0 < lv <= len(resp.level_y) else "")
        ax.set_title(f"Level {lv}{height}: sliding paths x {mag:g}"
                     + (" (true scale)" if mag == 1 else ""), fontsize=9)
        ax.grid(True, alpha=0.3)
    axes[-1, 0].set_xlabel("down-aisle x [m] (front beam at z = 0, rear beam at z = depth)")
    fig.suptitle(f"Pallet sliding in plan: {resp.motion_name}, angle {resp.angle_deg:g}°"
                 "\ndashed: fall limits (magnified like the paths); red: the pallet falls",
                 fontsize=10)
    return fig


def _largest(resp: RackResponse3D, n: int = 4) -> list[int]:
    order = np.argsort(-resp.peak_sliding[:, 2], kind="stable")
    return [int(p) for p in order[:n]]


def plot_pallet_histories(resp: RackResponse3D, pallets: Sequence[int] | None = None) -> Any:
    """Sliding down-aisle (top) and cross-aisle (bottom) against time [mm] of ``pallets``
    (0-based; default the 4 with the largest peak magnitude), with each pallet's cross-aisle
    fall limits (−front, +rear) as dashed lines and its fall marked. Returns the Figure."""
    plt = _pyplot()
    sel = _largest(resp) if pallets is None else [int(p) for p in pallets]
    falls = _fall_map(resp)
    fig, (ax_x, ax_z) = plt.subplots(2, 1, sharex=True, figsize=(7.5, 5.6))
    for i, p in enumerate(sel):
        c = f"C{i % 10}"
        lab = f"pallet {p + 1} (level {int(resp.pallet_level[p])}, bay {int(resp.pallet_bay[p])})"
        ax_x.plot(resp.t, resp.sliding[:, p, 0] * 1e3, lw=0.7, color=c, label=lab)
        ax_z.plot(resp.t, resp.sliding[:, p, 1] * 1e3, lw=0.7, color=c, label=lab)
        for lim, sign in ((resp.fall_front[p], -1.0), (resp.fall_rear[p], 1.0)):
            if np.isfinite(lim):
                ax_z.axhline(sign * lim * 1e3, color=c, ls="--", lw=0.7)
        fall = falls.get(p)
        if fall is not None:
            zf = np.interp(fall.time_s, resp.t, resp.sliding[:, p, 1]) * 1e3
            ax_z.plot([fall.time_s], [zf], "x", color=c, ms=8, mew=2)
    ax_x.set_ylabel("down-aisle sliding [mm]")
    ax_z.set_ylabel("cross-aisle sliding [mm]")
    ax_z.set_xlabel("time [s]")
    for ax in (ax_x, ax_z):
        ax.grid(True, alpha=0.3)
        ax.axhline(0.0, color="k", lw=0.4)
    if sel:
        ax_x.legend(fontsize=7, loc="upper right")
    fig.suptitle(f"Sliding of the pallets relative to their beams\n{resp.motion_name}, "
                 f"angle {resp.angle_deg:g}°", fontsize=10)
    ax_x.set_title(f"down-aisle (x), the {len(sel)} pallet{'s' * (len(sel) != 1)} "
                   "that slide most" if pallets is None else "down-aisle (x)", fontsize=9)
    ax_z.set_title("cross-aisle (z); dashed: fall limits (front −, rear +); x: the pallet "
                   "falls", fontsize=9)
    return fig


def existing_figures_3d(out: str | Path) -> list[Path]:
    """The files of :data:`RACK3D_FIGURES` already in ``out``."""
    return [Path(out) / f for f in RACK3D_FIGURES if (Path(out) / f).exists()]


def save_rack3d_figures(resp: RackResponse3D, model: Any, out: str | Path, *,
                        suptitle: str = "", force: bool = False) -> list[Path]:
    """Write :data:`RACK3D_FIGURES` into the folder ``out`` (created if missing).

    An existing figure is never overwritten unless ``force``: raises ``InputError`` before
    anything is written.
    """
    out = Path(out)
    if existing_figures_3d(out) and not force:
        from seisrack.errors import InputError

        raise InputError("--out", str(out),
                         "a folder without seisrack figures, or --force to overwrite them")
    out.mkdir(parents=True, exist_ok=True)
    plt = _pyplot()
    paths = []
    for name, draw in ((RACK3D_FIGURES[0], lambda: plot_sliding_paths(resp, model)),
                       (RACK3D_FIGURES[1], lambda: plot_pallet_histories(resp))):
        fig = draw()
        if suptitle:
            title = fig.get_suptitle()
            fig.suptitle(f"{suptitle}\n{title}" if title else suptitle, fontsize=9)
        fig.tight_layout()
        save_figure(fig, out / name, dpi=120)
        plt.close(fig)
        paths.append(out / name)
    return paths
