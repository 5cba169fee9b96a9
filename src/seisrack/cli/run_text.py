"""The text report of ``seisrack run`` (what a rack engineer reads without ``--json``)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

#: text lists longer than these are cut, with a line saying how many more there are
MAX_PALLET_ROWS = 100
MAX_FALL_ROWS = 20
MAX_IMPACT_ROWS = 10


def format_report(resp: Any, spec: Any, motion: Any, summary: dict[str, Any]) -> str:
    """The human-readable report printed without ``--json`` (2D or 3D rack; ``motion`` is the
    :class:`~seisrack.motion.components.GroundMotion` as run, before free vibration)."""
    pk = summary["peaks"]
    g = resp.g
    lines = [spec.title or summary["rack"]]
    comps = [f"{motion.names[0] or '-'} (down-aisle)"]
    if motion.z is not None:
        comps.append(f"{motion.names[1] or '-'} (cross-aisle)")
    if motion.v is not None:
        comps.append(f"{motion.names[2]} (vertical)")
    pga = float(np.max(np.abs(motion.x)))
    lines.append(f"record: {', '.join(comps)}; {motion.n} samples, record dt {motion.dt:g} s, "
                 f"down-aisle PGA {pga:.3f} m/s² = {pga / 9.80665:.3f} g"
                 + (f", incidence angle {motion.angle_deg:g}°" if motion.z is not None else ""))
    sc = summary.get("scaling")
    if sc is not None:
        how = {"pga": f"to PGA {sc['target']:.4g} m/s²",
               "sa": f"to Sa({sc.get('period_s', 0):.4g} s) = {sc['target']:.4g} m/s²",
               "factor": "by a given factor"}[sc["method"]]
        lines.append(f"scaling: {how}, factor {sc['factor']:.6g} on every component (PGA "
                     f"{sc['pga_before']:.4g} -> {sc['pga_after']:.4g} m/s²)")
    err = summary["energy_balance_error"]
    lines.append(f"analysis: {summary['dimension']} rack, analysis dt {resp.dt:g} s, "
                 f"{resp.t.size - 1} kept steps, {resp.t[-1]:.2f} s, g = {g:g} m/s², status "
                 f"{resp.status}" + ("" if err is None else f", energy balance error {err:.1e}"))
    lines.append("")
    m_tot = float(np.sum(resp.pallet_mass)) if resp.n_pallets else 0.0
    cap = float(np.sum(resp.pallet_mu_dynamic * resp.pallet_mass)) * g
    dirs = list(pk["per_direction"])
    lines.append("Peaks" + (" (largest over the directions; then each direction)"
                            if len(dirs) > 1 else ""))
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
    for name, val, unit, *note in rows:
        lines.append(f"  {name:<38} {val:>10.3f} {unit:<5} {note[0] if note else ''}".rstrip())
    if len(dirs) > 1:
        for key, d in pk["per_direction"].items():
            lines.append(f"    {key.replace('_', '-')}: displacement "
                         f"{d['beam_displacement_m'] * 1e3:.2f} mm, base shear "
                         f"{d['base_shear_N'] / 1e3:.3f} kN, upright moment base / connection "
                         f"{d['upright_moment_base_Nm'] / 1e3:.3f} / "
                         f"{d['upright_moment_connection_Nm'] / 1e3:.3f} kN·m, pallet sliding "
                         f"{d['pallet_sliding_max_m'] * 1e3:.1f} mm")
    per = pk["per_level"]
    if len(per["beam_displacement_m"]) > 1 or len(dirs) > 1:
        filt = per.get("beam_acceleration_filtered_m_s2")
        for lv, (d, a) in enumerate(zip(per["beam_displacement_m"],
                                        per["beam_acceleration_m_s2"], strict=True)):
            fa = "" if filt is None else f", filtered {_mm(filt[lv], 1.0)} m/s²"
            lines.append(f"    level {lv + 1}: displacement {_mm(d, 1e3)} mm, "
                         f"acceleration raw {_mm(a, 1.0)} m/s²{fa}")
    lines.extend(_design_lines(summary.get("design"), summary.get("hinges")))
    lines.extend(_hinge_lines(summary.get("hinges"), summary.get("energy_J") or {}))
    lines.append("")
    if resp.n_pallets:
        lines.extend(_pallet_lines(resp, summary))
        lines.extend(_fall_lines(summary))
        lines.extend(_simplified_lines(resp, summary["simplified_check"]))
    else:
        lines.append("No pallets on this rack.")
    if summary.get("warnings"):
        lines.append("")
        lines.extend(f"warning: {w}" for w in summary["warnings"])
    if summary.get("outputs"):
        lines.append("")
        lines.append("Written: " + ", ".join(summary["outputs"]))
    return "\n".join(lines)


def _mm(value: Any, scale: float) -> str:
    """'1.234' for a number, 'x / z' for a pair of directions."""
    if isinstance(value, list | tuple):
        return " / ".join(f"{v * scale:.3f}" for v in value)
    return f"{value * scale:.3f}"


def _pallet_lines(resp: Any, summary: dict[str, Any]) -> list[str]:
    """One row per pallet (the ones that slide most when there are many)."""
    pallets = summary["pallets"]
    planar = summary["dimension"] == "3D"
    friction = np.abs(resp.directional("pallet_friction"))
    peak_f = np.sqrt((friction ** 2).sum(axis=2)).max(axis=0) if resp.t.size else np.zeros(0)
    shown = list(range(len(pallets)))
    if len(shown) > MAX_PALLET_ROWS:
        shown = sorted(sorted(shown, key=lambda j: -pallets[j]["peak_sliding_m"])
                       [:MAX_PALLET_ROWS // 2])
    head = ("Pallets (sliding relative to the beams; limit = free distance -x / +x"
            + ("; peak = magnitude, x / z each direction" if planar else "") + ")")
    out = [head, f"  {'id':>4} {'label':<12} {'x [m]':>7} {'mass [kg]':>9} {'mu_s':>5} "
                 f"{'mu_d':>5} {'peak [mm]':>10} "
                 + (f"{'x / z [mm]':>15} " if planar else "")
                 + f"{'residual [mm]':>15} {'friction [kN]':>13} {'limit [mm]':>15} "
                 f"{'utilisation':>11}"]
    for j in shown:
        p = pallets[j]
        util = p["fall_utilisation"]
        flag = "  AT RISK" if p["id"] in summary["pallets_at_risk"] else ""
        if planar and p.get("falls"):
            flag += f"  FALLS {p['falls']['side']} at {p['falls']['time_s']:.2f} s"
        limit = f"{p['limit_neg_m'] * 1e3:.0f} / {p['limit_pos_m'] * 1e3:.0f}"
        util_s = "inf" if util is None or not math.isfinite(util) else f"{util:.2f}"
        xz = (f"{p['peak_sliding_down_aisle_m'] * 1e3:.1f} / "
              f"{p['peak_sliding_cross_aisle_m'] * 1e3:.1f}") if planar else ""
        out.append(
            f"  {p['id']:>4} {p['label']:<12} {p['x_m']:>7.3f} "
            f"{p['mass_kg']:>9.1f} {p['mu_static']:>5.2f} {p['mu_dynamic']:>5.2f} "
            f"{p['peak_sliding_m'] * 1e3:>10.2f} " + (f"{xz:>15} " if planar else "")
            + f"{_mm(p['residual_m'], 1e3):>15} {peak_f[j] / 1e3:>13.3f} {limit:>15} "
            f"{util_s:>11}{flag}")
    if len(shown) < len(pallets):
        out.append(f"  … {len(pallets) - len(shown)} more pallets (the {len(shown)} that slide "
                   "most are shown; every pallet is in summary.json and peaks.csv)")
    out.append("  (friction: peak magnitude over the kept samples)")
    out.append("")
    n_slip = summary["n_slip_events"]
    out.append(f"Sliding occurred: {'yes' if summary['sliding_occurred'] else 'no'}"
               f" ({n_slip} slip events)")
    risk = summary["pallets_at_risk"]
    labels = {p["id"]: p["label"] for p in pallets}
    out.append("Pallets whose down-aisle sliding reached their free distance: "
               + (", ".join(f"{i} ({labels[i]})" for i in risk[:MAX_FALL_ROWS]) if risk
                  else "none")
               + (f" … {len(risk) - MAX_FALL_ROWS} more" if len(risk) > MAX_FALL_ROWS else ""))
    impacts = summary.get("impacts") or []
    out.append(f"Down-aisle impacts (first contacts): {len(impacts)}")
    for i in impacts[:MAX_IMPACT_ROWS]:
        out.append(f"  {i['contact']} at {i['time_s']:.3f} s, closing at "
                   f"{i['closing_speed_m_s']:.3f} m/s")
    if len(impacts) > MAX_IMPACT_ROWS:
        out.append(f"  … {len(impacts) - MAX_IMPACT_ROWS} more (all in summary.json)")
    return out


def _fall_lines(summary: dict[str, Any]) -> list[str]:
    """Falls into the aisles (3D racks)."""
    if summary["dimension"] != "3D":
        return []
    out = [f"Pallets checked for falls into the aisles: {summary['pallets_checked_for_falls']} "
           f"of {len(summary['pallets'])}; falling: {summary['pallets_falling']}"
           + ("" if summary["pallets_falling_into_aisle"] == summary["pallets_falling"] else
              f" ({summary['pallets_falling_into_aisle']} into an aisle, the others into the "
              "flue)")]
    by = ", ".join(f"level {k}: {v}" for k, v in summary["falls_by_level"].items() if v)
    if by:
        out.append(f"  falls by level: {by}")
    falls = summary["falls"]
    for f in falls[:MAX_FALL_ROWS]:
        out.append(f"  pallet {f['pallet']} ({f['label']}) falls to the {f['side']} at "
                   f"{f['time_s']:.3f} s")
    if len(falls) > MAX_FALL_ROWS:
        out.append(f"  … {len(falls) - MAX_FALL_ROWS} more falls (all in summary.json and "
                   "peaks.csv)")
    if summary["pallets_checked_for_falls"] < len(summary["pallets"]):
        out.append("  note: pallets without depth or overhang are not checked for falls")
    for note in summary.get("notes", []):
        out.append(f"  note: {note}")
    return out


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
            ("upright axial force", "upright_axial_force_N", 1e-3, "kN"),
            # 3D racks: the cross-aisle twins (absent in 2D, skipped)
            ("interstorey drift ratio cross-aisle", "interstorey_drift_ratio_cross_aisle",
             1e2, "%"),
            ("upright moment cross-aisle", "upright_moment_section_cross_aisle_Nm", 1e-3,
             "kN·m")]
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
    w = max([24] + [len(r["hinge"]) + 1 for r in hinges["hinges"]])
    out = ["", "Connections (nonlinear; rotation from the zero-moment state, gravity included)",
           f"  {'hinge':<{w}} {'law':<16} {'peak rot [mrad]':>15} {'peak M [kN·m]':>13} "
           f"{'residual [mrad]':>15} {'ductility':>9}"]
    for r in hinges["hinges"]:
        duct = "-" if r["ductility"] is None else f"{r['ductility']:.2f}"
        out.append(f"  {r['hinge']:<{w}} {r['law']:<16} {r['peak_rotation_rad'] * 1e3:>15.2f} "
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
    if not sc["assessed"]:
        return ["", "Simplified check (paper §II/§IV, no sliding if mu_s >= alpha): not "
                    "assessed, alpha needs the run with rigidly held pallets (--rigid-check); "
                    "this run's own peak accelerations, with sliding pallets, are not the "
                    "designer's alpha"]
    out = ["", "Simplified check (paper §II/§IV): no sliding if mu_s >= alpha = peak horizontal "
               "beam acceleration / g, alpha from the run with rigidly held pallets"]
    for lv, alpha in enumerate(sc["alpha"]):
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
