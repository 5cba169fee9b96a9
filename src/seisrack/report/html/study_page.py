"""The engineer's HTML report of a study (issue #14 item 1: "for a study the fragility curves").

:func:`write_study_report` writes ONE self-contained file in the style of the rack report
(:mod:`seisrack.report.html.page`): inline CSS, figures as base64 PNG, A4 print CSS, no network.
It holds the inputs (``DIR/study.json``), run counts, per-stripe tables, fragility curves,
fitted parameters and IDA curves. Every number cell carries its ``summary.json`` value in
``data-value`` and its place there in ``data-path`` (a JSON list of keys). The report does not
import :mod:`seisrack.studies`: bootstrap bands come from ``summarize(..., boots=[])``.
"""

from __future__ import annotations

import datetime as _dt
import json
import math
import os
import tomllib
from collections import defaultdict
from pathlib import Path
from typing import Any

import numpy as np

from seisrack import __version__
from seisrack.jsonable import read_json_object
from seisrack.report.html import figures as F
from seisrack.report.html.page import _figure
from seisrack.report.html.style import CSS
from seisrack.report.html.tables import _unit_factor, esc, header_of
from seisrack.report.html.tables import path_cell as _cell
from seisrack.report.html.tables import table as _table

__all__ = ["STATUS_NOTES", "build_study_html", "read_study_json", "write_study_report"]

G = 9.80665  # [m/s²] standard gravity, for the IM shown in g
#: what a fit status other than "ok" means, and what to do about it
STATUS_NOTES = {
    "separated": "the stripes jump from no exceedance to exceedance without enough stripes in "
                 "between; the maximum-likelihood fit is a step at θ (β = 0). Add stripes "
                 "around θ to estimate the dispersion.",
    "underdetermined": "one stripe carries all the information; θ and β cannot both be "
                       "estimated. Add stripes with partial exceedance.",
    "no_exceedance": "no run reached the damage state; raise the stripes.",
    "all_exceed": "every run reached the damage state; lower the stripes.",
    "failed": "the likelihood has no maximum in range (e.g. fractions decreasing with IM).",
    "ida_censored": "some IDA curves never reached the damage state and were left out "
                    "(θ is biased low).",
}
#: fit statuses of a usable fit that need no explanation (IDA: method of moments, all curves)
OK_STATUSES = ("ok", "ida_moments")
#: (summary peak key, label) of the EC8 peak table
PEAK_LABELS = {"peak_sliding_max_m": "peak pallet sliding", "n_fall": "pallets at risk of "
               "falling", "base_shear_N": "base shear", "beam_displacement_max_m":
               "beam displacement", "drift_ratio_max": "interstorey drift ratio",
               "upright_moment_connection_Nm": "upright moment at the connection"}


def read_study_json(out_dir: str | os.PathLike[str]) -> dict[str, Any] | None:
    """``DIR/study.json`` (the study as given and its run table), or None if absent/unreadable.
    Read by :func:`seisrack.jsonable.read_json_object`, as the studies read it: the report may
    not import the studies."""
    return read_json_object(Path(out_dir) / "study.json")


