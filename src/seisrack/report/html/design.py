"""The report's section "Design analysis (EN 16681 / EN 1998-1 modal response spectrum)".

Built from JSON-ready dicts (what summary.json holds): the design analysis
(:meth:`seisrack.design.DesignResult.as_dict`), the time history's own peaks beside it and the
one run's sliding reduction (:func:`seisrack.design.sliding_reduction.one_run_table`).
"""

from __future__ import annotations

from typing import Any

from seisrack.report.html.tables import esc, num_cell

TITLE = "Design analysis (EN 16681 / EN 1998-1 modal response spectrum)"
#: modes shown in the table
N_MODES = 12
_AX = {"down-aisle": "x", "cross-aisle": "z"}


def _table(tid: str, headers: list[str], rows: list[str], caption: str) -> str:
    head = "".join(f"<th>{esc(h)}</th>" for h in headers)
    return (f'<table id="{esc(tid)}"><caption>{esc(caption)}</caption><thead><tr>{head}</tr>'
            f"</thead><tbody>{''.join(rows)}</tbody></table>")


def _modes(d: dict[str, Any]) -> str:
    m = d["modes"]
    dirs = d["directions"]
    heads = ["mode", "T [s]", "ζ [-]"]
    for di in dirs:
        heads += [f"S_a {_AX[di]} [m/s²]", f"effective mass {_AX[di]} [%]"]
    rows = []
    for k in range(min(N_MODES, len(m["periods_s"]))):
        cells = (f"<td>{k + 1}</td>" + num_cell(m["periods_s"][k], 1, "{:.4f}", "period_s")
                 + num_cell(m["damping"][k], 1, "{:.3f}", "damping"))
        for di in dirs:
            share = m["effective_mass_kg"][di][k] / m["total_mass_kg"][di]
            cells += (num_cell(m["sa_m_s2"][di][k], 1, "{:.4g}", "sa_m_s2")
                      + num_cell(100 * share, 1, "{:.2f}", "mass_share"))
        rows.append(f"<tr>{cells}</tr>")
    cum = ", ".join(f"{100 * m['cumulative_mass'][di]:.1f} % {di}" for di in dirs)
    return _table("table-design-modes", heads, rows,
                  "Modes of the rack with the unit loads' horizontal mass scaled by E_D1·E_D3 "
                  f"= {d['mass_factor_unit_loads']:g}; spectral accelerations with E_D2 "
                  f"(first {N_MODES} shown; the modes taken into account hold {cum} of the "
                  "mass).")


def _storeys(d: dict[str, Any]) -> str:
    out = []
    for di, st in d["storeys"].items():
        ax = _AX[di]
        lf = d["quantities"].get(f"level_force_{ax}", {}).get("seismic") or []
        rows = []
        for i, s in enumerate(st["storeys"]):
            rows.append("<tr>" + f"<td>{s['storey']}</td>"
                        + num_cell(lf[i] if i < len(lf) else None, 1e-3, "{:.3f}",
                                   "design_F_level_N")
                        + num_cell(s["drift_s_m"], 1e3, "{:.2f}", "design_drift_s_m")
                        + num_cell(s["drift_ratio"], 100, "{:.3f}", "design_drift_ratio")
                        + num_cell(s["V_tot_N"], 1e-3, "{:.3f}", "design_V_tot_N")
                        + num_cell(s["P_tot_N"], 1e-3, "{:.2f}", "design_P_tot_N")
                        + num_cell(s["theta"], 1, "{:.3f}", "design_theta")
                        + num_cell(s["amplification"], 1, "{:.3f}", "design_amplification")
                        + f"<td>{esc(s['verdict'])}</td></tr>")
        out.append(_table(
            f"table-design-storeys-{ax}",
            ["storey", "level force [kN]", "d_r = q·d_e [mm]", "drift [%]", "V_tot [kN]",
             "P_tot [kN]", "θ [-]", "1/(1−θ)", "verdict (EN 1998-1 §4.4.2.2)"], rows,
            f"{di}, q = {st['q']:g}: level forces (storey shear below minus above), design "
            "interstorey drift d_r = q·d_e (§4.3.4), storey shear, gravity load above, "
            "θ = P_tot·d_r/(V_tot·h) (Eq 4.28) and the amplification of the seismic effects."))
    return "".join(out)


def _members(d: dict[str, Any]) -> str:
    rows = []
    for name, q in d["quantities"].items():
        if q["kind"] != "member":
            continue
        k = q["labels"].index(q["max_label"])
        f = 1e-3
        rows.append(f"<tr><td>{esc(q['description'])}</td><td>{esc(q['max_label'])}</td>"
                    + num_cell(q["gravity"][k], f, "{:.3f}", f"{name}_gravity")
                    + num_cell(q["seismic"][k], f, "{:.3f}", f"{name}_seismic")
                    + num_cell(q["design"][k], f, "{:.3f}", f"{name}_design")
                    + f"<td>{esc('kN·m' if q['unit'] == 'N m' else 'kN')}</td></tr>")
    if not rows:
        return ""
    return _table("table-design-members", ["quantity", "governing member", "gravity G",
                                           "seismic E", "design |G| + E", "unit"], rows,
                  "Member forces: the largest design value |G| + E of each quantity, with G the "
                  "static state under gravity alone and E the seismic effect combined over the "
                  "modes and directions (upright N and M are envelopes, not concomitant).")


