"""Assemble the report's HTML text (sections, figures, tables)."""

from __future__ import annotations

from typing import Any

import numpy as np

from seisrack import __version__
from seisrack.report.html import figures as F
from seisrack.report.html.connections import connections_html
from seisrack.report.html.style import CSS
from seisrack.report.html.tables import (
    esc,
    generic_tables,
    level_table,
    num_cell,
    pallet_table,
    peaks_table,
)

#: pallets shown in the sliding time history (the worst ones)
N_WORST = 5
#: summary keys shown by dedicated sections (anything else gets a generic table)
KNOWN_KEYS = {"record", "g_m_s2", "dt_s", "duration_s", "status", "peaks", "sliding_occurred",
              "pallets_at_risk", "pallets", "simplified_check", "n_events", "n_slip_events",
              "energy_balance_error", "rack", "title", "integration", "basis", "scaling",
              "outputs", "design_checks", "modal", "report", "seed", "hinges", "warnings"}


def _figure(fig_id: str, src: str, caption: str) -> str:
    return (f'<figure id="{fig_id}"><img src="{src}" alt="{esc(caption)}">'
            f"<figcaption>{esc(caption)}</figcaption></figure>")


def _plotly_available() -> bool:
    try:
        import plotly  # noqa: F401
    except ImportError:
        return False
    return True


def _histories(response: Any) -> list[tuple[str, str, np.ndarray, dict[str, np.ndarray]]]:
    t = np.asarray(response.t)
    top = np.asarray(response.beam_displacement)[:, -1] * 1e3
    series = [("Top beam level: displacement relative to the ground", "displacement [mm]", t,
               {"top level": top}),
              ("Base shear (sum of the support reactions)", "base shear [kN]", t,
               {"base shear": np.asarray(response.base_shear) / 1e3})]
    if response.n_pallets:
        worst = np.argsort(-response.pallet_peak_sliding())[:N_WORST]
        series.append((f"Sliding of the {len(worst)} pallets that slid most, relative to the "
                       "beam", "sliding [mm]", t,
                       {f"pallet {j + 1}": np.asarray(response.pallet_sliding)[:, j] * 1e3
                        for j in worst}))
    return series


def _history_html(response: Any, interactive: bool) -> tuple[str, str]:
    """(head script, body html) of the time-history section."""
    series = _histories(response)
    cap = ("Time histories [s]: top-level displacement [mm], base shear [kN] and the sliding "
           f"[mm] of the {N_WORST} pallets that slid most (kept samples of the run).")
    if not interactive:
        return "", _figure("fig-histories", F.png_data_uri(F.plot_histories_static(series)), cap)
    import plotly.graph_objects as go
    from plotly.offline import get_plotlyjs

    divs = []
    for k, (title, unit, t, lines) in enumerate(series):
        fig = go.Figure()
        for name, y in lines.items():
            fig.add_trace(go.Scatter(x=t, y=y, mode="lines", name=name, line={"width": 1}))
        fig.update_layout(title=title, xaxis_title="time [s]", yaxis_title=unit, height=320,
                          margin={"l": 60, "r": 20, "t": 40, "b": 45}, template="plotly_white")
        divs.append(fig.to_html(full_html=False, include_plotlyjs=False, div_id=f"plot-{k}",
                                config={"displaylogo": False, "responsive": True}))
    head = f"<script>{get_plotlyjs()}</script>"
    body = (f'<figure id="fig-histories" class="plotly-figure">{"".join(divs)}'
            f"<figcaption>{esc(cap)} Interactive: zoom with the mouse, double-click to reset."
            "</figcaption></figure>")
    return head, body


def _inputs(spec: Any, record: Any, summary: dict[str, Any], rack_file: str | None,
            seed: int | None, date: str, response: Any) -> str:
    items = [("rack file", rack_file or summary.get("rack", "–")),
             ("rack", getattr(spec, "title", "") or "–"),
             ("record", f"{record.name}: {record.n} samples, dt {record.dt:g} s, "
                        f"PGA {record.pga:.4g} m/s² = {record.pga / 9.80665:.3f} g")]
    sc = summary.get("scaling")
    items.append(("scaling", ", ".join(f"{k} = {v}" for k, v in sc.items())
                  if isinstance(sc, dict) else "none (record as given)"))
    items += [("seed", "none" if seed is None else str(seed)),
              ("analysis", f"dt {response.dt:g} s, {summary.get('duration_s', 0):.2f} s, "
                           f"status {summary.get('status')}, "
                           f"{summary.get('integration', '')} integration"),
              ("seisrack version", __version__), ("date", date)]
    return '<dl class="inputs">' + "".join(f"<dt>{esc(k)}</dt><dd>{esc(v)}</dd>"
                                           for k, v in items) + "</dl>"