def _records_html(study: dict[str, Any], toml: dict[str, Any]) -> str:
    rec = toml.get("records", {}) if isinstance(toml.get("records"), dict) else {}
    parts = [f"{k}: {', '.join(map(str, v)) if isinstance(v, list) else v}"
             for k, v in rec.items() if k != "ec8"]
    for s in rec.get("ec8", []) or []:
        parts.append(f"{s.get('count', '?')} generated EC8 records (type {s.get('type', '?')}, "
                     f"ground {s.get('ground', '?')}, a_g {s.get('ag', '?')} g, "
                     f"{s.get('duration', '?')} s, seed {s.get('seed', '–')})")
    factors: dict[tuple[str, str], dict[float, set[float]]] = defaultdict(
        lambda: defaultdict(set))
    for r in study.get("runs", []):  # per rack too: an Sa(T1) factor depends on the rack
        factors[(r.get("rack", "?"), r.get("record", "?"))][
            float(r.get("im_target", math.nan))].add(round(float(r.get("scale_factor",
                                                                         math.nan)), 6))
    many = len({rack for rack, _ in factors}) > 1
    rows = []
    for (rack, name), per in sorted(factors.items()):
        items = [f"{im / G:.3g} g → ×{'/'.join(f'{f:.4g}' for f in sorted(fs))}"
                 for im, fs in sorted(per.items())]
        shown = "; ".join(items[:8]) + (f"; … ({len(items)} levels)" if len(items) > 8 else "")
        rows.append("<tr>" + (f"<td>{esc(rack)}</td>" if many else "")
                    + f"<td>{esc(name)}</td><td>{esc(shown)}</td></tr>")
    tab = _table("table-records", ["rack"] * many + ["record", "IM target [g] → scale "
                                                     "factor [-]"], rows,
                 "Records of the study and the factors that scale each to its intensity "
                 "levels (from study.json).") if rows else ""
    return "<p>" + esc("; ".join(parts) or "–") + "</p>" + tab


def _inputs(summary: dict[str, Any], study: dict[str, Any] | None, seed: int | None,
            date: str) -> str:
    study = study or {}
    try:
        toml = tomllib.loads(study.get("study_toml", "") or "")
    except tomllib.TOMLDecodeError:
        toml = {}
    inten = study.get("intensity", {})
    t_int = toml.get("intensity", {}) if isinstance(toml.get("intensity"), dict) else {}
    levels = inten.get("levels_m_s2", [])
    meas = inten.get("measure") or ", ".join(sorted({g["im_measure"] for g in summary["groups"]}))
    if t_int.get("period") is not None:
        meas += f" at T = {t_int['period']} s"
    racks = study.get("racks") or sorted({g["rack"] for g in summary["groups"]})
    kv = lambda d: ", ".join(f"{k} = {v}" for k, v in d.items()) if d else "–"  # noqa: E731
    items = [("study file", study.get("source", "– (no study.json in the study folder)")),
             ("title", study.get("title") or toml.get("title") or "–"),
             ("study folder", summary.get("out_dir", "–")),
             ("racks", ", ".join(map(str, racks))),
             ("intensity measure", f"{meas} [m/s²], {inten.get('kind', '–')}: "
                                   + (", ".join(f"{x:.4g} m/s² ({x / G:.3g} g)" for x in levels)
                                      if levels else "–")),
             ("friction", kv(toml.get("friction", {}))),
             ("occupancy", kv(toml.get("occupancy", {})) if toml.get("occupancy") else
              "all pallets present"),
             ("analysis step dt", f"{study.get('dt', '–')} s"),
             ("seeds", f"study {study.get('seed', '–')} (friction samples), bootstrap "
                       f"{'–' if seed is None else seed} ({summary.get('n_boot')} resamples)"),
             ("damage states", ", ".join(summary.get("damage_states", []))),
             ("seisrack version", __version__), ("date", date)]
    dl = '<dl class="inputs">' + "".join(f"<dt>{esc(k)}</dt><dd>{esc(v)}</dd>"
                                         for k, v in items) + "</dl>"
    src = study.get("study_toml")
    pre = (f"<details><summary>Study file as given</summary><pre>{esc(src)}</pre></details>"
           if src else "")
    return dl + "<h3>Records and scaling</h3>" + _records_html(study, toml) + pre


def _runs(summary: dict[str, Any]) -> str:
    keys = [("runs_total", "runs"), ("runs_ok", "ok"), ("runs_failed", "failed")]
    if "runs_skipped" in summary:
        keys.append(("runs_skipped", "skipped (stop rule)"))
    rows = [f"<tr><td>{esc(lab)}</td>{_cell([k], summary[k], fmt='{:.0f}')}</tr>"
            for k, lab in keys]
    out = _table("table-runs", ["runs", "count"], rows, "Run counts; only runs with status "
                 "ok enter the statistics.")
    reasons = summary.get("failure_reasons", {})
    if reasons:
        out += _table("table-failures", ["reason", "runs"],
                      [f"<tr><td>{esc(r)}</td>{_cell(['failure_reasons', r], n, fmt='{:.0f}')}"
                       "</tr>" for r, n in reasons.items()],
                      "Why runs failed (first line of each error).")
    return out


