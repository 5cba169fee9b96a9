"""The physics the paper's §IV reports, checked on our runs (the digits cannot be reproduced).

Each function returns a :class:`~seisrack.paper.sections.Check` with the numbers found:

- the modal result (T1, participation) against the paper's 0.65 s and 99.6 %;
- the total contact force is capped at μ·M·g when the pallets slide;
- sliding starts near μ ≈ Se(T1)/g (Se of the record with the structure's damping);
- the peak beam displacement is proportional to the peak force (one mode);
- the sliding is of the order of centimetres;
- the simplified rule "no sliding if μ ≥ α" (α from the run with pallets held) is safe.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from seisrack.paper import values as pv
from seisrack.paper.rack import RackRun, RackStudy, table_row
from seisrack.paper.sections import Check

__all__ = ["proportionality", "rack_checks"]

S = "§IV"
ONSET_TOL = 0.15  # |onset / (Se(T1)/g) - 1|
CAP_TOL = 1e-6  # relative overshoot of the force cap allowed (round-off)
R2_MIN = 0.95  # linear fit of displacement on force through the origin
CV_MAX = 0.10  # coefficient of variation of displacement / force
SLIDE_RANGE_M = (1e-3, 0.2)  # "of the order of centimetres": between 1 mm and 20 cm ...
SLIDE_LARGEST_MIN_M = 0.01  # ... and the largest at least 1 cm


def _all_sets(st: RackStudy) -> list[RackRun]:
    sets = list(st.suite)
    if st.sensitivity is not None:
        sets.append(st.sensitivity)
    return sets


def proportionality(disp: np.ndarray, force: np.ndarray) -> dict[str, float]:
    """Fit disp = k·force through the origin: k [m/N], R², and the CV of disp/force."""
    d, f = np.asarray(disp, float), np.asarray(force, float)
    k = float(np.sum(d * f) / np.sum(f * f))
    ss_res = float(np.sum((d - k * f) ** 2))
    ss_tot = float(np.sum((d - d.mean()) ** 2))
    ratio = d / f
    return {"k_m_per_N": k, "r2": 1.0 - ss_res / ss_tot if ss_tot > 0 else 1.0,
            "cv": float(ratio.std(ddof=1) / ratio.mean()) if ratio.size > 1 else 0.0,
            "ratio_min": float(ratio.min()), "ratio_max": float(ratio.max())}


def _modal(st: RackStudy) -> Check:
    t1, part = st.t1, float(st.modal.mass_participation[0])
    ok = abs(t1 / pv.T1_S - 1) < 0.05 and part >= 0.99
    return Check(S, "first mode (T1, participation)", ok,
                 f"T1 = {t1:.3f} s (paper {pv.T1_S} s), participation {100 * part:.1f} % "
                 f"(paper {100 * pv.PARTICIPATION:.1f} %)",
                 "T1 within 5 % of 0.65 s and participation ≥ 99 %")


def _ec8(st: RackStudy) -> Check:
    ok = bool(st.suite_check["passed"])
    items = {c["name"]: c for c in st.suite_check["checks"]}
    spec_item = next((c for n, c in items.items() if n.startswith("min mean/target")), None)
    found = f"{len(st.suite)} records; EN 1998-1 §3.2.3.1.2 checks {'pass' if ok else 'FAIL'}"
    if spec_item is not None:
        found += f"; lowest mean/target spectrum in [0.2 T1, 2 T1] = {spec_item['value']:.3f}"
    return Check(S, "EC8 suite is spectrum-compatible", ok, found,
                 "≥ 3 records, mean PGA ≥ ag·S, mean spectrum ≥ 90 % of target in "
                 "[0.2 T1, 2 T1], stationary part ≥ 10 s")


def _cap(st: RackStudy) -> Check:
    ratios = []
    for rs in _all_sets(st):
        for r in rs.runs.values():
            row = table_row(r)
            if row["slid"]:
                ratios.append(row["force_N"] / row["cap_N"])
    a = np.array(ratios)
    ok = a.size > 0 and a.max() <= 1 + CAP_TOL and a.min() >= 0.99
    return Check(S, "force capped at μ·M·g when pallets slide", bool(ok),
                 f"{a.size} runs with sliding: peak force / (μ M g) between {a.min():.6f} and "
                 f"{a.max():.6f} (g = {st.main.g:g} m/s², M = {st.spec.pallet_mass_total:g} kg)",
                 f"every sliding run reaches the cap (≥ 0.99) and never exceeds it "
                 f"(≤ 1 + {CAP_TOL:g})")


def _onset(st: RackStudy) -> Check:
    m, b = st.main, st.onset_bisection
    se_g = m.se_t1 / m.g
    err_main = abs(b["estimate"] / se_g - 1)
    errs = [abs(rs.onset_mu / (rs.se_t1 / rs.g) - 1) for rs in _all_sets(st)]
    in_bracket = b["low"] <= m.onset_mu <= b["high"]
    ok = err_main <= ONSET_TOL and max(errs) <= ONSET_TOL and in_bracket
    found = (f"main record: bisection onset μ ∈ [{b['low']:.4f}, {b['high']:.4f}] "
             f"({b['runs']} runs), rigid-run onset {m.onset_mu:.4f}, Se(T1, ζ = "
             f"{100 * m.damping_ratio:.0f} %)/g = {se_g:.4f} (difference "
             f"{100 * err_main:.1f} %); over all {len(errs)} record/damping sets the largest "
             f"difference is {100 * max(errs):.1f} %")
    if st.sensitivity is not None:
        s = st.sensitivity
        found += (f"; with ζ = {100 * s.damping_ratio:.0f} %: onset {s.onset_mu:.3f} vs "
                  f"Se/g = {s.se_t1 / s.g:.3f}")
    return Check(S, "sliding starts near μ ≈ Se(T1)/g", bool(ok), found,
                 f"|onset / (Se(T1)/g) − 1| ≤ {100 * ONSET_TOL:g} % for every record, and the "
                 "bisection bracket contains the rigid-run onset")


def _proportional(st: RackStudy) -> tuple[Check, dict[str, Any]]:
    rows = [table_row(r) for r in st.main.runs.values()]
    main = proportionality(np.array([r["disp_m"] for r in rows]),
                           np.array([r["force_N"] for r in rows]))
    pooled_rows = [table_row(r) for rs in _all_sets(st) for r in rs.runs.values()]
    pooled = proportionality(np.array([r["disp_m"] for r in pooled_rows]),
                             np.array([r["force_N"] for r in pooled_rows]))
    paper = proportionality(np.array([v[0] for v in pv.TABLE2.values()]),
                            np.array([v[2] for v in pv.TABLE2.values()]))
    ok = (main["r2"] >= R2_MIN and main["cv"] <= CV_MAX and pooled["r2"] >= R2_MIN)
    found = (f"Table 2 runs: disp/force = {1e6 * main['ratio_min']:.2f}–"
             f"{1e6 * main['ratio_max']:.2f} mm/kN (CV {100 * main['cv']:.1f} %), fit through "
             f"0: R² = {main['r2']:.4f}, i.e. a lateral stiffness of "
             f"{1e-3 / main['k_m_per_N']:.0f} kN/m; all {len(pooled_rows)} runs: R² = "
             f"{pooled['r2']:.4f}; paper: {1e6 * paper['ratio_min']:.2f}–"
             f"{1e6 * paper['ratio_max']:.2f} mm/kN (CV {100 * paper['cv']:.1f} %)")
    chk = Check(S, "peak displacement proportional to peak force", bool(ok), found,
                f"R² ≥ {R2_MIN} (Table 2 runs and all runs), CV of disp/force ≤ "
                f"{100 * CV_MAX:g} %")
    return chk, {"main": main, "pooled": pooled, "paper": paper}


def _centimetres(st: RackStudy) -> Check:
    peaks = [table_row(r)["sliding_mm"] / 1e3 for rs in st.suite for r in rs.runs.values()
             if r.sliding_occurred()]
    main03 = table_row(st.main.runs[0.30])["sliding_mm"]
    a = np.array(peaks)
    lo, hi = SLIDE_RANGE_M
    ok = a.size > 0 and a.min() >= lo and a.max() <= hi and a.max() >= SLIDE_LARGEST_MIN_M
    return Check(S, "sliding of the order of centimetres", bool(ok),
                 f"{a.size} sliding runs: peak sliding {1e3 * a.min():.1f}–{1e3 * a.max():.1f} "
                 f"mm; main record at μ = 0.30: {main03:.1f} mm (paper 44.34 mm, \"less than "
                 f"5 cm\")",
                 f"every peak sliding in [{1e3 * lo:g} mm, {1e3 * hi:g} mm] and the largest "
                 f"≥ {1e3 * SLIDE_LARGEST_MIN_M:g} mm")


def simplified_rows(rs: RackRun) -> list[dict[str, Any]]:
    """Per μ: the rule's prediction (μ < α_rigid → sliding) against what happened."""
    alpha = rs.alpha_rigid
    out = []
    for mu, r in rs.runs.items():
        slid = r.sliding_occurred()
        pred = mu < alpha
        out.append({"mu": mu, "alpha_rigid": alpha, "predicted_sliding": pred, "slid": slid,
                    "safe": pred or not slid})
    return out


def _simplified(st: RackStudy) -> Check:
    rows = [row for rs in _all_sets(st) for row in simplified_rows(rs)]
    unsafe = [r for r in rows if not r["safe"]]
    conservative = sum(1 for r in rows if r["predicted_sliding"] and not r["slid"])
    return Check(S, "simplified rule \"no sliding if μ ≥ α\" is safe", not unsafe,
                 f"{len(rows)} runs: {len(unsafe)} slid although μ ≥ α (unsafe), "
                 f"{conservative} predicted to slide but did not (conservative); main record "
                 f"α = {st.main.alpha_rigid:.3f}",
                 "no run slides with μ ≥ α = peak beam acceleration (pallets held) / g")


def rack_checks(st: RackStudy) -> tuple[list[Check], dict[str, Any]]:
    """All §IV checks and the proportionality fits (for the JSON summary)."""
    prop_check, fits = _proportional(st)
    return [_modal(st), _ec8(st), _cap(st), _onset(st), prop_check, _centimetres(st),
            _simplified(st)], fits