def _modal_html(model: Any, modal: Any) -> str:
    rows = []
    for k in range(modal.n_modes):
        rows.append(f"<tr><td>{k + 1}</td>" + num_cell(float(modal.periods[k]), 1, "{:.4f}")
                    + num_cell(float(modal.frequencies[k]), 1, "{:.3f}")
                    + num_cell(float(modal.gamma_x[k]), 1, "{:.4g}")
                    + num_cell(float(modal.mass_participation[k]) * 100, 1, "{:.2f}")
                    + num_cell(float(np.sum(modal.mass_participation[:k + 1])) * 100, 1,
                               "{:.2f}") + "</tr>")
    tab = ('<table id="table-modal"><caption>Natural modes with the pallets rigidly held: '
           "period, frequency, horizontal participation factor Γ and effective mass share."
           "</caption><thead><tr><th>mode</th><th>period T [s]</th><th>frequency [Hz]</th>"
           "<th>Γx [kg^0.5]</th><th>horizontal mass [%]</th><th>cumulative [%]</th></tr>"
           f"</thead><tbody>{''.join(rows)}</tbody></table>")
    fig = _figure("fig-modes", F.png_data_uri(F.plot_modes(model, modal)),
                  "First mode shapes (blue) over the undeformed rack (grey), x and y [m]; "
                  "displacements scaled to 15 % of the rack's size.")
    return tab + fig


def _checks_html(checks: dict[str, Any]) -> str:
    out = []
    for c in checks.get("checks", []):
        cmp_ = c.get("comparison", {})
        ok = c.get("ok", True)
        out.append(f'<div class="check" id="check-{esc(c["name"])}"><h3>{esc(c["title"])}</h3>'
                   f"<p>Source: {esc(c['source'])}; {esc(c['clause'])}. Rule: "
                   f"{esc(c['rule'])}.</p>"
                   f'<p>Check verdict: <span class="{"verdict-ok" if ok else "verdict-fail"}">'
                   f"{esc(c['verdict'])}</span></p>"
                   f"<p>Time history, same rack and record: {esc(cmp_.get('time_history', ''))}"
                   "</p>")
        if cmp_.get("disagreement"):
            out.append(f'<p class="disagree">Disagreement: {esc(cmp_["disagreement"])}</p>')
        if cmp_.get("note"):
            out.append(f"<p><small>{esc(cmp_['note'])}</small></p>")
        if c["name"] == "drift_sensitivity_ec8":
            out.append(_rows_table(f"table-{c['name']}", c["storeys"], [
                ("storey", "storey", 1, "{}"), ("height_m", "h [m]", 1, "{:.3f}"),
                ("P_tot_N", "P_tot [kN]", 1e-3, "{:.2f}"), ("drift_m", "d_r [mm]", 1e3, "{:.2f}"),
                ("V_tot_N", "V_tot [kN]", 1e-3, "{:.2f}"), ("theta", "θ [-]", 1, "{:.3f}"),
                ("verdict", "verdict", 1, "{}")], "θ per storey from the time history."))
        elif c["name"] == "pallet_sliding_fem":
            out.append(f"<p>Level accelerations from the {esc(c['acceleration_from'])}.</p>")
            out.append(_rows_table(f"table-{c['name']}", c["pallets"], [
                ("id", "pallet", 1, "{}"), ("level", "level", 1, "{}"),
                ("alpha_uls", "a/g ULS [-]", 1, "{:.3f}"), ("mu_uls", "μ ULS [-]", 1, "{:.3f}"),
                ("slides_uls", "slides ULS", 1, "{}"), ("alpha_sls", "a/g SLS [-]", 1,
                                                        "{:.3f}"),
                ("mu_sls", "μ SLS [-]", 1, "{:.3f}"), ("slides_sls", "slides SLS", 1, "{}")],
                "Per pallet: level acceleration over g against γ_μ·μ."))
        elif c["name"] == "mu_alpha_paper":
            out.append(_rows_table(f"table-{c['name']}", c["pallets"], [
                ("id", "pallet", 1, "{}"), ("level", "level", 1, "{}"),
                ("mu_static", "μ static [-]", 1, "{:.3f}"), ("alpha", "α [-]", 1, "{:.3f}"),
                ("slides_predicted", "predicted to slide", 1, "{}")],
                "Per pallet: α = peak beam acceleration / g of the pallet's level."))
        out.append("</div>")
    if checks.get("disagreements"):
        out.insert(0, '<div class="disagree"><b>Checks that disagree with the time history:'
                      "</b><ul>" + "".join(f"<li>{esc(d)}</li>" for d in checks["disagreements"])
                   + "</ul></div>")
    fac = "".join(f"<tr><td>{esc(k)}</td><td>{esc(v)}</td>"
                  f"<td>{esc(checks.get('factor_sources', {}).get(k, ''))}</td></tr>"
                  for k, v in checks.get("factors", {}).items())
    out.append('<table id="table-factors"><caption>Factors used by the checks and their '
               "sources (override with seisrack.checks.CheckFactors).</caption><thead><tr>"
               f"<th>factor</th><th>value</th><th>source</th></tr></thead><tbody>{fac}"
               "</tbody></table>")
    return "".join(out)


