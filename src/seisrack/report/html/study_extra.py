"""Sections of the study report for issue 24: the sliding reduction, the risk per year and the
warehouse.

Built from the study's ``summary.json`` (``groups[i].sliding_reduction``, ``risk``,
``warehouse``); every number cell carries its value and its place there (``data-path``), as the
rest of the page.
"""

from __future__ import annotations

from typing import Any

from seisrack.report.html import figures as F
from seisrack.report.html.page import _figure
from seisrack.report.html.study_page import _cell, _table
from seisrack.report.html.tables import esc

G = 9.80665  # [m/s²]
_Q = ("base_shear", "connector_moment", "upright_moment")


def reduction_section(summary: dict[str, Any], number: int) -> str:
    """``<section id="sliding-reduction">`` or "" when no group has rigid companions."""
    from seisrack.report.sliding_reduction_plot import plot_sliding_reduction

    parts = []
    for gi, g in enumerate(summary.get("groups", [])):
        red = g.get("sliding_reduction")
        if not red:
            continue
        rows = []
        for ri, row in enumerate(red["rows"]):
            base = ["groups", gi, "sliding_reduction", "rows", ri]
            cells = (_cell(base + ["im"], row["im"], 1 / G, "{:.3f}")
                     + _cell(base + ["mu_static"], row["mu_static"], 1, "{:.3g}")
                     + f"<td>{row['n']}</td>"
                     + _cell(base + ["alpha_mean"], row["alpha_mean"], 1, "{:.3f}"))
            for q in _Q:
                cells += (_cell(base + [q, "mean"], row[q]["mean"], 1, "{:.3f}")
                          + _cell(base + [q, "beta"], row[q]["beta"], 1, "{:.3f}"))
            rows.append(f"<tr>{cells}</tr>")
        heads = ["IM [g]", "μ", "runs", "α mean"]
        for q in _Q:
            heads += [f"{q.replace('_', ' ')}: mean", "β"]
        nom = red["code_nominal"]
        ax = plot_sliding_reduction(red["points"], nom["down-aisle"])
        parts.append(
            f"<h3>{esc(g['rack'])}, IM = {esc(g['im_measure'])}</h3>"
            + _table(f"table-sliding-reduction-{gi}", heads, rows,
                     "Peak with sliding pallets over the peak of the same record and intensity "
                     "with the pallets held rigidly: mean and lognormal dispersion β = std(ln "
                     "ratio) over the runs; α = rigid peak level acceleration / g.")
            + f"<p>The code's unit-load factors assume E_D1·E_D2·E_D3 = "
              f"{nom['down-aisle']:.3f} down-aisle (E_D1 = {nom['e_d1']:g}, E_D2 = "
              f"{nom['e_d2_down_aisle']:g}, E_D3 = {nom['e_d3']:g}; placeholders marked as "
              "assumptions, docs/user/design_analysis.md).</p>"
            + _figure(f"fig-sliding-reduction-{gi}", F.png_data_uri(ax.figure),
                      "Each run's ratio (sliding / rigid) against μ/α, with the pallet force "
                      "cap min(1, μ/α) and the code's assumed reduction (dashed)."))
    if not parts:
        return ""
    return (f'<section id="sliding-reduction"><h2>{number}. The reduction sliding really '
            "gives</h2>" + "".join(parts) + "</section>")


