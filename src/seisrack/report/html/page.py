"""Assemble the report's HTML text (sections, figures, tables)."""

from __future__ import annotations

from typing import Any

import numpy as np

from seisrack import __version__
from seisrack.report.html import figures as F
from seisrack.report.html.connections import connections_html
from seisrack.report.html.design import design_section_html
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
              "outputs", "design_checks", "modal", "report", "seed", "hinges",
              "design_analysis", "sliding_reduction", "dimension", "directions", "impacts",
              "falls", "falls_by_level", "pallets_falling", "pallets_checked_for_falls",
              "angle_deg", "notes", "design", "energy_J", "work", "warnings",
              "stuck_friction_ratio_max"}


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
    """Top-level displacement and base shear in every direction, the sliding of the pallets
    that slid most (along each direction where there are two)."""
    t = np.asarray(response.t)
    dirs = response.directions
    top = response.directional("beam_displacement")[:, -1, :] * 1e3
    shear = response.directional("base_shear") / 1e3
    series = [("Top beam level: displacement relative to the ground", "displacement [mm]", t,
               {d: top[:, k] for k, d in enumerate(dirs)}),
              ("Base shear (sum of the support reactions)", "base shear [kN]", t,
               {d: shear[:, k] for k, d in enumerate(dirs)})]
    if response.n_pallets:
        worst = np.argsort(-response.pallet_peak_sliding())[:N_WORST]
        sliding = response.directional("pallet_sliding") * 1e3
        for k, d in enumerate(dirs):
            where = f" ({d})" if len(dirs) > 1 else ""
            series.append((f"Sliding of the {len(worst)} pallets that slid most, relative to "
                           f"the beam{where}", "sliding [mm]", t,
                           {f"pallet {j + 1}": sliding[:, j, k] for j in worst}))
    return series


def _history_html(response: Any, interactive: bool) -> tuple[str, str]:
    """(head script, body html) of the time-history section."""
    series = _histories(response)
    cap = ("Time histories [s]: top-level displacement [mm], base shear [kN] and the sliding "
           f"[mm] of the {N_WORST} pallets that slid most (kept samples of the run)"
           + (", in each horizontal direction." if response.n_dir > 1 else "."))
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


def _inputs(spec: Any, motion: Any, summary: dict[str, Any], rack_file: str | None,
            seed: int | None, date: str, response: Any) -> str:
    items = [("rack file", rack_file or summary.get("rack", "–")),
             ("rack", getattr(spec, "title", "") or "–"),
             ("dimension", f"{summary.get('dimension', '2D')} rack, directions "
                           + ", ".join(response.directions))]
    for direction, name, a in F.components(motion):
        pga = float(np.max(np.abs(a)))
        items.append((f"record ({direction})",
                      f"{name}: {motion.n} samples, dt {motion.dt:g} s, PGA {pga:.4g} m/s² = "
                      f"{pga / 9.80665:.3f} g"))
    if motion.z is not None:
        items.append(("incidence angle", f"{motion.angle_deg:g}°"))
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
    planar = modal.mass_participation_z is not None  # a 3D rack: cross-aisle and torsion too
    rows = []
    for k in range(modal.n_modes):
        cells = (num_cell(float(modal.periods[k]), 1, "{:.4f}")
                 + num_cell(float(modal.frequencies[k]), 1, "{:.3f}")
                 + num_cell(float(modal.gamma_x[k]), 1, "{:.4g}")
                 + num_cell(float(modal.mass_participation[k]) * 100, 1, "{:.2f}")
                 + num_cell(float(np.sum(modal.mass_participation[:k + 1])) * 100, 1, "{:.2f}"))
        if planar:
            cells += (num_cell(float(modal.mass_participation_z[k]) * 100, 1, "{:.2f}")
                      + num_cell(float(modal.participation_theta[k]) * 100, 1, "{:.2f}")
                      + f"<td>{esc(modal.direction[k])}</td>")
        rows.append(f"<tr><td>{k + 1}</td>{cells}</tr>")
    extra = ("<th>cross-aisle mass [%]</th><th>plan rotation [%]</th><th>class</th>"
             if planar else "")
    tab = ('<table id="table-modal"><caption>Natural modes with the pallets rigidly held: '
           "period, frequency, down-aisle participation factor Γ and effective mass share"
           + (", cross-aisle and plan-rotation shares and each mode's class" if planar else "")
           + ".</caption><thead><tr><th>mode</th><th>period T [s]</th><th>frequency [Hz]</th>"
           "<th>Γx [kg^0.5]</th><th>down-aisle mass [%]</th><th>cumulative [%]</th>"
           f"{extra}</tr></thead><tbody>{''.join(rows)}</tbody></table>")
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
                ("storey", "storey", 1, "{}"), ("direction", "direction", 1, "{}"),
                ("height_m", "h [m]", 1, "{:.3f}"),
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
                "Per pallet: α = peak horizontal beam acceleration / g of the pallet's level."))
        out.append("</div>")
    if checks.get("disagreements"):
        out.insert(0, '<div class="disagree"><b>Checks that disagree with the time history:'
                      "</b><ul>" + "".join(f"<li>{esc(d)}</li>" for d in checks["disagreements"])
                   + "</ul></div>")
    fac = "".join(f"<tr><td>{esc(k)}</td><td>{_text(v)}</td>"
                  f"<td>{esc(checks.get('factor_sources', {}).get(k, ''))}</td></tr>"
                  for k, v in checks.get("factors", {}).items())
    out.append('<table id="table-factors"><caption>Factors used by the checks and their '
               "sources (override with seisrack.checks.CheckFactors).</caption><thead><tr>"
               f"<th>factor</th><th>value</th><th>source</th></tr></thead><tbody>{fac}"
               "</tbody></table>")
    return "".join(out)


