"""Figures of a rack time history, like the paper's Fig. 16a–d (§IV.B).

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
        return f"pallet {resp.pallet_labels()[pallet]}"
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
        plot_rack_history(resp, "pallet_sliding", ax, pallet=j, label=labels[j],
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
