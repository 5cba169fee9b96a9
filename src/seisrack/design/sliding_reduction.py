"""The force reduction that sliding really gives, beside the one the code's factors assume.

For one rack and one record at one intensity, the peak base shear, connector moment and upright
moment with the pallets sliding are divided by the same peaks with the pallets held rigidly
(friction ``RIGID_MU``, same record, same intensity): the *sliding reduction ratio*. Over a
record suite the ratios are summarised per friction and intensity by their mean and their
lognormal dispersion β = std(ln ratio) (the sample standard deviation, as the fragility fits
of :mod:`seisrack.studies.fragility` use). The paper's α (§II, §IV) is the rigid run's peak
level acceleration over g; μ/α < 1 is where sliding is expected.

The reduction the code assumes (EN 16681 / FEM 10.2.08 unit-load factors, :mod:`.factors`) is
given two ways: the nominal product E_D1·E_D2·E_D3 (the pallets' share of the force, if the
pallets carried all the mass and the period did not move), and, for a given rack and spectrum,
the ratio of the design analysis with the factors to the same analysis with all of them 1
(:func:`code_reduction`), which includes the period shift of the lighter unit loads.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np

#: quantities compared: key -> (store column of the sliding run, rigid column, description)
QUANTITIES = {
    "base_shear": ("base_shear_N", "rigid_base_shear_N", "peak base shear"),
    "connector_moment": ("connector_moment_Nm", "rigid_connector_moment_Nm",
                         "peak connector moment (seismic part)"),
    "upright_moment": ("upright_moment_Nm", "rigid_upright_moment_Nm",
                       "peak upright moment (base and connections, seismic part)"),
}


def rigid_model(model: Any) -> Any:
    """``model`` with every pallet held rigidly (friction ``RIGID_MU``: no record moves it)."""
    from seisrack.analysis.rack import RIGID_MU

    n = int(np.asarray(model.pallet_mass).shape[0])
    return replace(model, pallet_mu_static=np.full(n, RIGID_MU),
                   pallet_mu_dynamic=np.full(n, RIGID_MU))


def response_peaks(resp: Any) -> dict[str, float]:
    """The peaks compared, from a 2D :class:`~seisrack.analysis.RackResponse` (over every
    analysis step): base shear [N], connector moment [N·m] and upright moment [N·m] (seismic
    parts: the response to the record, gravity excluded), total pallet force [N] and the peak
    absolute level acceleration [m/s²]."""
    from seisrack.analysis.peaks import design_summary

    p = resp.peaks()
    ds = design_summary(resp)
    conn = math.nan
    if ds is not None and ds["connector_moment_Nm"].get("seismic_peak_abs"):
        conn = float(max(ds["connector_moment_Nm"]["seismic_peak_abs"]))
    return {
        "base_shear_N": float(p["base_shear_N"]),
        "connector_moment_Nm": conn,
        "upright_moment_Nm": float(max(p["upright_moment_base_Nm"],
                                       p["upright_moment_connection_Nm"])),
        "pallet_force_N": float(p["total_friction_force_N"]),
        "level_acceleration_m_s2": float(p["beam_acceleration_m_s2"]),
    }


def run_ratios(sliding: dict[str, float], rigid: dict[str, float], mu_static: float,
               g: float) -> dict[str, float]:
    """Ratios sliding/rigid of each quantity of :data:`QUANTITIES`, α = rigid peak level
    acceleration / g and μ/α, for one run (JSON-ready; NaN where a peak is missing or 0)."""
    out: dict[str, float] = {}
    for key, (col, _, _) in QUANTITIES.items():
        a, b = sliding.get(col, math.nan), rigid.get(col, math.nan)
        out[key] = float(a / b) if b and math.isfinite(a) and math.isfinite(b) else math.nan
    alpha = rigid.get("level_acceleration_m_s2", math.nan) / g
    out["alpha"] = float(alpha)
    out["mu_over_alpha"] = float(mu_static / alpha) if alpha > 0 else math.nan
    return out


def ratio_statistics(ratios: Any) -> dict[str, float | int | None]:
    """Mean, median and lognormal dispersion β = std(ln r) (ddof 1) of positive finite
    ``ratios``; ``n`` how many entered (None where undefined)."""
    r = np.asarray(ratios, dtype=float)
    r = r[np.isfinite(r) & (r > 0)]
    if r.size == 0:
        return {"n": 0, "mean": None, "median": None, "beta": None}
    ln = np.log(r)
    return {"n": int(r.size), "mean": float(r.mean()), "median": float(np.exp(ln.mean())),
            "beta": float(ln.std(ddof=1)) if r.size >= 2 else None}


def nominal_code_reduction(factors: Any = None) -> dict[str, Any]:
    """E_D1·E_D2·E_D3 per direction from :class:`~seisrack.design.DesignFactors` (the pallets'
    share of the design force relative to rigid, fully loaded pallets)."""
    from seisrack.design.factors import FACTOR_SOURCES, DesignFactors

    f = factors or DesignFactors()
    return {"e_d1": f.e_d1, "e_d2_down_aisle": f.e_d2_down_aisle,
            "e_d2_cross_aisle": f.e_d2_cross_aisle, "e_d3": f.e_d3,
            "down-aisle": f.mass_factor * f.e_d2_down_aisle,
            "cross-aisle": f.mass_factor * f.e_d2_cross_aisle,
            "sources": {k: FACTOR_SOURCES[k] for k in ("e_d1", "e_d2_down_aisle",
                                                       "e_d2_cross_aisle", "e_d3")}}


def code_reduction(model: Any, spectrum: Any, factors: Any = None,
                   direction: str = "down-aisle") -> dict[str, Any]:
    """Rack-specific reduction the code's unit-load factors assume: each quantity of the design
    analysis with ``factors`` over the same with every unit-load factor 1 (same spectrum)."""
    from seisrack.design.analysis import design_analysis
    from seisrack.design.factors import DesignFactors

    f = factors or DesignFactors()
    with_f = design_analysis(model, spectrum, factors=f, directions=direction)
    without = design_analysis(model, spectrum, factors=f.without_unit_load_factors(),
                              directions=direction)
    ax = "z" if direction == "cross-aisle" else "x"
    out: dict[str, Any] = {"direction": direction,
                           "spectrum": getattr(spectrum, "name", "spectrum")}
    for key, name in (("base_shear", f"base_shear_{ax}"),
                      ("connector_moment", "connector_moment"),
                      ("upright_moment", "upright_moment")):
        a, b = with_f.quantities.get(name), without.quantities.get(name)
        out[key] = (float(a.seismic.max() / b.seismic.max())
                    if a is not None and b is not None and b.seismic.max() > 0 else None)
    out["period_with_factors_s"] = float(with_f.periods[0])
    out["period_rigid_full_s"] = float(without.periods[0])
    return out


def one_run_table(model: Any, sliding_resp: Any, rigid_resp: Any, *, mu_static: float | None
                  = None, factors: Any = None, spectrum: Any = None) -> dict[str, Any]:
    """The report's table for one rack and record: peaks sliding and rigid, their ratios,
    α and μ/α, beside the code's assumed reduction (JSON-ready)."""
    s, r = response_peaks(sliding_resp), response_peaks(rigid_resp)
    mus = np.asarray(model.pallet_mu_static, dtype=float)
    mu = float(mu_static if mu_static is not None else (mus.min() if mus.size else math.nan))
    ratios = run_ratios(s, r, mu, float(model.g))
    rows = [{"quantity": key, "description": desc, "sliding": s[col], "rigid": r[col],
             "ratio": ratios[key]}
            for key, (col, _, desc) in QUANTITIES.items()]
    rows.append({"quantity": "pallet_force", "description": "peak total pallet-beam force",
                 "sliding": s["pallet_force_N"], "rigid": r["pallet_force_N"],
                 "ratio": (s["pallet_force_N"] / r["pallet_force_N"]
                           if r["pallet_force_N"] > 0 else math.nan)})
    out = {"rows": rows, "mu_static": mu, "alpha": ratios["alpha"],
           "mu_over_alpha": ratios["mu_over_alpha"], "record": sliding_resp.record_name,
           "code_nominal": nominal_code_reduction(factors)}
    if spectrum is not None:
        out["code_rack"] = code_reduction(model, spectrum, factors)
    return out
