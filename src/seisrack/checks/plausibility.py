"""Plausibility warnings a reviewer would raise (issue 23, class 3).

A result can be computed correctly from an input that makes no physical sense (a 1e9 kg
pallet, a rack that buckles under its own weight, connector rotations of thousands of
radians), or be computed inaccurately without failing (an energy balance that does not close).
Such results are not refused: they are flagged, in the text output, in the ``warnings`` list of
the JSON summary and in the HTML report.

Each rule is a pure function of the rack spec, the compiled model or the run's summary
(the dict of ``seisrack run --json``) and returns warning records
(``{"code", "message", "value", "limit", "source"}``); :func:`plausibility_warnings` runs them
all. The bounds are named constants below, each with where it comes from, or marked as an
assumption.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

#: [kg] a pallet lighter than this is no unit load: probably a unit error (t for kg)
PALLET_MASS_MIN = 1.0
#: [kg] assumption: a EUR pallet (EN 13698-1) is rated for 1,500 kg and rack unit loads stay
#: within a few tonnes; 5,000 kg on one pallet position is beyond any storage rack
PALLET_MASS_MAX = 5000.0
#: EN 1993-1-1 §5.2.2(5)B: the sway amplification 1/(1 - 1/α_cr) of a first-order analysis
#: is only valid for α_cr >= 3.0 (it then exceeds 1.5); below, the frame is close to
#: buckling under its gravity load (α_cr <= 1 is refused when the rack is built)
CRITICAL_LOAD_FACTOR_MIN = 3.0
#: relative energy-balance residual above which a run's integration is suspect: the engine's
#: exact propagators close it to about 1e-11 and Newmark with hinges to about 5e-9 (README,
#: tests/test_engine_energy.py, tests/test_engine_hinges.py)
ENERGY_ERROR_MAX = 1e-6
#: [rad] assumption: 0.2 rad (11.5°) is far beyond the rotation at which rack beam-end
#: connectors fail in the EN 15512 cantilever test; an elastic connector model says nothing
#: physical there
CONNECTOR_ROTATION_MAX = 0.2
#: a stuck pallet's friction force over mu_s N: Coulomb's law bounds it by 1; the engines
#: hold it to their event tolerance (1e-10 of mu_s N; tests/test_local_front.py); 1 % is an
#: inexact contact decision the output shows, not round-off
STUCK_FRICTION_RATIO_MAX = 1.01
#: interstorey drift ratio: twice the 5 % "collapse prevention" transient drift of steel
#: moment frames (FEMA 356, Table C1-3); beyond, the rack would have collapsed
DRIFT_RATIO_MAX = 0.10

__all__ = ["basis_cap", "critical_load", "energy_balance", "pallet_mass",
           "plausibility_warnings", "response_extremes", "stuck_friction"]


def _warning(code: str, message: str, value: float, limit: float, source: str
             ) -> dict[str, Any]:
    return {"code": code, "message": message, "value": float(value), "limit": float(limit),
            "source": source}


def _ids(idx: list[int], n: int = 8) -> str:
    text = ", ".join(str(i + 1) for i in idx[:n])
    return text + (f" and {len(idx) - n} more" if len(idx) > n else "")


def pallet_mass(spec: Any) -> list[dict[str, Any]]:
    """Pallets lighter than :data:`PALLET_MASS_MIN` or heavier than :data:`PALLET_MASS_MAX`."""
    masses = [float(p.mass) for p in getattr(spec, "pallets", ())]
    out = []
    light = [i for i, m in enumerate(masses) if m < PALLET_MASS_MIN]
    heavy = [i for i, m in enumerate(masses) if m > PALLET_MASS_MAX]
    if heavy:
        top = max(masses[i] for i in heavy)
        out.append(_warning(
            "pallet_mass", f"pallet(s) {_ids(heavy)} weigh up to {top:.4g} kg, more than the "
            f"{PALLET_MASS_MAX:g} kg any storage rack carries per pallet: check the unit "
            "(kg) of the mass", top, PALLET_MASS_MAX,
            "assumption (a EUR pallet, EN 13698-1, is rated for 1,500 kg)"))
    if light:
        low = min(masses[i] for i in light)
        out.append(_warning(
            "pallet_mass", f"pallet(s) {_ids(light)} weigh {low:.4g} kg or less, below "
            f"{PALLET_MASS_MIN:g} kg: no unit load is that light; check the unit (kg, not t)",
            low, PALLET_MASS_MIN, "assumption (a unit load, not a unit error)"))
    return out


def critical_load(factor: float | None) -> list[dict[str, Any]]:
    """A P-Δ rack whose critical load factor is below :data:`CRITICAL_LOAD_FACTOR_MIN`."""
    if factor is None or not math.isfinite(factor) or factor >= CRITICAL_LOAD_FACTOR_MIN:
        return []
    amp = 1.0 / (1.0 - 1.0 / factor) if factor > 1.0 else math.inf
    return [_warning(
        "critical_load_factor", f"the critical load factor under gravity is {factor:.4g}, "
        f"below {CRITICAL_LOAD_FACTOR_MIN:g}: the rack is close to sway buckling under its "
        f"own weight (amplification 1/(1 - 1/alpha_cr) = {amp:.3g}); the drifts and forces "
        "are dominated by second-order effects", factor, CRITICAL_LOAD_FACTOR_MIN,
        "EN 1993-1-1 §5.2.2(5)B (amplification valid for alpha_cr >= 3)")]


def energy_balance(summary: Mapping[str, Any]) -> list[dict[str, Any]]:
    """An energy balance residual above :data:`ENERGY_ERROR_MAX` of the input energy."""
    err = summary.get("energy_balance_error")
    if err is None or not isinstance(err, int | float):
        return []
    if math.isfinite(err) and abs(err) <= ENERGY_ERROR_MAX:
        return []
    return [_warning(
        "energy_balance", f"the energy balance does not close: residual {err:.3g} of the "
        f"input energy (the engine closes it to about 1e-9 or better): the integration is "
        "suspect; rerun with a smaller --dt and compare", err if math.isfinite(err) else 1e300,
        ENERGY_ERROR_MAX, "the engine's energy tests (tests/test_engine_energy.py)")]


def basis_cap(summary: Mapping[str, Any]) -> list[dict[str, Any]]:
    """A reduced basis whose size cap dropped directions of the loads' static responses
    (``basis.capped_directions`` > 0): the rack is larger than the basis can represent at its
    compression tolerance, and the run says how much static energy it lost."""
    b = summary.get("basis")
    if not isinstance(b, Mapping):
        return []
    capped = b.get("capped_directions")
    if not isinstance(capped, int) or capped <= 0:
        return []
    err = b.get("static_energy_error")
    err_text = f"{100 * err:.3g} %" if isinstance(err, int | float) else "unknown"
    return [_warning(
        "basis_cap", f"the reduced basis hit its size cap ({b.get('size')} vectors) and "
        f"dropped {capped} directions of the loads' static responses (largest static energy "
        f"error of a load pattern: {err_text}): the rack is larger than the basis represents; "
        "compare with --basis full if it fits, or with --engine local", capped, 0,
        "seisrack.dynamics.basis.DEFAULT_MAX_SIZE (issue 22: no silent truncation)")]


def _design_max(summary: Mapping[str, Any], key: str) -> tuple[float | None, str]:
    d = summary.get("design") or {}
    q = d.get(key) if isinstance(d, Mapping) else None
    if isinstance(q, Mapping) and isinstance(q.get("max_abs"), int | float):
        return float(q["max_abs"]), str(q.get("max_label") or "")
    peaks = summary.get("peaks") or {}
    v = peaks.get(key) if isinstance(peaks, Mapping) else None
    return (float(v), "") if isinstance(v, int | float) else (None, "")


def response_extremes(summary: Mapping[str, Any]) -> list[dict[str, Any]]:
    """Connector rotations above :data:`CONNECTOR_ROTATION_MAX` and drift ratios above
    :data:`DRIFT_RATIO_MAX`: beyond any physical meaning for a steel rack."""
    out = []
    rot, at = _design_max(summary, "connector_rotation_rad")
    if rot is not None and (not math.isfinite(rot) or rot > CONNECTOR_ROTATION_MAX):
        out.append(_warning(
            "connector_rotation", f"a connector rotates by {rot:.4g} rad"
            + (f" (at {at})" if at else "") + f", more than {CONNECTOR_ROTATION_MAX:g} rad: "
            "no beam-end connector survives that; the elastic result is not physical (check "
            "the masses, the stiffnesses and the record's units)",
            rot if math.isfinite(rot) else 1e300, CONNECTOR_ROTATION_MAX,
            "assumption (connector tests to EN 15512 fail far below)"))
    drift, at = _design_max(summary, "interstorey_drift_ratio")
    cross, at_z = _design_max(summary, "interstorey_drift_ratio_cross_aisle")  # 3D racks
    if cross is not None and (drift is None or not cross <= drift):
        drift, at = cross, f"{at_z}, cross-aisle" if at_z else "cross-aisle"
    at = f"at {at}" if at else ""
    if drift is not None and (not math.isfinite(drift) or drift > DRIFT_RATIO_MAX):
        out.append(_warning(
            "drift_ratio", f"the interstorey drift ratio reaches {100 * drift:.4g} %"
            + (f" ({at})" if at else "") + f", more than {100 * DRIFT_RATIO_MAX:g} %: "
            "the rack would have collapsed long before; the linear result is not physical",
            drift if math.isfinite(drift) else 1e300, DRIFT_RATIO_MAX,
            "FEMA 356 Table C1-3 (steel moment frames: collapse prevention at 5 %)"))
    return out


def stuck_friction(summary: Mapping[str, Any]) -> list[dict[str, Any]]:
    """A pallet reported stuck with a friction force beyond :data:`STUCK_FRICTION_RATIO_MAX`
    of its static capacity mu_s N."""
    ratio = summary.get("stuck_friction_ratio_max")
    if ratio is None or not isinstance(ratio, int | float) or ratio <= STUCK_FRICTION_RATIO_MAX:
        return []
    return [_warning(
        "stuck_friction", f"a pallet is reported stuck with a friction force of {ratio:.4g} "
        "times mu_s N, which Coulomb's law does not allow: the engine's contact decisions "
        "were inexact there (a contact held through a step it could not resolve); compare "
        "with a smaller --dt or the default engine", ratio if math.isfinite(ratio) else 1e300,
        STUCK_FRICTION_RATIO_MAX,
        "Coulomb's law (stuck: |friction| <= mu_s N)")]


def plausibility_warnings(spec: Any = None, model: Any = None,
                          summary: Mapping[str, Any] | None = None) -> list[dict[str, Any]]:
    """Every warning that applies to what is given (each argument is optional)."""
    out: list[dict[str, Any]] = []
    if spec is not None:
        out += pallet_mass(spec)
    if model is not None:
        out += critical_load(getattr(model, "critical_load_factor", None))
    if summary is not None:
        out += (energy_balance(summary) + response_extremes(summary) + basis_cap(summary)
                + stuck_friction(summary))
    return out


def format_warnings(warnings: list[dict[str, Any]]) -> str:
    """The text block of the warnings ('' when there is none)."""
    if not warnings:
        return ""
    lines = ["", "", "Plausibility warnings (a reviewer would question these results):"]
    lines += [f"  - {w['message']} [{w['source']}]" for w in warnings]
    return "\n".join(lines)
