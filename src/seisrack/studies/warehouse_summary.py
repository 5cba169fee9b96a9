"""The summary of a warehouse study (issue 24 item 4): per intensity level, the expected number
of pallets that fall in the whole warehouse and the rows that drive it.

Every row of a group of identical rows sees the same ground motion (one site, no spatial
variation), so a group's runs are those of its rack at its orientation, and its expectation is
``count × mean over the runs of the level`` (the records, friction samples and occupancies of
the study are equally likely). A 3D row counts the pallets that fall into an aisle (the first
crossing of their overhang); a 2D row, which has no cross-aisle, the pallets whose down-aisle
sliding reached their free distance (a neighbour or an upright), flagged as such.

With a site hazard curve H(x) the expected number of falling pallets per year is
Σ_i E[N | x_i]·Δλ_i, the stripes x_i standing for bins of the intensity whose edges are the
geometric midpoints between stripes (the lowest bin starts one half-step below the lowest
stripe, the highest runs to infinity) and Δλ_i = H(lower edge) − H(upper edge): the
time-based assessment of FEMA P-58-1 (2012, §8.2) with one intensity per hazard interval.
Intensities below the lowest bin count no falls; the highest bin's share is reported, because
it assumes the highest stripe's falls for every stronger motion.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from seisrack.studies.store import STUDY_JSON


def warehouse_groups(out_dir: str | Path) -> dict[str, Any] | None:
    """The ``warehouse`` entry of ``study.json`` (None for a study of racks). A study.json
    that cannot be read gives ``{"unreadable": reason}``: the summary says so (running the
    study again rewrites the file and resumes with nothing to run)."""
    p = Path(out_dir) / STUDY_JSON
    if not p.is_file():
        return None
    try:
        doc = json.loads(p.read_text(encoding="utf-8"))
        wh = doc.get("warehouse")
        if wh is not None and not (isinstance(wh, dict) and isinstance(wh.get("groups"), list)):
            raise ValueError("its 'warehouse' entry is not a table of groups")
    except (OSError, ValueError, AttributeError) as exc:
        return {"unreadable": f"{p} could not be read ({type(exc).__name__}: {exc})"}
    return wh


def warehouse_summary(r: dict[str, np.ndarray], wh: dict[str, Any]) -> dict[str, Any]:
    """Per intensity level: the expected number of falling pallets of each group and of the
    whole warehouse, each group's probability that a row loses a pallet, and the groups ranked
    by their share. ``r``: the run arrays (:func:`seisrack.studies.summary.runs_as_arrays`)."""
    ok = r["status"] == "ok"
    angle = np.nan_to_num(r["angle_deg"], nan=0.0)
    levels = sorted({float(x) for x in r["im_target"][ok]})
    out_levels = []
    for im in levels:
        at = ok & (r["im_target"] == im)
        groups = []
        for g in wh["groups"]:
            sel = at & (r["rack"] == g["rack"]) & (angle == float(g["angle_deg"]))
            n = int(sel.sum())
            falls, anyf = (("n_aisle_fall", "any_aisle_fall") if g["three_d"]
                           else ("n_fall", "any_fall"))
            mean_n = float(np.mean(r[falls][sel])) if n else float("nan")
            p_row = float(np.mean(r[anyf][sel])) if n else float("nan")
            groups.append({"group": g["name"], "rows": g["count"], "runs": n,
                           "what": "falls into an aisle" if g["three_d"] else
                           "down-aisle: reached its free distance (2D row)",
                           "pallets_per_row": g["n_pallets"],
                           "mean_per_row": mean_n, "p_row_loses_a_pallet": p_row,
                           "expected": g["count"] * mean_n})
        total = float(np.nansum([g["expected"] for g in groups]))
        for g in groups:
            g["share"] = (g["expected"] / total) if total > 0 and np.isfinite(g["expected"]) \
                else 0.0
        drivers = [g["group"] for g in sorted(groups, key=lambda g: -np.nan_to_num(
            g["expected"])) if np.nan_to_num(g["expected"]) > 0]
        out_levels.append({"im": im, "expected_falls": total, "groups": groups,
                           "driven_by": drivers})
    return {"file": wh["file"], "title": wh.get("title", ""),
            "n_rows": int(sum(g["count"] for g in wh["groups"])),
            "n_pallets": int(sum(g["count"] * g["n_pallets"] for g in wh["groups"])),
            "levels": out_levels}


def annual_falls(s: dict[str, Any], curve: Any) -> dict[str, Any]:
    """The expected number of falling pallets per year of a :func:`warehouse_summary` on a
    hazard curve (:class:`seisrack.studies.risk.HazardCurve`, the study's measure), per group
    and in total, and the share of the highest bin (module docstring)."""
    im = np.array([lv["im"] for lv in s["levels"]], dtype=float)
    if im.size == 0:
        return {"expected_per_year": None, "note": "no successful runs"}
    lx = np.log(im)
    half = np.diff(lx) / 2.0
    lo_step = half[0] if half.size else np.log(2.0) / 2.0
    edges = np.exp(np.concatenate([[lx[0] - lo_step], lx[:-1] + half, [np.inf]]))
    h = np.array([float(curve(e)) if np.isfinite(e) else 0.0 for e in edges])
    d_lambda = h[:-1] - h[1:]
    names = [g["group"] for g in s["levels"][0]["groups"]]
    per_group = {}
    for j, name in enumerate(names):
        e = np.array([np.nan_to_num(lv["groups"][j]["expected"]) for lv in s["levels"]])
        per_group[name] = float(np.sum(e * d_lambda))
    total_bins = np.array([np.nan_to_num(lv["expected_falls"]) for lv in s["levels"]])
    total = float(np.sum(total_bins * d_lambda))
    top = float(total_bins[-1] * d_lambda[-1] / total) if total > 0 else 0.0
    return {"expected_per_year": total, "per_group": per_group,
            "expected_in_50_years": 50.0 * total,
            "bins": [{"im": float(x), "lower_m_s2": float(lo), "upper_m_s2": float(hi),
                      "annual_frequency": float(dl)}
                     for x, lo, hi, dl in zip(im, edges[:-1], edges[1:], d_lambda,
                                              strict=True)],
            "top_bin_share": top,
            "method": "sum over stripes of E[falls | stripe] x the annual frequency of the "
                      "intensity bin around the stripe (edges at geometric midpoints; FEMA "
                      "P-58-1 2012 section 8.2)"}


def format_warehouse(s: dict[str, Any]) -> list[str]:
    """Text lines of :func:`warehouse_summary`."""
    lines = [f"\nwarehouse {s['title'] or s['file']}: {s['n_rows']} rows, {s['n_pallets']} "
             "pallets; expected number of falling pallets per intensity level"]
    for lv in s["levels"]:
        lines.append(f"  IM {lv['im']:7.3g} m/s²: {lv['expected_falls']:.2f} pallets"
                     + (f", driven by {', '.join(lv['driven_by'][:3])}" if lv["driven_by"]
                        else ""))
        for g in lv["groups"]:
            lines.append(f"    {g['group']:<8} {g['rows']:3d} rows x {g['mean_per_row']:.3g} "
                         f"= {g['expected']:.3g}  (P(row loses a pallet) "
                         f"{g['p_row_loses_a_pallet']:.2f}; {g['what']})")
    per_year = s.get("per_year")
    if per_year and per_year.get("expected_per_year") is not None:
        lines.append(f"  on the hazard curve: {per_year['expected_per_year']:.3g} falling pallets "
                     f"per year ({per_year['expected_in_50_years']:.3g} in 50 years; "
                     f"{100 * per_year['top_bin_share']:.0f} % from above the highest stripe's "
                     "bin, counted at the highest stripe)")
    return lines


def plan_axes(s: dict[str, Any], wh_path: str | None) -> list[Any]:
    """One plan per intensity level, each row coloured by the probability that it loses a
    pallet (matplotlib axes; [] when the warehouse file is gone)."""
    if not wh_path or not Path(wh_path).is_file():
        return []
    import matplotlib

    matplotlib.use("Agg", force=False)

    from seisrack.report.warehouse_plot import plot_warehouse_plan
    from seisrack.studies.warehouse import load_warehouse

    wh = load_warehouse(wh_path)
    axes = []
    for lv in s["levels"]:
        p = {g["group"]: g["p_row_loses_a_pallet"] for g in lv["groups"]}
        values = {(row.name, i): p[row.name] for row in wh.rows for i in range(row.count)
                  if np.isfinite(p.get(row.name, np.nan))}
        ax = plot_warehouse_plan(wh, values, label="P(the row loses a pallet)")
        ax.set_title(f"{wh.title or 'warehouse'}: IM {lv['im']:.3g} m/s², expected "
                     f"{lv['expected_falls']:.2f} falling pallets", fontsize="small")
        axes.append(ax)
    return axes


def plan_figures(folder: Path, s: dict[str, Any], wh_path: str | None) -> dict[str, str]:
    """The plans of :func:`plan_axes` as ``warehouse_plan_<k>.png``."""
    import matplotlib.pyplot as plt

    from seisrack.atomic import save_figure

    files = {}
    for k, ax in enumerate(plan_axes(s, wh_path)):
        path = folder / f"warehouse_plan_{k}.png"
        save_figure(ax.figure, path, dpi=110, bbox_inches="tight")
        plt.close(ax.figure)
        files[f"warehouse_plan_{k}"] = str(path)
    return files