def _stripe_tables(gi: int, g: dict[str, Any], states: list[str]) -> str:
    base = ["groups", gi, "stripes", "stripes"]
    st = g["stripes"]["stripes"]
    rows = []
    for si, s in enumerate(st):
        p = [*base, si]
        rows.append(f'<tr data-stripe="{si}"><td>{s["stripe"]}</td>'
                    + _cell([*p, "im"], s["im"]) + f"<td>{s['im'] / G:.3g}</td>"
                    + "".join(_cell([*p, k], s[k], fmt="{:.0f}")
                              for k in ("n_runs", "n_ok", "n_failed", "n_records"))
                    + "".join(_cell([*p, "fraction", d], s["fraction"].get(d), fmt="{:.3f}")
                              for d in states) + "</tr>")
    t1 = _table(f"table-stripes-{gi}", ["stripe", "IM [m/s²]", "IM [g]", "runs", "ok",
                                        "failed", "records"]
                + [f"P({d}) [-]" for d in states], rows,
                f"Stripes of {g['rack']} ({g['im_measure']}): runs per stripe and the fraction "
                "of ok runs exceeding each damage state.")
    rows = []
    for si, s in enumerate(st):
        for k, pk in s["peaks"].items():
            unit, f = _unit_factor(k)
            p = [*base, si, "peaks", k]
            rule = "mean (≥ 7 records)" if s["n_records"] >= 7 else "max (< 7 records)"
            rows.append(f'<tr data-stripe="{si}"><td>{s["stripe"]}</td>'
                        f"<td>{esc(PEAK_LABELS.get(k, header_of(k)))} [{esc(unit)}]</td>"
                        + "".join(_cell([*p, c], pk.get(c), f) for c in ("mean", "max", "ec8"))
                        + f"<td>{esc(rule)}</td></tr>")
    t2 = _table(f"table-peaks-{gi}", ["stripe", "quantity", "mean over records",
                                      "max over records", "EC8 value", "EC8 rule"], rows,
                "Peaks per stripe (EN 1998-1 §4.3.3.4.3): each peak is averaged over the runs "
                "of one record, then the mean and the maximum over the records; the EC8 value "
                "is the mean with 7 or more records, else the maximum.")
    return t1 + t2


def _band(grid: np.ndarray, boot: Any) -> tuple[np.ndarray, np.ndarray] | None:
    """5-95 % pointwise band of the bootstrap curves (as studies.fragility.fragility_band)."""
    from seisrack.lognormal import fragility_curve

    if not boot or boot[0] is None:
        return None
    t, b = np.asarray(boot[0], dtype=float), np.asarray(boot[1], dtype=float)
    good = np.isfinite(t) & np.isfinite(b) & (t > 0) & (b >= 0)
    if good.sum() < 2:
        return None
    curves = np.stack([fragility_curve(grid, ti, bi) for ti, bi in zip(t[good], b[good],
                                                                        strict=True)])
    return tuple(np.percentile(curves, [5.0, 95.0], axis=0))


def _g_axis(ax: Any, vertical: bool = False) -> None:
    conv = (lambda x: np.asarray(x) / G, lambda x: np.asarray(x) * G)
    sec = ax.secondary_yaxis("right", functions=conv) if vertical else ax.secondary_xaxis(
        "top", functions=conv)
    (sec.set_ylabel if vertical else sec.set_xlabel)("[g]")


