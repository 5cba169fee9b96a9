"""Moment–rotation loops of a run's nonlinear hinges: :func:`plot_hinge_loops`.

matplotlib is imported inside the function (it is an optional dependency of the reports);
the figure is never shown: the caller saves it or embeds the Axes.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from seisrack.atomic import save_figure
from seisrack.errors import InputError


def default_hinges(hinges: Any) -> list[int]:
    """Indices of the most-demanded connector and the most-demanded base plate (largest peak
    |rotation| / yield rotation, or |rotation| when the hinge is elastic), those that exist."""
    rot = np.abs(np.asarray(hinges.rotation, dtype=float))
    peak = rot.max(axis=0) if rot.shape[0] else np.zeros(rot.shape[1])
    ty = np.asarray(hinges.yield_rotation, dtype=float)
    demand = np.where(np.isfinite(ty) & (ty > 0), peak / np.where(ty > 0, ty, 1.0), peak)
    out = []
    for kind in ("connector", "base"):
        idx = [i for i, k in enumerate(hinges.kind) if k == kind]
        if idx:
            out.append(max(idx, key=lambda i: (demand[i], -i)))
    return out


def _select(hinges: Any, which: int | str | Sequence[int | str] | None) -> list[int]:
    labels = list(hinges.labels)
    if which is None:
        return default_hinges(hinges)
    items = list(which) if isinstance(which, Sequence) and not isinstance(which, str) \
        else [which]
    if not items:
        raise InputError("which", which, "one or more hinge indices or labels, or None")
    out = []
    for it in items:
        if isinstance(it, str):
            if it not in labels:
                raise InputError("which", it, "a hinge label: " + ", ".join(labels))
            out.append(labels.index(it))
        elif isinstance(it, int | np.integer) and not isinstance(it, bool) \
                and -len(labels) <= int(it) < len(labels):
            out.append(int(it) % len(labels))
        else:
            raise InputError("which", it, f"a hinge index in [0, {len(labels) - 1}] or a label")
    return out


def plot_hinge_loops(hinges: Any, which: int | str | Sequence[int | str] | None = None,
                     ax: Any = None, label: str | None = None, **style: Any) -> Any:
    """Moment [kN·m] against rotation [mrad] of the selected hinges, one line per hinge.

    hinges: a :class:`~seisrack.analysis.hinges.HingeResponse` (``RackResponse.hinges``).
    which: hinge indices or labels (``"base U2"``); default the most-demanded connector and
        base plate (:func:`default_hinges`).
    ax: matplotlib Axes to draw into (default: a new figure's). label: prefix of the legend
        entries (e.g. ``"seisrack"``, ``"OpenSees"``, to overlay two runs on one Axes); each
        line is labelled ``"{label}: {hinge}"`` (or the hinge's label alone).
    style: passed to ``Axes.plot`` (``color``, ``linestyle``, ``linewidth``, ...).

    Returns the Axes. Never calls ``show()``.
    """
    if hinges is None:
        raise InputError("hinges", None, "a HingeResponse (RackResponse.hinges of a run with "
                         "nonlinear connections)")
    rot = np.asarray(hinges.rotation, dtype=float)
    mom = np.asarray(hinges.moment, dtype=float)
    if rot.ndim != 2 or rot.shape != mom.shape or rot.shape[1] != len(hinges.labels):
        raise InputError("hinges", f"rotation {rot.shape}, moment {mom.shape}, "
                         f"{len(hinges.labels)} labels", "(n_t, n_h) rotation and moment "
                         "histories and one label per hinge")
    sel = _select(hinges, which)
    if ax is None:
        import matplotlib.pyplot as plt

        _fig, ax = plt.subplots(figsize=(6.0, 4.5))
    for i in sel:
        name = hinges.labels[i]
        ax.plot(1e3 * rot[:, i], 1e-3 * mom[:, i],
                label=f"{label}: {name}" if label else name, **style)
    ax.set_xlabel("rotation [mrad]")
    ax.set_ylabel("moment [kN·m]")
    ax.axhline(0.0, color="0.6", linewidth=0.5)
    ax.axvline(0.0, color="0.6", linewidth=0.5)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small")
    return ax


#: file names written by :func:`save_hinge_figures` (only for a run with nonlinear connections)
HINGE_FIGURES = ("hinge_loops.png",)
#: hinges drawn per panel of :func:`hinge_loops_figure` (the most demanded of each kind)
LOOPS_PER_PANEL = 4


def most_demanded(hinges: Any, kind: str, n: int = LOOPS_PER_PANEL) -> list[int]:
    """Indices of the (at most ``n``) hinges of ``kind`` with the largest peak |rotation| /
    yield rotation (|rotation| for an elastic hinge), most demanded first."""
    rot = np.abs(np.asarray(hinges.rotation, dtype=float))
    peak = rot.max(axis=0) if rot.shape[0] else np.zeros(rot.shape[1])
    ty = np.asarray(hinges.yield_rotation, dtype=float)
    demand = np.where(np.isfinite(ty) & (ty > 0), peak / np.where(ty > 0, ty, 1.0), peak)
    idx = [i for i, k in enumerate(hinges.kind) if k == kind]
    return sorted(idx, key=lambda i: (-demand[i], i))[:n]


def hinge_loops_figure(hinges: Any, n: int = LOOPS_PER_PANEL, title: str | None = None) -> Any:
    """A figure of moment–rotation loops: one panel for the connectors and one for the base
    plates (those that exist), each with its ``n`` most-demanded hinges
    (:func:`most_demanded`). title: a first line above the figure's own. Returns the Figure
    (never shown)."""
    import matplotlib.pyplot as plt

    kinds = [k for k in ("connector", "base") if k in hinges.kind]
    fig, axes = plt.subplots(1, len(kinds), figsize=(5.2 * len(kinds), 4.2), squeeze=False)
    ty = np.asarray(hinges.yield_rotation, dtype=float)
    for ax, kind in zip(axes[0], kinds, strict=True):
        sel = most_demanded(hinges, kind, n)
        plot_hinge_loops(hinges, sel, ax=ax, linewidth=0.8)
        n_kind = sum(k == kind for k in hinges.kind)
        what = "beam-to-upright connectors" if kind == "connector" else "base plates"
        more = f" ({len(sel)} most demanded of {n_kind})" if len(sel) < n_kind else ""
        ax.set_title(f"{what}{more}", fontsize=9)
        for c, i in enumerate(sel):  # a yielded elastic-plastic hinge: its plateau, dashed
            th = np.abs(np.asarray(hinges.rotation, dtype=float)[:, i])
            if hinges.law[i] == "elastic-plastic" and th.size and th.max() > ty[i]:
                my = 1e-3 * float(np.max(np.abs(np.asarray(hinges.moment)[:, i])))
                ax.axhline(my, color=f"C{c}", ls="--", lw=0.6)
                ax.axhline(-my, color=f"C{c}", ls="--", lw=0.6)
    head = "Moment–rotation of the connections (rotation from the zero-moment state, " \
           "gravity included; dashed: yield moment of a yielded elastic-plastic hinge)"
    fig.suptitle(f"{title}\n{head}" if title else head, fontsize=9)
    fig.tight_layout()
    return fig


def save_hinge_figures(resp: Any, out_dir: Any, *, suptitle: str | None = None) -> list[Any]:
    """Write :data:`HINGE_FIGURES` into ``out_dir`` when ``resp`` has nonlinear connections
    (``resp.hinges``); nothing (an empty list) otherwise. Returns the paths written."""
    from pathlib import Path

    import matplotlib.pyplot as plt

    if getattr(resp, "hinges", None) is None:
        return []
    fig = hinge_loops_figure(resp.hinges, title=suptitle)
    path = Path(out_dir) / HINGE_FIGURES[0]
    save_figure(fig, path, dpi=120)
    plt.close(fig)
    return [path]
