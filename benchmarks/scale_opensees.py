"""The OpenSeesPy peer of the scale benchmark: one function, :func:`run_opensees`.

``benchmarks/scale.py`` calls it with the same compiled rack, ground motion and step as
seisrack. The model is the script of ``seisrack export opensees`` for that rack, executed by
``benchmarks/opensees_rack.py`` (``build_from_export``; node for node from ``model.mesh``):

- ``mu=None``: pallets rigidly attached (``equalDOF`` in ux, the model is linear), solved with
  ``Linear -factorOnce`` — the cheapest correct OpenSees setting for a linear model at a
  constant step;
- ``mu`` a number: every pallet on an ElasticPP ``zeroLength`` (regularised Coulomb with
  mu_s = mu_d = mu and N = m g, initial stiffness ``k_init``), Newton with the fallbacks of
  ``opensees_rack.advance``.

Accuracy of the friction mode (measured, El Centro, 3-level x 3-bay rack, mu 0.3): the
regularised model needs its pallet springs resolved in time (omega dt = sqrt(kInit / m) dt well
below 1). At dt = 1 ms, kInit = 1e8 it agrees with seisrack within 0.3 % on every level's peak
(first 6 s); at dt = 5 ms it is off by 3-5 % over 6 s and by 6-18 % over 20 s, with Newton
retries, and it moves with kInit (1e8, 1e9, 1e10 give different peaks). seisrack itself is
converged at 5 ms there (1 ms changes its peaks by < 0.1 %). Rigid pallets agree within
0.01 % (3 x 3 and 10 x 20 racks, 20 s). So a like-for-like accuracy comparison with sliding
needs a smaller OpenSees step; the timing at 5 ms is a lower bound on its cost.

System ``SparseSYM`` by default: every tangent here is symmetric, and on the 10-level x
20-bay rack (3,900 equations) it was the fastest of BandGeneral, UmfPack, SparseSYM and
ProfileSPD (friction: 59 against 25, 44, 46 steps/s; rigid: within 10 % of each other).

Reports; never asserts. Run by itself, it times the peer on two racks::

    python benchmarks/scale_opensees.py [--seconds 20] [--max-wall 600]
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
import tomllib
from pathlib import Path
from typing import Any

import numpy as np

_HERE = Path(__file__).resolve().parent
if str(_HERE) not in sys.path:
    sys.path.insert(0, str(_HERE))

import opensees_rack as osr  # noqa: E402

ROOT = _HERE.parent


def run_opensees(
    model, ag: np.ndarray, dt: float, mu: float | None = None, *, k_init: float = 1e8,
    system: str = "SparseSYM", tol: float = 1e-10, max_iter: int = 25,
    max_wall_s: float | None = None,
) -> dict[str, Any]:
    """Time history of a compiled seisrack rack in OpenSeesPy; peaks and timings.

    Args:
        model: a compiled :class:`seisrack.model.FrameModel` (any levels, bays, pallets).
        ag: (n_steps + 1,) [m/s²] horizontal ground acceleration on the grid ``k dt``.
        dt: [s] analysis step (= the grid step of ``ag``).
        mu: None for rigidly attached pallets, else the friction coefficient of every pallet.
        k_init: [N/m] initial stiffness of the friction springs (mu given).
        system: OpenSees system of equations.
        max_wall_s: stop the analysis after this wall time [s] (status "timeout"); the
            rate (steps/s) is still reported.

    Returns a dict (JSON-serialisable): ``status`` ("ok", "failed_steps": some steps forced
    through, "timeout", or "unavailable: ..." without openseespy), ``wall_time_s`` (build +
    analysis), ``build_time_s``, ``analysis_time_s``, ``n_steps``, ``steps_done``,
    ``steps_per_s``, ``peak_beam_displacement_m`` ((n_level,) list [m]: max over time of |mean
    ux of the level's nodes| relative to the ground, as seisrack's
    ``RackResponse.beam_displacement``), ``retried_steps``, ``failed_steps``, ``n_equations``
    and ``settings``.
    """
    ag = np.asarray(ag, dtype=float)
    n_steps = int(ag.size - 1)
    n_level = model.n_level
    out: dict[str, Any] = {
        "program": "OpenSeesPy", "status": "ok", "wall_time_s": math.nan,
        "build_time_s": math.nan, "analysis_time_s": math.nan, "n_steps": n_steps,
        "steps_done": 0, "steps_per_s": math.nan, "peak_beam_displacement_m": [math.nan] * n_level,
        "retried_steps": 0, "failed_steps": 0, "n_equations": 0,
    }
    try:
        ops = osr._ops()
        out["version"] = osr.opensees_version()
    except ImportError as exc:
        out["status"] = f"unavailable: {exc} (pip install '.[bench]'; needs libblas3 liblapack3)"
        return out
    rigid = mu is None
    t0 = time.perf_counter()
    rack = osr.build_from_export(model, mu=None if rigid else float(mu), k_init=k_init,
                                 pallets="rigid" if rigid else "friction")
    osr.setup_analysis(ag, dt, system=system, tol=tol, max_iter=max_iter, linear=rigid)
    build_time = time.perf_counter() - t0

    levels = [[int(n) for n in lv] for lv in rack.level_nodes]
    peak = np.zeros(n_level)
    node_disp = ops.nodeDisp
    retried = failed = done = 0
    t1 = time.perf_counter()
    for step in range(1, n_steps + 1):
        outcome = osr.advance(step * dt, dt, tol, max_iter)
        retried += outcome != osr.STEP_OK
        failed += outcome == osr.STEP_FAILED
        done = step
        for lv, nodes in enumerate(levels):
            d = abs(sum(node_disp(n, 1) for n in nodes) / len(nodes))
            if d > peak[lv]:
                peak[lv] = d
        if max_wall_s is not None and time.perf_counter() - t1 > max_wall_s:
            break
    analysis_time = time.perf_counter() - t1
    n_eq = _n_equations(ops)
    ops.wipe()
    if done < n_steps:
        out["status"] = "timeout"
    elif failed:
        out["status"] = "failed_steps"
    out.update(
        wall_time_s=build_time + analysis_time, build_time_s=build_time,
        analysis_time_s=analysis_time, steps_done=done,
        steps_per_s=done / analysis_time if analysis_time > 0 else math.nan,
        peak_beam_displacement_m=peak.tolist(), retried_steps=retried, failed_steps=failed,
        n_equations=n_eq,
        settings={
            "pallets": "rigid (equalDOF ux)" if rigid else "friction: zeroLength ElasticPP",
            "mu": mu, "k_init_N_m": None if rigid else k_init, "dt_s": dt, "system": system,
            "algorithm": "Linear -factorOnce" if rigid else "Newton (+ fallbacks)",
            "test": None if rigid else f"NormDispIncr {tol:g} {max_iter}",
            "integrator": "Newmark 0.5 0.25", "constraints": "Transformation",
            "numberer": "RCM", "element": "dispBeamColumn, Elastic section, Legendre 3, -cMass",
            "rayleigh": list(model.damping_coefficients),
            "model": "seisrack export opensees script",
        },
    )
    return out


def _n_equations(ops) -> int:  # noqa: ANN001
    try:
        return int(ops.systemSize())
    except Exception:  # noqa: BLE001 - older openseespy has no systemSize
        return 0


# --- stand-alone timing ----------------------------------------------------------------------

def warehouse_rack(levels: int = 10, bays: int = 20):
    """The scale benchmark's large rack: paper rack materials, ``levels`` x 1.5 m, ``bays`` x
    2.7 m, two 800 kg pallets (width 1.2 m) per bay and level, mu 0.3."""
    from seisrack.model import compile_rack
    from seisrack.model.load import rack_from_dict

    d = tomllib.loads((ROOT / "examples" / "paper_rack.toml").read_text())
    d["title"] = f"{levels} levels x {bays} bays, {2 * levels * bays} pallets"
    d["geometry"].update(levels=[1.5] * levels, bays=[2.7] * bays, subdivisions=2)
    d["sections"]["upright"] = {"A": 1.2e-3, "I": 1.6e-6}
    d["sections"]["beam"] = {"A": 1.0e-3, "I": 2.5e-6}
    d["pallets"] = [
        {"mass": 800.0, "bay": b, "level": lv, "position": x, "mu_static": 0.3,
         "mu_dynamic": 0.3, "width": 1.2}
        for lv in range(1, levels + 1) for b in range(1, bays + 1) for x in (0.675, 2.025)
    ]
    return compile_rack(rack_from_dict(d))


def elcentro(seconds: float, dt: float) -> np.ndarray:
    """(n,) [m/s²] the first ``seconds`` of El Centro 1940 N-S, linearly interpolated to ``dt``."""
    from seisrack.motion import load_builtin_record

    rec = load_builtin_record("elcentro_1940_ns")
    t = np.arange(int(round(seconds / dt)) + 1) * dt
    return np.interp(t, np.arange(rec.accel.size) * rec.dt, rec.accel)


def main(argv: list[str] | None = None) -> None:
    from seisrack.model import compile_rack, load_rack

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=20.0, help="of El Centro (default 20)")
    ap.add_argument("--dt", type=float, default=0.005)
    ap.add_argument("--max-wall", type=float, default=600.0, help="per run [s] (default 600)")
    ap.add_argument("--racks", default="3x3,10x20", help="comma list of 3x3 and/or 10x20")
    args = ap.parse_args(argv)
    ag = elcentro(args.seconds, args.dt)
    racks = {"3x3": lambda: compile_rack(load_rack(ROOT / "examples/three_level_rack.toml")),
             "10x20": warehouse_rack}
    for name in args.racks.split(","):
        model = racks[name]()
        for mu in (None, 0.3):
            r = run_opensees(model, ag, args.dt, mu, max_wall_s=args.max_wall)
            summary = {k: r[k] for k in ("status", "wall_time_s", "steps_done", "n_steps",
                                         "steps_per_s", "failed_steps", "retried_steps",
                                         "n_equations")}
            summary["peak_beam_displacement_mm"] = [
                round(1e3 * x, 3) for x in r["peak_beam_displacement_m"]]
            print(json.dumps({"rack": name, "n_dof": model.n_dof, "pallets": model.n_pallets,
                              "mu": mu, **summary}), flush=True)


if __name__ == "__main__":
    main()