def _fit_text(f: dict[str, Any]) -> str:
    if f.get("theta") is None:
        return f"no fit ({f.get('status')}: {STATUS_NOTES.get(f.get('status'), '')[:-1]})"
    txt = f"θ = {f['theta']:.4g} m/s² ({f['theta'] / G:.3g} g), β = {f['beta']:.3g}"
    if f.get("status") not in OK_STATUSES:
        txt += f"; status {f['status']}: {STATUS_NOTES.get(f['status'], '')[:-1]}"
    return txt


def _fragility_figures(gi: int, g: dict[str, Any], boots: dict) -> str:
    import matplotlib.pyplot as plt

    from seisrack.report.fragility_plot import fit_is_drawable, plot_fragility

    st = g["stripes"]["stripes"]
    im = np.array([s["im"] for s in st], dtype=float)
    out = []
    for di, (name, f) in enumerate(g["stripes"]["fragility"].items()):
        nan = lambda v: math.nan if v is None else v  # noqa: E731
        top = max(1.6 * im.max(), 1.2 * nan(f.get("theta_hi")) if f.get("theta_hi") else 0.0)
        grid = np.linspace(0.0, top, 200)[1:]
        band = _band(grid, boots.get((g["rack"], g["im_measure"], "stripes", name)))
        _, ax = plt.subplots(figsize=(6.4, 4.0))
        plot_fragility(im, [nan(s["fraction"].get(name)) for s in st], nan(f.get("theta")),
                       nan(f.get("beta")), band=band, grid=grid, label=f"{name}: fitted",
                       im_label=f"{g['im_measure'].upper()} [m/s²]", status=f.get("status"),
                       ax=ax)
        drawn = fit_is_drawable(nan(f.get("theta")), nan(f.get("beta")), f.get("status"))
        _g_axis(ax)
        ax.grid(alpha=0.3)
        ax.set_title(f"{Path(g['rack']).name}: {name}", fontsize="small")
        cap = (f"Fragility of {g['rack']} for {name}: probability of exceedance [-] against "
               f"{g['im_measure'].upper()} [m/s²] (top axis in g). Circles: observed fraction "
               "of ok runs per stripe; "
               + ("line: fitted lognormal (binomial maximum likelihood, Baker 2015 Eq. 11), "
                  + _fit_text(f) + "; shaded: "
                  + ("5-95 % bootstrap band." if band is not None else
                     "no bootstrap band (no bootstrap samples available).") if drawn else
                  "dashed: the observed fractions joined; no fitted curve is drawn because "
                  + _fit_text(f) + "."))
        out.append(_figure(f"fig-fragility-{gi}-{di}", F.png_data_uri(ax.figure), cap))
    return "".join(out)


def _ida_html(gi: int, g: dict[str, Any], summary: dict[str, Any]) -> str:
    import matplotlib.pyplot as plt

    from seisrack.report.fragility_plot import plot_fragility, plot_ida

    ida = g["ida"]
    d = summary.get("d_slide_m", [None])[0]
    _, ax = plt.subplots(figsize=(6.4, 4.2))
    curves = [{**c, "peak_sliding_max_m": [math.nan if v is None else v * 1e3
                                           for v in c["peak_sliding_max_m"]]}
              for c in ida["curves"]]
    plot_ida(curves, edp_label="peak pallet sliding [mm]",
             im_label=f"{g['im_measure'].upper()} [m/s²]",
             threshold=None if d is None else d * 1e3, ax=ax)
    _g_axis(ax, vertical=True)
    ax.grid(alpha=0.3)
    out = [_figure(f"fig-ida-{gi}", F.png_data_uri(ax.figure),
                   f"IDA curves of {g['rack']}: {g['im_measure'].upper()} [m/s²] (right axis in "
                   "g) against the peak pallet sliding [mm], one line per record, friction "
                   f"sample and occupancy ({len(ida['curves'])} curves); dotted: the first "
                   "sliding threshold.")]
    for di, (name, f) in enumerate(ida["fragility"].items()):
        cap = np.sort([c for c in f.get("capacities", []) if c is not None])
        if cap.size == 0:
            continue
        _, ax = plt.subplots(figsize=(6.4, 4.0))
        grid = np.linspace(0.0, 1.3 * cap.max(), 200)[1:]
        plot_fragility(cap, np.arange(1, cap.size + 1) / cap.size,
                       math.nan if f.get("theta") is None else f["theta"],
                       math.nan if f.get("beta") is None else f["beta"], grid=grid,
                       label=f"{name}: fitted", im_label=f"{g['im_measure'].upper()} [m/s²]",
                       status=f.get("status"), ax=ax)
        _g_axis(ax)
        ax.grid(alpha=0.3)
        out.append(_figure(f"fig-ida-fragility-{gi}-{di}", F.png_data_uri(ax.figure),
                           f"IDA fragility of {g['rack']} for {name}: circles, the empirical "
                           f"distribution of the {cap.size} capacities (IM [m/s²] of first "
                           "exceedance per curve); line, the lognormal of the method of "
                           "moments, " + _fit_text(f) + "."))
    return "".join(out)