def risk_section(summary: dict[str, Any], number: int) -> str:
    """``<section id="risk">`` or "" without a hazard curve (``study summary --hazard``)."""
    from seisrack.report.risk_plot import plot_risk

    risk = summary.get("risk")
    if not risk:
        return ""
    rows = []
    for i, f in enumerate(risk["fragilities"]):
        base = ["risk", "fragilities", i]
        rows.append(f"<tr><td>{esc(f['name'])}</td><td>{esc(f['analysis'])}</td>"
                    + _cell(base + ["theta_m_s2"], f["theta_m_s2"], 1 / G, "{:.3f}")
                    + _cell(base + ["beta"], f["beta"], 1, "{:.3f}")
                    + _cell(base + ["annual_rate"], f["annual_rate"], 1, "{:.3e}")
                    + _cell(base + ["return_period_yr"], f["return_period_yr"], 1, "{:.4g}")
                    + _cell(base + ["p50"], f["p50"], 100, "{:.3f}") + "</tr>")
    ref = risk.get("reference")
    if ref:
        base = ["risk", "reference"]
        rows.append(f"<tr><td>{esc(ref['name'])} (outside reference)</td><td>–</td>"
                    + _cell(base + ["theta_m_s2"], ref["theta_m_s2"], 1 / G, "{:.3f}")
                    + _cell(base + ["beta"], ref["beta"], 1, "{:.3f}")
                    + _cell(base + ["annual_rate"], ref["annual_rate"], 1, "{:.3e}")
                    + _cell(base + ["return_period_yr"], ref["return_period_yr"], 1, "{:.4g}")
                    + _cell(base + ["p50"], ref["p50"], 100, "{:.3f}") + "</tr>")
    ax = plot_risk(risk)
    src = f" Reference: {esc(ref['source'])}." if ref else ""
    given = esc(risk["units_given"]) + (f"; {esc(risk['source'])}" if risk["source"] else "")
    return (f'<section id="risk"><h2>{number}. Risk per year</h2>'
            f"<p>Site hazard curve {esc(risk.get('file', ''))} ({esc(risk['measure'].upper())}, "
            f"given in {given}). λ = ∫ H(x) f(x) dx with H interpolated log-log; P in "
            f"{risk['years']:g} years = 1 − exp(−{risk['years']:g} λ).{src}</p>"
            + _table("table-risk", ["damage state", "analysis", "θ [g]", "β", "λ [1/yr]",
                                    "return period [yr]", f"P in {risk['years']:g} yr [%]"],
                     rows, "Mean annual frequency of each fitted fragility on the site's "
                           "hazard curve.")
            + _figure("fig-risk", F.png_data_uri(ax.figure),
                      "Site hazard curve (left axis, log scale) and the fitted fragilities "
                      "(right axis) with the FEMA P-58 storage-rack fragility (dashed), "
                      "against the intensity [m/s²].")
            + "</section>")


def warehouse_section(summary: dict[str, Any], number: int) -> str:
    """``<section id="warehouse">`` or "" for a study of racks (``warehouse = ...``)."""
    wh = summary.get("warehouse")
    if not wh:
        return ""
    rows = []
    for li, lv in enumerate(wh["levels"]):
        for gi, g in enumerate(lv["groups"]):
            base = ["warehouse", "levels", li, "groups", gi]
            rows.append("<tr>" + (_cell(["warehouse", "levels", li, "im"], lv["im"], 1 / G,
                                        "{:.3f}") if gi == 0 else "<td></td>")
                        + f"<td>{esc(g['group'])}</td><td>{g['rows']}</td><td>{g['runs']}</td>"
                        + _cell(base + ["mean_per_row"], g["mean_per_row"], 1, "{:.3g}")
                        + _cell(base + ["p_row_loses_a_pallet"], g["p_row_loses_a_pallet"], 1,
                                "{:.2f}")
                        + _cell(base + ["expected"], g["expected"], 1, "{:.3g}")
                        + f"<td>{esc(g['what'])}</td></tr>")
        rows.append("<tr class=\"total\"><td></td><td>warehouse</td><td></td><td></td><td></td>"
                    "<td></td>" + _cell(["warehouse", "levels", li, "expected_falls"],
                                        lv["expected_falls"], 1, "{:.3g}")
                    + f"<td>driven by {esc(', '.join(lv['driven_by']) or 'no group')}</td></tr>")
    per_year = wh.get("per_year") or {}
    year = ""
    if per_year.get("expected_per_year") is not None:
        year = (f"<p>On the site hazard curve: <b>{per_year['expected_per_year']:.3g}</b> falling "
                f"pallets per year ({per_year['expected_in_50_years']:.3g} in 50 years), each "
                "stripe standing for the intensities between the geometric midpoints to its "
                f"neighbours; {100 * per_year['top_bin_share']:.0f} % comes from motions "
                "stronger than the highest stripe's bin, counted at the highest stripe "
                "(FEMA P-58-1 §8.2).</p>")
    figs = ""
    path = wh.get("path")
    if path:
        from seisrack.studies.warehouse_summary import plan_axes

        for li, ax in enumerate(plan_axes(wh, path)):
            figs += _figure(f"fig-warehouse-{li}", F.png_data_uri(ax.figure),
                            f"Plan at IM {wh['levels'][li]['im'] / G:.3f} g: each row coloured "
                            "by the probability that it loses a pallet (arrow: down-aisle).")
    return (f'<section id="warehouse"><h2>{number}. The warehouse</h2>'
            f"<p>{wh['n_rows']} rows, {wh['n_pallets']} pallets ({esc(wh.get('file', ''))}). "
            "Identical rows see the same motion; a group's expected falls are its number of "
            "rows times the mean over the runs of the level. A 3D row counts the pallets "
            "falling into an aisle; a 2D row, which has no cross-aisle, the pallets whose "
            "down-aisle sliding reached their free distance.</p>"
            + _table("table-warehouse", ["IM [g]", "group", "rows", "runs", "falls per row",
                                         "P(row loses a pallet)", "expected falls", "what"],
                     rows, "Expected number of falling pallets per intensity level.")
            + year + figs + "</section>")