def _text(v: Any) -> str:
    """A table cell's text: "–" for a value that was not assessed (None), never "None"."""
    return "–" if v is None else esc(v)


def _rows_table(tid: str, rows: list[dict[str, Any]], cols: list[tuple[str, str, float, str]],
                caption: str) -> str:
    head = "".join(f"<th>{esc(h)}</th>" for _, h, _, _ in cols)
    body = "".join("<tr>" + "".join(
        num_cell(r.get(k), f, fmt, k) if isinstance(r.get(k), float) else
        f'<td data-key="{esc(k)}">{_text(r.get(k))}</td>' for k, _, f, fmt in cols) + "</tr>"
        for r in rows)
    return (f'<table id="{tid}"><caption>{esc(caption)}</caption><thead><tr>{head}</tr>'
            f"</thead><tbody>{body}</tbody></table>")


def _falls_html(summary: dict[str, Any]) -> str:
    """Falls into the aisles (3D racks) and down-aisle impacts, one row each."""
    out = []
    falls = summary.get("falls")
    if falls is not None:
        rows = [f'<tr data-fall="{f["pallet"]}"><td>{f["pallet"]}</td><td>{esc(f["label"])}</td>'
                f"<td>{f['level']}</td><td>{f['bay']}</td>" + num_cell(f["time_s"], 1, "{:.3f}",
                                                                       "time_s")
                + f"<td>{esc(f['side'])}</td></tr>" for f in falls]
        flue = sum(1 for f in falls if f["side"] == "flue")
        out.append('<table id="table-falls"><caption>Pallets falling off the beams (first '
                   f"crossing of the overhang), {len(falls)} of "
                   f"{summary.get('pallets_checked_for_falls', 0)} checked"
                   + (f", {flue} of them into the flue between the rows" if flue else
                      ", each into an aisle")
                   + ". The model keeps a "
                   "fallen pallet on its beams: its sliding after the fall is not physical."
                   "</caption><thead><tr><th>pallet</th><th>label</th><th>level</th><th>bay</th>"
                   "<th>time [s]</th><th>side</th></tr></thead><tbody>"
                   + "".join(rows) + "</tbody></table>")
    impacts = summary.get("impacts") or []
    rows = [f"<tr><td>{esc(i['contact'])}</td>" + num_cell(i["time_s"], 1, "{:.3f}", "time_s")
            + num_cell(i["closing_speed_m_s"], 1, "{:.3f}", "closing_speed_m_s") + "</tr>"
            for i in impacts]
    out.append('<table id="table-impacts"><caption>Down-aisle impacts: first contact of a '
               f"pallet with its neighbour or an upright ({len(impacts)}).</caption><thead><tr>"
               "<th>contact</th><th>time [s]</th><th>closing speed [m/s]</th></tr></thead>"
               "<tbody>" + "".join(rows) + "</tbody></table>")
    return "".join(out)


