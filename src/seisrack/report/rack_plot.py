"""Figures of a rack time history (2D or 3D), like the paper's Fig. 16a–d (§IV.B).

Fig. 16a: horizontal displacement of the beam (relative to the ground); 16b: horizontal
(absolute) acceleration of the beam; 16c: total horizontal contact force between the beam and
the pallets; 16d: sliding of a pallet relative to its beam. The paper overlays the runs for
μ = 0.80, 0.75, 0.60 and 0.30 on each panel: :func:`plot_rack_histories` does the same for any
mapping ``label -> RackResponse``.

matplotlib is imported lazily; every function takes ``ax=None`` and returns the Axes; nothing here
calls ``show()``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from seisrack.analysis.rack import RackResponse
from seisrack.report.hinge_plot import HINGE_FIGURES, save_hinge_figures
from seisrack.report.motion_plot import _axes, save

# quantity -> (attribute, per, scale to the plotted unit, axis label, title, figure name)
_QUANTITIES: dict[str, tuple[str, str, float, str, str, str]] = {
    "beam_displacement": ("beam_displacement", "level", 1e3,
                          "beam displacement [mm]",
                          "Horizontal displacement of the beam relative to the ground",
                          "fig16a_displacement"),
    "beam_acceleration": ("beam_acceleration", "level", 1.0,
                          "beam acceleration [m/s²]",
                          "Horizontal (absolute) acceleration of the beam",
                          "fig16b_acceleration"),
    "contact_force": ("contact_force", "total", 1e-3,
                      "total contact force [kN]",
                      "Total horizontal contact force between beams and pallets",
                      "fig16c_contact_force"),
    "pallet_sliding": ("pallet_sliding", "pallet", 1e3,
                       "pallet sliding [mm]",
                       "Sliding of a pallet relative to its beam",
                       "fig16d_sliding"),
    "base_shear": ("base_shear", "none", 1e-3, "base shear [kN]", "Base shear", "base_shear"),
    "ground_accel": ("ground_accel", "none", 1.0, "ground acceleration [m/s²]",
                     "Horizontal ground acceleration", "ground_accel"),
    "pallet_friction": ("pallet_friction", "pallet", 1e-3, "friction force on pallet [kN]",
                        "Horizontal force of the beam on a pallet", "pallet_friction"),
}
_ALIASES = {"16a": "beam_displacement", "16b": "beam_acceleration", "16c": "contact_force",
            "16d": "pallet_sliding", "displacement": "beam_displacement",
            "acceleration": "beam_acceleration", "sliding": "pallet_sliding",
            "force": "contact_force"}
#: the four panels of Fig. 16, in order
FIG16 = ("beam_displacement", "beam_acceleration", "contact_force", "pallet_sliding")


def quantities() -> list[str]:
    """Names accepted by :func:`rack_history` (aliases: ``16a``…``16d``)."""
    return list(_QUANTITIES)


def _key(quantity: str) -> str:
    key = _ALIASES.get(quantity, quantity)
    if key not in _QUANTITIES:
        from seisrack.errors import InputError

        raise InputError("quantity", quantity, ", ".join([*_QUANTITIES, *_ALIASES]))
    return key


def rack_history(
    resp: RackResponse, quantity: str, *, level: int | None = None, pallet: int = 0
) -> tuple[np.ndarray, np.ndarray, str]:
    """(t [s], values in the plotted unit, axis label) of one quantity of ``resp``.

    level: 0-based beam level for per-level quantities (default: the top level).
    pallet: 0-based pallet for per-pallet quantities.
    """
    attr, per, scale, ylabel, _, _ = _QUANTITIES[_key(quantity)]
    arr = np.asarray(getattr(resp, attr))
    if per == "level":
        y = arr[:, arr.shape[1] - 1 if level is None else level]
    elif per == "total":
        y = arr.sum(axis=1)
    elif per == "pallet":
        if not 0 <= pallet < resp.n_pallets:
            from seisrack.errors import InputError

            raise InputError("pallet", pallet, f"0 .. {resp.n_pallets - 1}")
        y = arr[:, pallet]
    else:
        y = arr
    return resp.t, y * scale, ylabel


def _describe(resp: RackResponse, key: str, level: int | None, pallet: int) -> str:
    per = _QUANTITIES[key][1]
    if per == "level":
        n = resp.beam_displacement.shape[1]
        return f"beam level {(n - 1 if level is None else level) + 1}"
    if per == "pallet":
        return f"pallet {pallet + 1} ({resp.pallet_labels()[pallet]})"
    if per == "total":
        return "sum over all pallets"
    return ""


def plot_rack_history(
    resp: RackResponse, quantity: str, ax: Any = None, *, level: int | None = None,
    pallet: int = 0, label: str | None = None, **line_kw: Any,
) -> Any:
    """One quantity of one run against time. Returns the Axes."""
    key = _key(quantity)
    ax = _axes(ax)
    t, y, ylabel = rack_history(resp, key, level=level, pallet=pallet)
    ax.plot(t, y, lw=line_kw.pop("lw", 0.8), label=label, **line_kw)
    ax.set_xlabel("time [s]")
    ax.set_ylabel(ylabel)
    what = _describe(resp, key, level, pallet)
    ax.set_title(f"{_QUANTITIES[key][4]}" + (f" ({what})" if what else ""), fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.axhline(0.0, color="k", lw=0.4)
    return ax


def plot_rack_histories(
    responses: Mapping[str, RackResponse], quantity: str, ax: Any = None, *,
    level: int | None = None, pallet: int = 0, caps: bool = True,
) -> Any:
    """Overlay one quantity of several runs (e.g. ``{"μ = 0.80": r80, "μ = 0.30": r30}``), as
    each panel of the paper's Fig. 16 does. Returns the Axes.

    quantity: ``beam_displacement`` (16a), ``beam_acceleration`` (16b), ``contact_force`` (16c),
        ``pallet_sliding`` (16d), or ``base_shear``, ``ground_accel``, ``pallet_friction``.
    caps: for ``contact_force``, draw the sliding cap ±Σ μd·m·g of each run as dashed lines
        (the force cannot exceed it while every pallet slides, paper §IV.B).
    """
    key = _key(quantity)
    ax = _axes(ax)
    import matplotlib.pyplot as plt

    colors = plt.rcParams["axes.prop_cycle"].by_key().get("color", ["C0"])
    # draw the largest response first so that smaller ones stay visible on top
    order = sorted(responses.items(),
                   key=lambda kv: -float(np.max(np.abs(
                       rack_history(kv[1], key, level=level, pallet=pallet)[1]), initial=0.0)))
    index = {lab: i for i, lab in enumerate(responses)}
    for lab, resp in order:
        c = colors[index[lab] % len(colors)]
        plot_rack_history(resp, key, ax, level=level, pallet=pallet, label=lab, color=c)
        if caps and key == "contact_force" and resp.n_pallets:
            cap = float(np.sum(resp.pallet_mu_dynamic * resp.pallet_mass)) * resp.g * 1e-3
            ax.axhline(cap, color=c, ls="--", lw=0.7)
            ax.axhline(-cap, color=c, ls="--", lw=0.7)
    if len(responses) > 1 or any(lab for lab in responses):
        ax.legend(fontsize=8, loc="upper right")
    if caps and key == "contact_force":
        ax.set_title(ax.get_title() + "\ndashed: μd·M·g, the cap when all pallets slide",
                     fontsize=10)
    return ax


def plot_pallet_sliding(
    resp: RackResponse, ax: Any = None, *, pallets: Sequence[int] | None = None,
    limits: bool = True,
) -> Any:
    """Sliding of every pallet (or of ``pallets``, 0-based) with their fall limits dashed."""
    ax = _axes(ax)
    sel = list(range(resp.n_pallets)) if pallets is None else list(pallets)
    labels = resp.pallet_labels()
    for j in sel:
        plot_rack_history(resp, "pallet_sliding", ax, pallet=j, label=f"{j + 1} {labels[j]}",
                          color=f"C{j % 10}")
        if limits:
            ax.axhline(resp.pallet_limit_pos[j] * 1e3, color=f"C{j % 10}", ls="--", lw=0.7)
            ax.axhline(-resp.pallet_limit_neg[j] * 1e3, color=f"C{j % 10}", ls="--", lw=0.7)
    ax.set_title("Sliding of the pallets relative to their beams"
                 + ("\ndashed: free distance before a pallet falls" if limits else ""),
                 fontsize=10)
    if sel:
        ax.legend(fontsize=7, loc="upper right")
    return ax


def save_fig16(
    responses: RackResponse | Mapping[str, RackResponse], out_dir: str | Path, *,
    level: int | None = None, pallet: int = 0, suptitle: str | None = None,
) -> list[Path]:
    """Write ``fig16a_displacement.png`` … ``fig16d_sliding.png`` into ``out_dir``.

    A single response draws every pallet (with its fall limits) in 16d; a mapping of responses
    is overlaid on each panel, with pallet ``pallet`` in 16d, as in the paper.
    """
    out = Path(out_dir)
    single = isinstance(responses, RackResponse)
    runs = {"": responses} if single else dict(responses)
    paths = []
    for key in FIG16:
        ax = _axes(None)
        ax.figure.set_size_inches(7.0, 3.4)
        if key == "pallet_sliding" and single:
            if responses.n_pallets:
                plot_pallet_sliding(responses, ax)
            else:
                ax.set_title("no pallets")
        elif key == "pallet_sliding" and not any(r.n_pallets for r in runs.values()):
            ax.set_title("no pallets")
        else:
            plot_rack_histories(runs, key, ax, level=level, pallet=pallet)
        if suptitle:
            ax.figure.suptitle(suptitle, fontsize=9)
        path = out / f"{_QUANTITIES[key][5]}.png"
        save(ax, str(path))
        paths.append(path)
    return paths


#: file names written by :func:`save_fig16`
FIG16_FILES = tuple(f"{_QUANTITIES[k][5]}.png" for k in FIG16)


# ------------------------------------------------------------------ the user's rack (issue 14)
#: file names written by :func:`save_rack_figures`, named after what they show (a rack with
#: two horizontal directions adds the plan view ``sliding_paths.png``)
RACK_FIGURES = ("beam_displacement.png", "beam_acceleration.png", "contact_force.png",
                "pallet_sliding.png", "sliding_heatmap.png")
#: the directions' names in titles
_DIRECTION_TITLE = ("down-aisle", "cross-aisle")


def _level_colours(n: int) -> list[Any]:
    import matplotlib

    cmap = matplotlib.colormaps["viridis"]
    return [cmap(0.9 * i / max(n - 1, 1)) for i in range(n)]


def _level_legend_or_bar(ax: Any, n: int, max_legend: int = 8) -> None:
    """A legend for a few levels, a discrete colour bar of level numbers for many."""
    if n <= max_legend:
        ax.legend(fontsize=7, loc="upper right", ncol=1 if n <= 4 else 2)
        return
    import matplotlib as mpl

    norm = mpl.colors.BoundaryNorm(np.arange(0.5, n + 1.5), n)
    sm = mpl.cm.ScalarMappable(norm=norm, cmap=mpl.colors.ListedColormap(_level_colours(n)))
    ax.figure.colorbar(sm, ax=ax, label="beam level", ticks=range(1, n + 1, max(1, n // 10)))


def plot_levels(resp: RackResponse, quantity: str, ax: Any = None, *, direction: int = 0
                ) -> Any:
    """A per-level history (``beam_displacement``, ``beam_acceleration`` (raw) or
    ``beam_acceleration_filtered``, ``contact_force``) of every level along ``direction``
    (0 down-aisle, 1 cross-aisle), coloured by level."""
    ax = _axes(ax)
    scale, unit, title = {
        "beam_displacement": (1e3, "beam displacement [mm]",
                              "Horizontal displacement of each beam level (relative to the "
                              "ground)"),
        "beam_acceleration": (1.0, "beam acceleration [m/s²]",
                              "Absolute acceleration of each beam level (raw)"),
        "beam_acceleration_filtered": (
            1.0, "beam acceleration [m/s²]",
            f"Absolute acceleration of each beam level, low-pass "
            f"{resp.acceleration_filter_hz:g} Hz"),
        "contact_force": (1e-3, "contact force [kN]",
                          "Horizontal contact force of the beams on the pallets, per level"),
    }[quantity]
    arr = resp.directional(quantity)[..., direction]
    n = arr.shape[1]
    if resp.n_dir > 1:
        title = f"{title} [{_DIRECTION_TITLE[direction]}]"
    for lv, c in enumerate(_level_colours(n)):
        ax.plot(resp.t, arr[:, lv] * scale, lw=0.7, color=c, label=f"level {lv + 1}")
    ax.set_xlabel("time [s]")
    ax.set_ylabel(unit)
    ax.set_title(title, fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.axhline(0.0, color="k", lw=0.4)
    _level_legend_or_bar(ax, n)
    return ax


def plot_all_pallet_sliding(resp: RackResponse, ax: Any = None, *, direction: int = 0) -> Any:
    """Sliding history of every pallet along ``direction``, coloured by its level (a colour
    bar, no legend), with the smallest free distance (down-aisle) or the smallest fall limits
    (cross-aisle) dashed."""
    ax = _axes(ax)
    n = resp.beam_displacement.shape[1]
    cols = _level_colours(n)
    sliding = resp.directional("pallet_sliding")[..., direction]
    for j in range(resp.n_pallets):
        ax.plot(resp.t, sliding[:, j] * 1e3, lw=0.6, color=cols[int(resp.pallet_level[j])],
                label=f"level {int(resp.pallet_level[j]) + 1}")
    pos, neg = ((resp.pallet_limit_pos, resp.pallet_limit_neg) if direction == 0 else
                (resp.fall_rear, resp.fall_front))
    lim_p = float(np.nanmin(pos, initial=np.inf))
    lim_n = float(np.nanmin(neg, initial=np.inf))
    if np.isfinite(lim_p) and np.isfinite(lim_n):
        ax.axhline(lim_p * 1e3, color="r", ls="--", lw=0.7)
        ax.axhline(-lim_n * 1e3, color="r", ls="--", lw=0.7)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("pallet sliding [mm]")
    what = ("smallest free distance (neighbour or upright)" if direction == 0 else
            "smallest fall limits (front -, rear +)")
    where = f" [{_DIRECTION_TITLE[direction]}]" if resp.n_dir > 1 else ""
    ax.set_title(f"Sliding of the {resp.n_pallets} pallets relative to their beams{where}, "
                 f"coloured by level\ndashed: {what}", fontsize=10)
    ax.grid(True, alpha=0.3)
    if n <= 8:  # one legend entry per level
        handles, labels = ax.get_legend_handles_labels()
        seen = dict(zip(labels, handles, strict=True))
        ax.legend(seen.values(), seen.keys(), fontsize=7, loc="upper right")
    else:
        _level_legend_or_bar(ax, n)
    return ax


def sliding_grid(resp: RackResponse) -> tuple[np.ndarray, np.ndarray, int]:
    """(n_level, n_bay·n_slot) grids of peak sliding [m] and of pallet id (0 = empty cell),
    rows = levels bottom to top, columns = (bay, slot) left to right; and n_slot."""
    n_level = resp.beam_displacement.shape[1]
    bay, slot = resp._bay(), resp._slot()
    n_bay = int(bay.max()) + 1 if resp.n_pallets else 1
    n_slot = int(slot.max()) + 1 if resp.n_pallets else 1
    val = np.full((n_level, n_bay * n_slot), np.nan)
    ids = np.zeros((n_level, n_bay * n_slot), dtype=int)
    peak = resp.pallet_peak_sliding()
    for j in range(resp.n_pallets):
        r, c = int(resp.pallet_level[j]), int(bay[j]) * n_slot + int(slot[j])
        val[r, c] = peak[j]
        ids[r, c] = j + 1
    return val, ids, n_slot


#: share of the magma_r colour map used by the heat map: its last quarter is near black, which
#: hid the pallet numbers and made a rack whose pallets all slid alike one black block
HEATMAP_CMAP_TOP = 0.75
#: peaks within this fraction of the largest count as "all alike" (said in the title)
HEATMAP_UNIFORM_RTOL = 0.01


def plot_sliding_heatmap(resp: RackResponse, ax: Any = None, *, annotate: int = 80) -> Any:
    """Peak sliding of every pallet on a level × (bay, slot) grid, with a colour bar [mm].

    Cells are labelled with the pallet id when there are at most ``annotate`` pallets, in
    black or white after the cell's lightness so that they stay legible; a pallet whose
    sliding reached its free distance is outlined in red. The colour map stops short of black
    (:data:`HEATMAP_CMAP_TOP`), and when every pallet slid alike the title says so (a uniform
    map is then the truth, not a failure). Returns the Axes.
    """
    import matplotlib
    from matplotlib.colors import ListedColormap, Normalize

    ax = _axes(ax)
    val, ids, n_slot = sliding_grid(resp)
    n_level, n_col = val.shape
    masked = np.ma.masked_invalid(val * 1e3)
    cmap = ListedColormap(matplotlib.colormaps["magma_r"](
        np.linspace(0.0, HEATMAP_CMAP_TOP, 256)))
    vmax = max(float(masked.max()) if masked.count() else 0.0, 1e-3)
    norm = Normalize(vmin=0.0, vmax=vmax)
    im = ax.imshow(masked, origin="lower", aspect="auto", cmap=cmap, norm=norm)
    ax.figure.colorbar(im, ax=ax, label="peak sliding [mm]")
    risk = set(resp.pallets_at_risk()) | {f.pallet + 1 for f in resp.falls}
    for (r, c), pid in np.ndenumerate(ids):
        if pid and pid in risk:
            ax.add_patch(matplotlib.patches.Rectangle(
                (c - 0.5, r - 0.5), 1, 1, fill=False, ec="red", lw=1.5))
        if pid and resp.n_pallets <= annotate:
            red, green, blue, _ = cmap(norm(float(masked[r, c])))
            light = 0.299 * red + 0.587 * green + 0.114 * blue
            ax.text(c, r, str(pid), ha="center", va="center", fontsize=6,
                    color="black" if light > 0.5 else "white")
    n_bay = n_col // n_slot
    for b in range(1, n_bay):
        ax.axvline(b * n_slot - 0.5, color="k", lw=0.6)
    step = max(1, n_bay // 20)
    ax.set_xticks([b * n_slot + (n_slot - 1) / 2 for b in range(0, n_bay, step)])
    ax.set_xticklabels([str(b + 1) for b in range(0, n_bay, step)], fontsize=7)
    ax.set_yticks(range(0, n_level, max(1, n_level // 20)))
    ax.set_yticklabels([str(lv + 1) for lv in range(0, n_level, max(1, n_level // 20))],
                       fontsize=7)
    ax.set_xlabel(f"bay (each split in {n_slot} slot{'s' if n_slot > 1 else ''}, left to right)")
    ax.set_ylabel("beam level")
    title = ("Peak sliding of each pallet (numbers: pallet id; red: reached its free distance"
             + (" or fell" if resp.n_dir > 1 else "") + ")")
    if masked.count():
        lo, hi = float(masked.min()), float(masked.max())
        if hi - lo <= HEATMAP_UNIFORM_RTOL * max(hi, 1e-12):
            title += (f"\nevery pallet slid alike: {hi:.3g} mm" if hi > 1e-9 else
                      "\nno pallet slid")
    ax.set_title(title, fontsize=10)
    return ax


def existing_figures(out_dir: str | Path) -> list[Path]:
    """The seisrack figures (:data:`RACK_FIGURES`, ``sliding_paths.png``,
    ``hinge_loops.png``) already in ``out_dir``."""
    from seisrack.report.sliding_paths import SLIDING_PATHS_FIGURE

    return [Path(out_dir) / f for f in (*RACK_FIGURES, SLIDING_PATHS_FIGURE, *HINGE_FIGURES)
            if (Path(out_dir) / f).exists()]


def _direction_panels(resp: RackResponse, height: float) -> list[Any]:
    """One Axes per horizontal direction, stacked in one figure."""
    axes = [_axes(None)]
    fig = axes[0].figure
    if resp.n_dir > 1:
        fig.clear()
        axes = list(fig.subplots(resp.n_dir, 1, sharex=True))
    fig.set_size_inches(7.5, height * resp.n_dir)
    return axes


def save_rack_figures(resp: RackResponse, out_dir: str | Path, *, model: Any = None,
                      suptitle: str | None = None, force: bool = False) -> list[Path]:
    """Write the figures of the user's rack into ``out_dir``: :data:`RACK_FIGURES` (all levels,
    one panel per horizontal direction), with two directions the plan view
    ``sliding_paths.png`` (needs ``model``), with nonlinear connections ``hinge_loops.png``.

    An existing figure is never overwritten unless ``force``: raises ``InputError`` naming
    ``--force`` before anything is written.
    """
    out = Path(out_dir)
    there = existing_figures(out)
    if there and not force:
        from seisrack.errors import InputError

        raise InputError("--force", False, "--force to overwrite existing figures",
                         hint="These figures exist: " + ", ".join(str(p) for p in there))
    n_level = resp.beam_displacement.shape[1]
    height = 3.4 + 0.12 * max(0, n_level - 4)
    paths = []

    def finish(ax: Any, name: str) -> None:
        if suptitle:
            ax.figure.suptitle(suptitle, fontsize=9)
        save(ax, str(out / name))
        paths.append(out / name)

    filtered = resp.beam_acceleration_filtered is not None
    for name, quantity in ((RACK_FIGURES[0], "beam_displacement"),
                           (RACK_FIGURES[1], "beam_acceleration_filtered" if filtered
                            else "beam_acceleration"),
                           (RACK_FIGURES[2], "contact_force")):
        axes = _direction_panels(resp, height)
        for d, ax in enumerate(axes):
            plot_levels(resp, quantity, ax, direction=d)
            if quantity == "beam_acceleration_filtered":
                raw = float(np.max(np.abs(resp.directional("beam_acceleration")[..., d]),
                                   initial=0.0))
                ax.set_title(ax.get_title() + f"\nraw (unfiltered) peak of the kept samples: "
                             f"{raw:.2f} m/s²", fontsize=10)
        finish(axes[-1], name)
    axes = _direction_panels(resp, height)
    for d, ax in enumerate(axes):
        if resp.n_pallets:
            plot_all_pallet_sliding(resp, ax, direction=d)
        else:
            ax.set_title("no pallets")
    finish(axes[-1], RACK_FIGURES[3])
    ax = _axes(None)
    ax.figure.set_size_inches(7.5, 2.0 + 0.35 * n_level)
    if resp.n_pallets:
        plot_sliding_heatmap(resp, ax)
    else:
        ax.set_title("no pallets")
    finish(ax, RACK_FIGURES[4])
    if resp.n_dir > 1 and model is not None:
        paths.append(_save_plan_view(resp, model, out, suptitle))
    return paths + save_hinge_figures(resp, out, suptitle=suptitle)


def _save_plan_view(resp: RackResponse, model: Any, out: Path, suptitle: str | None) -> Path:
    from seisrack.report.sliding_paths import SLIDING_PATHS_FIGURE, plot_sliding_paths

    fig = plot_sliding_paths(resp, model)
    if suptitle:
        title = fig.get_suptitle()
        fig.suptitle(f"{suptitle}\n{title}" if title else suptitle, fontsize=9)
        fig.tight_layout(rect=(0.0, 0.0, 1.0, 1.0 - 0.65 / fig.get_figheight()))
    from seisrack.atomic import save_figure

    save_figure(fig, out / SLIDING_PATHS_FIGURE, dpi=120)
    import matplotlib.pyplot as plt

    plt.close(fig)
    return out / SLIDING_PATHS_FIGURE