def _parameters(summary: dict[str, Any]) -> str:
    rows, seen = [], []
    for i, f in enumerate(summary.get("fragility", [])):
        p = ["fragility", i]
        st = f.get("status")
        if st not in OK_STATUSES and st not in seen:
            seen.append(st)
        band = lambda a, b, p=p, f=f: _cell([*p, a], f.get(a)) + _cell([*p, b], f.get(b))  # noqa: E731, E501
        rows.append(f'<tr data-fit="{i}"><td>{esc(f.get("analysis"))}</td>'
                    f"<td>{esc(f.get('rack'))}</td><td>{esc(f.get('im_measure'))}</td>"
                    f"<td>{esc(f.get('name'))}</td>" + _cell([*p, "theta"], f.get("theta"))
                    + ("<td>–</td>" if f.get("theta") is None else
                       f"<td>{f['theta'] / G:.3g}</td>") + band("theta_lo", "theta_hi")
                    + _cell([*p, "beta"], f.get("beta"), fmt="{:.3g}")
                    + band("beta_lo", "beta_hi")
                    + _cell([*p, "n_stripes"], f.get("n_stripes"), fmt="{:.0f}")
                    + _cell([*p, "n_runs"], f.get("n_runs"), fmt="{:.0f}")
                    + f"<td>{esc(f.get('method'))}</td>"
                    + f'<td class="{"verdict-ok" if st in OK_STATUSES else "verdict-fail"}" '
                      f'data-key="status" data-path="{esc(json.dumps([*p, "status"]))}">'
                      f"{esc(st)}</td></tr>")
    tab = _table("table-fragility", ["analysis", "rack", "IM", "damage state", "θ [m/s²]",
                                     "θ [g]", "θ 5 % [m/s²]", "θ 95 % [m/s²]", "β [-]",
                                     "β 5 %", "β 95 %", "stripes", "runs", "method", "status"],
                 rows, "Fitted lognormal fragility P = Φ(ln(IM/θ)/β) per damage state, with "
                       "the 5-95 % bootstrap percentiles of θ and β (as in fragility.csv).")
    notes = "".join(f'<li id="status-{esc(s)}"><b>{esc(s)}</b>: '
                    f"{esc(STATUS_NOTES.get(s, 'see the documentation of the summary'))}</li>"
                    for s in seen)
    return tab + (f'<div class="disagree"><b>Fits whose status is not ok:</b><ul>{notes}</ul>'
                  "</div>" if notes else "")