def _rows_table(tid: str, rows: list[dict[str, Any]], cols: list[tuple[str, str, float, str]],
                caption: str) -> str:
    head = "".join(f"<th>{esc(h)}</th>" for _, h, _, _ in cols)
    body = "".join("<tr>" + "".join(
        num_cell(r.get(k), f, fmt, k) if isinstance(r.get(k), float) else
        f'<td data-key="{esc(k)}">{esc(r.get(k))}</td>' for k, _, f, fmt in cols) + "</tr>"
        for r in rows)
    return (f'<table id="{tid}"><caption>{esc(caption)}</caption><thead><tr>{head}</tr>'
            f"</thead><tbody>{body}</tbody></table>")


def build_html(*, spec: Any, model: Any, response: Any, record: Any, summary: dict[str, Any],
               modal: Any = None, checks: dict[str, Any] | None = None,
               design_spectrum: Any = None, rack_file: str | None = None,
               seed: int | None = None, interactive: bool | None = None, date: str = "") -> str:
    """The report as one HTML string (see :func:`write_html_report`)."""
    import matplotlib

    matplotlib.use("Agg")
    if interactive is None:
        interactive = _plotly_available()
    title = getattr(spec, "title", "") or summary.get("title") or "rack"
    peak = response.pallet_peak_sliding()
    util = response.fall_utilisation()
    ax = F.plot_elevation(model, spec, peak, util)
    n_risk = int(np.sum(util >= 1.0))
    sec = []
    sec.append(f'<section id="inputs"><h2>1. Inputs</h2>'
               f"{_inputs(spec, record, summary, rack_file, seed, date, response)}</section>")
    sec.append('<section id="elevation"><h2>2. Rack elevation and pallet sliding</h2>'
               + _figure("fig-elevation", F.png_data_uri(ax.figure),
                         "Elevation of the rack, x and height [m]: each pallet drawn at its "
                         "position and coloured by its peak sliding on the beam [mm] (colour "
                         "bar); pallet numbers are the 1-based ids of the tables; red hatched "
                         f"pallets reached their free distance (may fall): {n_risk}.")
               + "</section>")
    if modal is not None:
        sec.append('<section id="modal"><h2>3. Modal analysis</h2>'
                   + _modal_html(model, modal) + "</section>")
    rec_ax = F.plot_record(record)
    sp_ax = F.plot_spectra(record, design=design_spectrum,
                           periods_rack=None if modal is None else modal.periods)
    sec.append('<section id="record"><h2>4. Ground motion</h2>'
               + _figure("fig-record", F.png_data_uri(rec_ax.figure),
                         f"Horizontal ground acceleration of {record.name} [m/s²] against time "
                         "[s], as applied (after any scaling).")
               + _figure("fig-spectrum", F.png_data_uri(sp_ax.figure),
                         "5 %-damped pseudo-acceleration response spectrum of the record "
                         "[m/s²] against period [s]"
                         + (f", with the design spectrum ({design_spectrum.name})"
                            if design_spectrum is not None else
                            " (no design spectrum given)")
                         + "; dotted: the rack's first periods.")
               + "</section>")
    head, hist = _history_html(response, interactive)
    sec.append(f'<section id="histories"><h2>5. Time histories</h2>{hist}</section>')
    sec.append('<section id="tables"><h2>6. Peaks, levels and pallets</h2>'
               + peaks_table(summary) + level_table(summary, model.level_y)
               + pallet_table(summary) + "".join(generic_tables(summary, KNOWN_KEYS))
               + "</section>")
    conn = connections_html(summary, response)
    if conn:
        sec.append(f'<section id="connections"><h2>7. Connections (nonlinear)</h2>{conn}'
                   "</section>")
    if checks is not None:
        sec.append(f'<section id="checks"><h2>{8 if conn else 7}. Design checks beside the '
                   "time history</h2>" + _checks_html(checks) + "</section>")
    verdict = (f"{n_risk} pallet(s) may fall" if n_risk else "no pallet reached its free "
               "distance") + ("; pallets slid" if summary.get("sliding_occurred") else
                              "; no sliding")
    if summary.get("hinges"):
        verdict += f"; {summary['hinges']['yielded']} connection hinge(s) yielded"
    return ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            f"<title>seisrack report: {esc(title)}</title>"
            '<meta name="viewport" content="width=device-width, initial-scale=1">'
            f"<style>{CSS}</style>{head}</head><body>"
            f"<h1>Earthquake response of {esc(title)}</h1>"
            f'<p class="summary-line">Record {esc(record.name)}: {esc(verdict)}.</p>'
            + _warnings_html(summary.get("warnings") or []) + "".join(sec)
            + "</body></html>\n")


def _warnings_html(warnings: list[dict[str, Any]]) -> str:
    """The plausibility warnings (:mod:`seisrack.checks.plausibility`), first thing a reader
    sees after the verdict."""
    if not warnings:
        return ""
    items = "".join(f'<li data-code="{esc(w.get("code", ""))}">{esc(w["message"])} '
                    f'<i>({esc(w.get("source", ""))})</i></li>' for w in warnings)
    return (f'<div class="disagree" id="warnings"><b>Plausibility warnings: a reviewer would '
            f"question these results.</b><ul>{items}</ul></div>")