def build_html(*, spec: Any, model: Any, response: Any, record: Any, summary: dict[str, Any],
               modal: Any = None, checks: dict[str, Any] | None = None,
               design_spectrum: Any = None, rack_file: str | None = None,
               seed: int | None = None, interactive: bool | None = None, date: str = "",
               design_section: dict[str, Any] | None = None) -> str:
    """The report as one HTML string (see :func:`write_html_report`). ``record``: the ground
    motion as run, a Record (down-aisle) or a GroundMotion (with cross-aisle and vertical
    components on a 3D rack)."""
    import matplotlib

    from seisrack.motion.components import GroundMotion, combine

    matplotlib.use("Agg")
    motion = record if isinstance(record, GroundMotion) else combine(record)
    if interactive is None:
        interactive = _plotly_available()
    title = getattr(spec, "title", "") or summary.get("title") or "rack"
    peak = response.pallet_peak_sliding()
    util = response.fall_utilisation()
    fell = np.zeros(response.n_pallets, dtype=bool)
    fell[[f.pallet for f in response.falls]] = True
    ax = F.plot_elevation(model, spec, peak, np.where(fell, np.inf, util))
    n_risk = int(np.sum(util >= 1.0))
    n_fall = int(fell.sum())
    planar = response.n_dir > 1
    sec = []
    sec.append(f'<section id="inputs"><h2>1. Inputs</h2>'
               f"{_inputs(spec, motion, summary, rack_file, seed, date, response)}</section>")
    plan = ""
    if planar and response.n_pallets:
        from seisrack.report.sliding_paths import plot_sliding_paths

        plan = _figure("fig-plan", F.png_data_uri(plot_sliding_paths(response, model)),
                       "Plan view of each loaded beam level, x down-aisle and z cross-aisle "
                       "[m]: each pallet's footprint and the path of its centre (magnified as "
                       "the panel title says); dashed: its fall limits; red: it falls.")
    sec.append('<section id="elevation"><h2>2. Rack elevation, plan and pallet sliding</h2>'
               + _figure("fig-elevation", F.png_data_uri(ax.figure),
                         "Elevation of the rack" + (" (front frame)" if planar else "")
                         + ", x and height [m]: each pallet drawn at its position and coloured "
                         "by its peak sliding on the beams [mm] (colour bar"
                         + ("; the magnitude of the sliding vector" if planar else "")
                         + "); pallet numbers are the 1-based ids of the tables; red hatched "
                         f"pallets reached their free distance down-aisle ({n_risk})"
                         + (f" or fell into an aisle ({n_fall})" if planar else "") + ".")
               + plan + _falls_html(summary) + "</section>")
    if modal is not None:
        sec.append('<section id="modal"><h2>3. Modal analysis</h2>'
                   + _modal_html(model, modal) + "</section>")
    rec_fig = F.plot_record(motion)
    sp_ax = F.plot_spectra(motion, design=design_spectrum,
                           periods_rack=None if modal is None else modal.periods)
    sec.append('<section id="record"><h2>4. Ground motion</h2>'
               + _figure("fig-record", F.png_data_uri(rec_fig),
                         f"Ground acceleration of {motion.name} [m/s²] against time [s], each "
                         "component as applied (after any scaling and rotation).")
               + _figure("fig-spectrum", F.png_data_uri(sp_ax.figure),
                         "5 %-damped pseudo-acceleration response spectrum of each horizontal "
                         "component [m/s²] against period [s]"
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
    if design_section:
        sec.append(design_section_html(7 + bool(conn) + (checks is not None), **design_section))
    verdict = (f"{n_risk} pallet(s) reached their free distance down-aisle" if n_risk else
               "no pallet reached its free distance down-aisle") + (
        (f"; {n_fall} pallet(s) fall into an aisle" if n_fall else "; no pallet falls into an "
         "aisle") if planar else "") + ("; pallets slid" if summary.get("sliding_occurred")
                                        else "; no sliding")
    if summary.get("hinges"):
        verdict += f"; {summary['hinges']['yielded']} connection hinge(s) yielded"
    return ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            f"<title>seisrack report: {esc(title)}</title>"
            '<meta name="viewport" content="width=device-width, initial-scale=1">'
            f"<style>{CSS}</style>{head}</head><body>"
            f"<h1>Earthquake response of {esc(title)}</h1>"
            f'<p class="summary-line">Record {esc(motion.name)}: {esc(verdict)}.</p>'
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
