"""The text report of ``seisrack run`` (what a rack engineer reads without ``--json``)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np


def format_report(resp: Any, spec: Any, rec: Any, vert: Any, summary: dict[str, Any]) -> str:
    """The human-readable report printed without ``--json``."""

    pk = summary["peaks"]
    g = resp.g
    lines = [spec.title or summary["rack"]]
    lines.append(
        f"record: {rec.name} ({rec.n} samples, dt {rec.dt:g} s, PGA {rec.pga:.3f} m/s² = "
        f"{rec.pga / 9.80665:.3f} g)" + (f", vertical: {vert.name}" if vert is not None else ""))
    sc = summary.get("scaling")
    if sc is not None:
        how = {"pga": f"to PGA {sc['target']:.4g} m/s²",
               "sa": f"to Sa({sc.get('period_s', 0):.4g} s) = {sc['target']:.4g} m/s²",
               "factor": "by a given factor"}[sc["method"]]
        lines.append(f"scaling: {how}, factor {sc['factor']:.6g} (PGA {sc['pga_before']:.4g} "
                     f"-> {sc['pga_after']:.4g} m/s²)")
    lines.append(f"analysis: dt {resp.dt:g} s, {resp.t.size - 1} steps, {resp.t[-1]:.2f} s, "
                 f"g = {g:g} m/s², status {resp.status}, energy balance error "
                 f"{summary['energy_balance_error']:.1e}")
    lines.append("")
    m_tot = float(np.sum(resp.pallet_mass)) if resp.n_pallets else 0.0
    cap = float(np.sum(resp.pallet_mu_dynamic * resp.pallet_mass)) * g
    rows = [
        ("beam displacement (relative to ground)", pk["beam_displacement_m"] * 1e3, "mm"),
        ("beam acceleration (absolute, raw)", pk["beam_acceleration_m_s2"], "m/s²",
         f"= {pk['beam_acceleration_m_s2'] / g:.3f} g"),
        *([] if pk.get("beam_acceleration_filtered_m_s2") is None else [
            (f"beam acceleration (low-pass {pk['acceleration_filter_hz']:g} Hz)",
             pk["beam_acceleration_filtered_m_s2"], "m/s²",
             f"= {pk['beam_acceleration_filtered_m_s2'] / g:.3f} g")]),
        ("total pallet-beam contact force", pk["total_friction_force_N"] / 1e3, "kN",
         f"(μd·M·g = {cap / 1e3:.3f} kN, M = {m_tot:.0f} kg)" if resp.n_pallets else ""),
        ("base shear", pk["base_shear_N"] / 1e3, "kN"),
        ("upright moment at the base", pk["upright_moment_base_Nm"] / 1e3, "kN·m"),
        ("upright moment at the connections", pk["upright_moment_connection_Nm"] / 1e3,
         "kN·m"),
    ]
    lines.append("Peaks")
    for name, val, unit, *note in rows:
        lines.append(f"  {name:<38} {val:>10.3f} {unit:<5} {note[0] if note else ''}".rstrip())
    if len(pk["per_level"]["beam_displacement_m"]) > 1:
        filt = pk["per_level"].get("beam_acceleration_filtered_m_s2")
        for lv, (d, a) in enumerate(zip(pk["per_level"]["beam_displacement_m"],
                                        pk["per_level"]["beam_acceleration_m_s2"],
                                        strict=True)):
            fa = "" if filt is None else f", filtered {filt[lv]:.3f} m/s²"
            lines.append(f"    level {lv + 1}: displacement {d * 1e3:.3f} mm, "
                         f"acceleration raw {a:.3f} m/s²{fa}")
    lines.extend(_design_lines(summary.get("design"), summary.get("hinges")))
    lines.extend(_hinge_lines(summary.get("hinges"), summary.get("energy_J") or {}))
    lines.append("")
    if resp.n_pallets:
        lines.append("Pallets (sliding relative to the beam; limit = free distance -x / +x)")
        lines.append(f"  {'id':>4} {'label':<12} {'x [m]':>7} {'mass [kg]':>9} {'mu_s':>5} "
                     f"{'mu_d':>5} {'peak [mm]':>10} {'residual [mm]':>13} "
                     f"{'limit [mm]':>15} {'utilisation':>11}")
        for j, p in enumerate(summary["pallets"]):
            util = p["fall_utilisation"]
            flag = "  AT RISK" if p["id"] in summary["pallets_at_risk"] else ""
            limit = f"{p['limit_neg_m'] * 1e3:.0f} / {p['limit_pos_m'] * 1e3:.0f}"
            util_s = "inf" if util is None or not math.isfinite(util) else f"{util:.2f}"
            lines.append(
                f"  {p['id']:>4} {p['label']:<12} {resp.pallet_x[j]:>7.3f} "
                f"{p['mass_kg']:>9.1f} {p['mu_static']:>5.2f} {p['mu_dynamic']:>5.2f} "
                f"{p['peak_sliding_m'] * 1e3:>10.2f} {p['residual_m'] * 1e3:>13.2f} "
                f"{limit:>15} {util_s:>11}{flag}")
        lines.append("")
        n_slip = summary["n_slip_events"]
        lines.append(f"Sliding occurred: {'yes' if summary['sliding_occurred'] else 'no'}"
                     f" ({n_slip} slip events)")
        risk = summary["pallets_at_risk"]
        labels = {p["id"]: p["label"] for p in summary["pallets"]}
        lines.append("Pallets at risk of falling: "
                     + (", ".join(f"{i} ({labels[i]})" for i in risk) if risk else "none"))
        lines.extend(_simplified_lines(resp, summary["simplified_check"]))
    else:
        lines.append("No pallets on this rack.")
    if summary.get("outputs"):
        lines.append("")
        lines.append("Written: " + ", ".join(summary["outputs"]))
    return "\n".join(lines)


def _design_lines(design: dict[str, Any] | None,
                  hinges: dict[str, Any] | None = None) -> list[str]:
    """Peaks of the design quantities (gravity + seismic, elastic) with the member.

    With nonlinear connections the design summary's connector moment is the moment of the
    connectors' law (:func:`~seisrack.analysis.hinges.nonlinear_connector_design`), and the
    row says so.
    """
    if not design:
        return []
    conn = [r for r in (hinges or {}).get("hinges", []) if r["kind"] == "connector"]
    rows = [("interstorey drift ratio", "interstorey_drift_ratio", 1e2, "%"),
            ("beam end moment", "beam_end_moment_Nm", 1e-3, "kN·m"),
            ("beam end shear", "beam_end_shear_N", 1e-3, "kN"),
            ("connector moment", "connector_moment_Nm", 1e-3, "kN·m"),
            ("connector rotation", "connector_rotation_rad", 1e3, "mrad"),
            ("upright axial force", "upright_axial_force_N", 1e-3, "kN")]
    out = ["", "Design quantities (gravity + seismic, elastic; member of the peak)"]
    for name, key, scale, unit in rows:
        item = design.get(key) or {}
        if not item.get("labels"):
            continue
        if key == "connector_moment_Nm" and conn:
            name = "connector moment (hinge law)"
        out.append(f"  {name:<38} {item['max_abs'] * scale:>10.3f} {unit:<5} "
                   f"at {item['max_label']}")
    nm = design.get("upright_n_m") or {}
    if nm.get("labels"):
        k = max(range(len(nm["labels"])), key=lambda i: abs(nm["at_max_abs_N"][i][0]))
        n_, m_ = nm["at_max_abs_N"][k]
        out.append(f"  {'upright N with concomitant M':<38} N = {n_ / 1e3:.3f} kN, "
                   f"M = {m_ / 1e3:.3f} kN·m at {nm['labels'][k]}")
    return out


def _hinge_lines(hinges: dict[str, Any] | None, energy: dict[str, float]) -> list[str]:
    """The nonlinear connections: one line per hinge and the hysteretic energy."""
    if not hinges:
        return []
    out = ["", "Connections (nonlinear; rotation from the zero-moment state, gravity included)",
           f"  {'hinge':<24} {'law':<16} {'peak rot [mrad]':>15} {'peak M [kN·m]':>13} "
           f"{'residual [mrad]':>15} {'ductility':>9}"]
    for r in hinges["hinges"]:
        duct = "-" if r["ductility"] is None else f"{r['ductility']:.2f}"
        out.append(f"  {r['hinge']:<24} {r['law']:<16} {r['peak_rotation_rad'] * 1e3:>15.2f} "
                   f"{r['peak_moment_Nm'] * 1e-3:>13.3f} "
                   f"{r['residual_rotation_rad'] * 1e3:>15.2f} {duct:>9}"
                   + ("  YIELDED" if r["yielded"] else ""))
    top = ("" if hinges.get("peak_ductility") is None else
           f"; largest ductility {hinges['peak_ductility']:.2f} at "
           f"{hinges['peak_ductility_hinge']}")
    out.append(f"  {hinges['count']} hinges, {hinges['yielded']} yielded{top}")
    hyst, e_in = hinges.get("hysteretic_energy_J"), energy.get("input")
    if hyst is not None:
        share = (f" = {100 * hyst / e_in:.1f} % of the input energy ({e_in:.4g} J)"
                 if e_in else "")
        out.append(f"  hysteretic energy dissipated by the connections: {hyst:.4g} J{share}")
    return out


def _simplified_lines(resp: Any, sc: dict[str, Any]) -> list[str]:
    out = ["", "Simplified check (paper §II/§IV): no sliding if mu_s >= alpha = peak beam "
               "acceleration / g, alpha from the run with rigidly held pallets"]
    for lv, alpha in enumerate(sc["alpha_rigid"]):
        on = [j for j in range(resp.n_pallets) if int(resp.pallet_level[j]) == lv]
        if not on:
            continue
        mus = sorted({float(resp.pallet_mu_static[j]) for j in on})
        pred = [j for j in on if sc["predicted_sliding"][j]]
        slid = [j for j in on if sc["sliding"][j]]
        out.append(f"  level {lv + 1}: alpha = {alpha:.3f}, mu_s = "
                   f"{', '.join(f'{m:.2f}' for m in mus)}; predicted to slide: "
                   f"{len(pred)}/{len(on)} pallets, slid: {len(slid)}/{len(on)}")
    verdict = ("SAFE on this run: every pallet that slid was predicted to slide"
               if sc["rule_safe"] else
               "UNSAFE on this run: a pallet slid although mu_s >= alpha")
    out.append(f"  verdict: {verdict}")
    return out