def build_study_html(summary: dict[str, Any], *, study: dict[str, Any] | None = None,
                     boots: Any = None, seed: int | None = None, date: str = "",
                     plans: list[Any] = ()) -> str:
    """The study report as one HTML string (see :func:`write_study_report`)."""
    import matplotlib

    matplotlib.use("Agg")  # as the rack report: no window, PNG only
    boots = {tuple(b[:4]): b[4] for b in (boots or [])}
    title = (study or {}).get("title") or Path(str(summary.get("out_dir", "study"))).name
    states = summary.get("damage_states", [])
    sec = [f'<section id="inputs"><h2>1. Inputs</h2>{_inputs(summary, study, seed, date)}'
           "</section>",
           f'<section id="runs"><h2>2. Runs</h2>{_runs(summary)}</section>']
    stripes, figs, ida = [], [], []
    for gi, g in enumerate(summary.get("groups", [])):
        head = f"<h3>{esc(g['rack'])}, IM = {esc(g['im_measure'])}</h3>"
        if "stripes" in g:
            stripes.append(head + _stripe_tables(gi, g, states))
            figs.append(head + _fragility_figures(gi, g, boots))
        if "ida" in g:
            ida.append(head + _ida_html(gi, g, summary))
    if stripes:
        sec.append('<section id="stripes"><h2>3. Stripes</h2>' + "".join(stripes)
                   + "</section>")
        sec.append('<section id="fragility"><h2>4. Fragility curves</h2>' + "".join(figs)
                   + "</section>")
    sec.append('<section id="parameters"><h2>5. Fitted parameters</h2>'
               + _parameters(summary) + "</section>")
    if ida:
        sec.append('<section id="ida"><h2>6. Incremental dynamic analysis</h2>'
                   + "".join(ida) + "</section>")
    from seisrack.report.html.study_extra import (
        reduction_section,
        risk_section,
        warehouse_section,
    )

    sec += [s for s in (reduction_section(summary, 7), risk_section(summary, 8),
                        warehouse_section(summary, 9, plans)) if s]
    line = (f"{summary.get('runs_total')} runs, {summary.get('runs_ok')} ok, "
            f"{summary.get('runs_failed')} failed.")
    return ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            f"<title>seisrack study report: {esc(title)}</title>"
            '<meta name="viewport" content="width=device-width, initial-scale=1">'
            f"<style>{CSS}</style></head><body><h1>Study: {esc(title)}</h1>"
            f'<p class="summary-line">{esc(line)}</p>' + _warnings(summary) + "".join(sec)
            + "</body></html>\n")


def _warnings(summary: dict[str, Any]) -> str:
    """The summary's warnings (runs missing from the store, stored runs of another definition
    of the study left out), before any figure: the statistics describe only part of what the
    folder holds."""
    ws = [w for w in summary.get("warnings") or [] if isinstance(w, str)]
    if not ws:
        return ""
    items = "".join(f"<li>{esc(w)}</li>" for w in ws)
    return f'<div class="disagree" id="warnings"><b>Read first:</b><ul>{items}</ul></div>'


def write_study_report(path: str | os.PathLike[str], summary: dict[str, Any], *,
                       out_dir: str | os.PathLike[str] | None = None, boots: Any = None,
                       seed: int | None = None, force: bool = False,
                       plans: list[Any] = ()) -> Path:
    """Write the HTML report of a study summary.

    summary: the dict of ``summary.json`` (JSON values: None for non-finite); out_dir: the
    study folder holding ``study.json`` (default ``summary["out_dir"]``); boots: the list that
    ``summarize(..., boots=[])`` filled (bootstrap samples for the bands; no band without it);
    seed: the bootstrap seed (shown); plans: a warehouse study's plan figures, one matplotlib
    Axes per intensity level (``seisrack.studies.warehouse_summary.plan_axes``). Raises
    InputError if ``path`` exists (without ``force``)
    or cannot be written.
    """
    from seisrack.report.html import check_report_path, write_atomically

    p = check_report_path(path, force)
    study = read_study_json(out_dir if out_dir is not None else summary.get("out_dir", "."))
    text = build_study_html(summary, study=study, boots=boots, seed=seed, plans=plans,
                            date=_dt.datetime.now().isoformat(timespec="seconds"))
    return write_atomically(p, text)
