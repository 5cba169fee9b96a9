"""Where the pallets of a rack with two horizontal directions (a 3D rack) slide, in plan:
:func:`plot_sliding_paths`, a plan view of each loaded beam level (x down-aisle along the rack,
z cross-aisle: front beam at z = 0, rear beam at z = depth, and the second row's frames of a
back-to-back rack beyond the flue) with every pallet's footprint and
the path of its centre, magnified so that small sliding is visible; the fall limits are dashed
on each footprint and fallen pallets are red. Written as ``sliding_paths.png`` by
:func:`seisrack.report.rack_plot.save_rack_figures`.

matplotlib is imported lazily; nothing here calls ``show()``.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from seisrack.analysis.response import RackResponse

#: the plan-view figure's file name
SLIDING_PATHS_FIGURE = "sliding_paths.png"
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


def _fall_map(resp: RackResponse) -> dict[int, Any]:
    return {f.pallet: f for f in resp.falls}


def plot_sliding_paths(
    resp: RackResponse, model: Any, *, magnify: float | None = None,
    widths: Sequence[float] | np.ndarray | None = None,
) -> Any:
    """Plan view of the sliding path of every pallet, one panel per loaded level (top level on
    top). Returns the Figure.

    model: the compiled 3D rack that was run.
    magnify: factor on the sliding (and on the fall limits, so that the two compare);
        default :func:`default_magnify` of the largest peak sliding magnitude.
    widths: (m,) pallet widths along the beams [m] (default 0.8 m each).
    The fall limits are dashed where the magnified path of the centre would make the pallet
    fall (centre − front limit, centre + rear limit).
    """
    plt = _pyplot()
    from matplotlib.patches import Rectangle

    m = resp.n_pallets
    peak = float(np.max(resp.pallet_peak_sliding())) if m else 0.0
    mag = default_magnify(peak) if magnify is None else float(magnify)
    w = np.full(m, DEFAULT_WIDTH) if widths is None else np.asarray(widths, dtype=float)
    depth = float(model.depth)
    # each pallet centred between the two beams it rests on (its row's, on a back-to-back
    # rack); a frame line at each upright side
    support_z = np.asarray(model.nodes)[np.asarray(model.pallet_node), 2]
    zc_all = support_z.mean(axis=1) if support_z.size else np.zeros(0)
    frames = (np.asarray(model.frame_z) if getattr(model, "frame_z", None) is not None
              else np.array([0.0, depth]))
    px = np.asarray(model.nodes)[np.asarray(model.pallet_node)[:, 0], 0]
    pdep = np.where(np.isfinite(model.pallet_depth), model.pallet_depth, depth)
    up_x = np.asarray(model.upright_x)
    levels = sorted({int(v) + 1 for v in resp.pallet_level}, reverse=True) or [1]
    falls = _fall_map(resp)
    fig, axes = plt.subplots(len(levels), 1, squeeze=False,
                             figsize=(max(6.0, 1.6 * (up_x[-1] - up_x[0]) + 2.0),
                                      1.0 + 2.6 * len(levels)))
    for ax, lv in zip(axes[:, 0], levels, strict=True):
        for z in frames:
            ax.plot([up_x[0], up_x[-1]], [z, z], color="0.3", lw=2.0, zorder=1)
        ax.plot(np.repeat(up_x, frames.size), np.tile(frames, up_x.size), "s", color="0.2",
                ms=5, zorder=2, label="uprights")
        for p in np.flatnonzero(resp.pallet_level == lv - 1):
            zc = zc_all[p]
            fall = falls.get(int(p))
            colour = "red" if fall is not None else "C0"
            x0, hw, hd = px[p], w[p] / 2, pdep[p] / 2
            ax.add_patch(Rectangle((x0 - hw, zc - hd), w[p], pdep[p], fill=fall is not None,
                                   fc=(1.0, 0.0, 0.0, 0.08), ec=colour, lw=1.0, zorder=3))
            for lim, sign in ((resp.fall_front[p], -1.0), (resp.fall_rear[p], 1.0)):
                if np.isfinite(lim):
                    ax.plot([x0 - hw, x0 + hw], [zc + sign * mag * lim] * 2, ls="--",
                            color=colour, lw=0.8, zorder=3)
            u = resp.pallet_sliding[:, p, :]
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
    fig.suptitle(f"Pallet sliding in plan: {resp.record_name}, angle {resp.angle_deg:g}°"
                 "\ndashed: fall limits (magnified like the paths); red: the pallet falls",
                 fontsize=10)
    # leave room for the two-line title above the panels' own titles
    fig.tight_layout(rect=(0.0, 0.0, 1.0, 1.0 - 0.5 / fig.get_figheight()))
    return fig