def _beside(beside: list[dict[str, Any]]) -> str:
    rows = []
    for r in beside:
        rows.append(f"<tr><td>{esc(r['description'])}</td>"
                    + num_cell(r["design"], r["factor"], "{:.3f}", f"beside_{r['quantity']}_design")
                    + num_cell(r["time_history"], r["factor"], "{:.3f}",
                               f"beside_{r['quantity']}_time_history")
                    + num_cell(r["ratio"], 1, "{:.3f}", f"beside_{r['quantity']}_ratio")
                    + f"<td>{esc(r['unit'])}</td></tr>")
    return _table("table-design-beside", ["quantity (seismic part)", "design analysis",
                                          "time history peak", "time history / design",
                                          "unit"], rows,
                  "The code's answer beside the exact one: the design analysis (spectrum, q, "
                  "unit-load factors) and the peak of this run's time history (the record, "
                  "sliding pallets). They see different motions unless the record matches the "
                  "spectrum.")


def _reduction(red: dict[str, Any]) -> str:
    rows = []
    for r in red["rows"]:
        f, unit = (1e-3, "kN·m") if r["quantity"].endswith("moment") else (1e-3, "kN")
        rows.append(f"<tr><td>{esc(r['description'])}</td>"
                    + num_cell(r["sliding"], f, "{:.3f}", f"reduction_{r['quantity']}_sliding")
                    + num_cell(r["rigid"], f, "{:.3f}", f"reduction_{r['quantity']}_rigid")
                    + num_cell(r["ratio"], 1, "{:.3f}", f"reduction_{r['quantity']}_ratio")
                    + f"<td>{esc(unit)}</td></tr>")
    nom = red["code_nominal"]
    text = (f"E_D1·E_D2·E_D3 = {nom['down-aisle']:.3f} down-aisle (E_D1 = {nom['e_d1']:g}, "
            f"E_D2 = {nom['e_d2_down_aisle']:g}, E_D3 = {nom['e_d3']:g}; assumptions, see the "
            "factor table)")
    rack = red.get("code_rack")
    if rack:
        text += (f"; for this rack and {esc(rack['spectrum'])} the design analysis gives "
                 f"{rack['base_shear']:.3f} of the rigid, fully loaded base shear "
                 f"(T1 {rack['period_rigid_full_s']:.3f} s → "
                 f"{rack['period_with_factors_s']:.3f} s)")
    return (_table("table-sliding-reduction", ["quantity", "sliding pallets", "rigid pallets",
                                               "sliding / rigid", "unit"], rows,
                   f"The reduction sliding really gives on record {red['record']}: peaks with "
                   f"the pallets sliding (μ = {red['mu_static']:g}) over the same with the "
                   f"pallets held rigidly; α = {red['alpha']:.3f} (rigid peak level acceleration "
                   f"/ g), μ/α = {red['mu_over_alpha']:.3f}.")
            + f"<p>Reduction the code's unit-load factors assume: {text}.</p>")


def design_section_html(number: int, design: dict[str, Any] | None = None,
                        beside: list[dict[str, Any]] | None = None,
                        reduction: dict[str, Any] | None = None, note: str = "") -> str:
    """The whole section (``<section id="design">``); empty string when there is nothing."""
    if design is None and reduction is None and not note:
        return ""
    out = [f'<section id="design"><h2>{number}. {esc(TITLE)}</h2>']
    if note:
        out.append(f"<p>{esc(note)}</p>")
    if design is not None:
        parts = []
        for di in design["directions"]:
            name = design["spectra"][di]
            name += "" if "q =" in name else f", q = {design['q'][di]:g}"
            parts.append(f"{esc(di)}: {esc(name)}; {esc(design['modal_rule_reason'][di])}")
        if len(design["directions"]) > 1:
            parts.append(f"directions: {esc(design['direction_rule_text'])}")
        out.append("<p>EN 1998-1 §4.3.3.3 modal response spectrum analysis. "
                   + "; ".join(parts) + ".</p>")
        out.append(_modes(design))
        out.append(_storeys(design))
        out.append(_members(design))
        if beside:
            out.append(_beside(beside))
        fac = "".join(f"<tr><td>{esc(k)}</td>" + num_cell(v, 1, "{:g}", k)
                      + f"<td>{esc(design['factor_sources'].get(k, ''))}</td></tr>"
                      for k, v in design["factors"].items())
        out.append(_table("table-design-factors", ["factor", "value", "source"],
                          [fac], "Factors of the design analysis and their sources "
                          "(override with seisrack design --factors KEY=VALUE)."))
        for n in design.get("notes", []):
            out.append(f"<p><small>Note: {esc(n)}</small></p>")
    if reduction is not None:
        out.append(_reduction(reduction))
    out.append("</section>")
    return "".join(out)


def beside_rows(design: Any, th_peaks: dict[str, float]) -> list[dict[str, Any]]:
    """Rows of the design value (seismic part, directions combined) beside the time history's
    peak (``response_peaks``) for base shear, connector and upright moments."""
    q = design.quantities
    pairs = [("base_shear", "base shear", "base_shear_x", "base_shear_N", 1e-3, "kN"),
             ("connector_moment", "connector moment", "connector_moment",
              "connector_moment_Nm", 1e-3, "kN·m"),
             ("upright_moment", "upright moment", "upright_moment", "upright_moment_Nm",
              1e-3, "kN·m")]
    rows = []
    for key, desc, name, col, f, unit in pairs:
        if name not in q:
            continue
        dv = float(q[name].seismic.max())
        th = float(th_peaks.get(col, float("nan")))
        rows.append({"quantity": key, "description": desc, "design": dv, "time_history": th,
                     "ratio": th / dv if dv > 0 else float("nan"), "factor": f, "unit": unit})
    return rows
