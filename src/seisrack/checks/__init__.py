"""Design checks beside the time history (issue #14 item 3).

Each check cites its source and clause, reads its factors from one
:class:`~seisrack.checks.factors.CheckFactors` table, and returns a JSON-ready dict with a
``verdict``. :func:`run_design_checks` runs them all for one rack and record and puts each
verdict next to what the time history shows, flagging disagreements:

- ``pallet_sliding_fem`` — simplified sliding check of FEM 10.2.08 / EN 16681 (:mod:`.sliding`);
- ``drift_sensitivity_ec8`` — EN 1998-1 §4.4.2.2 θ per storey (:mod:`.drift`);
- ``mu_alpha_paper`` — the reference paper's "no sliding if μ ≥ α" rule
  (:meth:`RackResponse.simplified_check`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from seisrack.checks.drift import drift_sensitivity_check, sensitivity_theta, theta_verdict
from seisrack.checks.factors import FACTOR_SOURCES, CheckFactors
from seisrack.checks.sliding import level_accelerations, pallet_sliding_check

__all__ = [
    "FACTOR_SOURCES",
    "CheckFactors",
    "compare_sliding",
    "drift_sensitivity_check",
    "level_accelerations",
    "mu_alpha_check",
    "pallet_sliding_check",
    "run_design_checks",
    "sensitivity_theta",
    "theta_verdict",
]

PAPER = ("H. Degée & V. Denoël, An investigation on the sliding of pallets on storage racks "
         "subjected to earthquake (ULiège)")


def mu_alpha_check(response: Any) -> dict[str, Any]:
    """The paper's §II/§IV rule from :meth:`RackResponse.simplified_check`, per pallet."""
    sc = response.simplified_check()
    lv = np.asarray(response.pallet_level)
    assessed = sc["assessed"]
    pallets = [{"id": j + 1, "level": int(lv[j]) + 1,
                "mu_static": float(response.pallet_mu_static[j]),
                "alpha": float(sc["alpha"][lv[j]]),
                "slides_predicted": bool(sc["predicted_sliding"][j]) if assessed else None}
               for j in range(response.n_pallets)]
    n = sum(bool(p["slides_predicted"]) for p in pallets)
    return {
        "name": "mu_alpha_paper",
        "title": "Paper's rule: no sliding if μ ≥ α",
        "source": PAPER,
        "clause": "§II (sliding threshold of the rigid block) and §IV",
        "rule": sc["rule"],
        "acceleration_from": sc["alpha_source"],
        "pallets": pallets,
        "verdict": ("not assessed: alpha needs the run with rigidly held pallets"
                    if not assessed else f"{n} of {len(pallets)} pallets predicted to slide"
                    if n else "no pallet predicted to slide"),
        "ok": n == 0 if assessed else None,
    }


def compare_sliding(check: dict[str, Any], slid: np.ndarray, key: str) -> dict[str, Any]:
    """Per-pallet agreement of a check's predicted sliding (``key``) with the time history.

    slid: (m,) bool, pallet slid in the time history. Returns counts and the 1-based ids of
    pallets where the check is unsafe (predicted no sliding but slid) or conservative.
    """
    pred = np.array([p[key] for p in check["pallets"]], dtype=bool)
    unsafe = [int(i) + 1 for i in np.flatnonzero(~pred & slid)]
    cons = [int(i) + 1 for i in np.flatnonzero(pred & ~slid)]
    n_slid = int(slid.sum())
    return {
        "time_history": (f"{n_slid} of {slid.size} pallets slid" if n_slid
                         else "no pallet slid"),
        "pallets_slid": [int(i) + 1 for i in np.flatnonzero(slid)],
        "unsafe_ids": unsafe,
        "conservative_ids": cons,
        "agree": not unsafe and not cons,
        "disagreement": (
            f"check says no sliding but pallets {_ids(unsafe)} slid in the time history"
            if unsafe else
            f"check predicts sliding of pallets {_ids(cons)} that did not slide "
            "(conservative)" if cons else ""),
    }


def _ids(ids: list[int], n: int = 12) -> str:
    txt = ", ".join(str(i) for i in ids[:n])
    return txt + (f" and {len(ids) - n} more" if len(ids) > n else "")


def run_design_checks(model: Any, response: Any, *, modal: Any = None, spectrum: Any = None,
                      record: Any = None, factors: CheckFactors | None = None
                      ) -> dict[str, Any]:
    """All design checks for one rack and record, each beside the time history.

    model: FrameModel; response: its RackResponse; modal: a ModalResult (computed if None);
    spectrum: design spectrum (``seisrack.motion.ec8_spectrum``) for the FEM check, else the
    record's own response spectrum is used (``record`` needed then). Returns a JSON-ready
    ``{"factors", "factor_sources", "checks": [...], "disagreements": [...]}``.
    """
    f = factors or CheckFactors()
    if modal is None:
        from seisrack.fe.modal import modal_analysis

        modal = modal_analysis(model, n_modes=min(model.n_dof, 12))
    slid = response.pallet_peak_sliding() > 1e-6
    checks: list[dict[str, Any]] = []
    if model.n_pallets:
        fem = pallet_sliding_check(model, modal, spectrum=spectrum, record=record, factors=f)
        fem["comparison"] = compare_sliding(fem, slid, "slides_uls")
        if spectrum is not None:
            fem["comparison"]["note"] = ("the check uses the design spectrum, the time history "
                                         "the record: they agree only if the record matches it")
        checks.append(fem)
        mua = mu_alpha_check(response)
        mua["comparison"] = (compare_sliding(mua, slid, "slides_predicted")
                             if mua["ok"] is not None else
                             {"agree": True, "disagreement": "", "note": mua["verdict"]})
        checks.append(mua)
    drift = drift_sensitivity_check(model, response, f)
    drift["comparison"] = {
        "time_history": "peak interstorey drift ratios "
        + ", ".join(f"{r['drift_ratio'] * 100:.3f} %" for r in drift["storeys"]),
        "agree": True, "disagreement": "",
        "note": "θ is computed from the time history itself (no independent prediction)",
    }
    checks.append(drift)
    dis = [f"{c['title']}: {c['comparison']['disagreement']}" for c in checks
           if c["comparison"].get("disagreement")]
    return {"factors": f.as_dict(), "factor_sources": dict(FACTOR_SOURCES), "checks": checks,
            "disagreements": dis}
