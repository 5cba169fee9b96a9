"""Speed of 3D rack time histories with planar sliding pallets (issue 11): the 3D paper rack
and the 5-level x 10-bay warehouse rack (``examples/warehouse_rack_3d.toml``, 150 pallets)
under a 20 s two-component record (two EC8 artificial accelerograms, ag 0.25 g, ground C,
seeds 1 and 2), one BLAS thread, numba warm. Target: ≤ 10 s on one core for the warehouse
rack. No peer: no tool we know of runs rack time histories with planar stick–slip pallets.
Reports; never asserts on time. Writes ``benchmarks/results/rack3d.md``. Run::

    python benchmarks/rack3d.py [--skip-warehouse] [--ritz-tol TOL] [--out FILE]

``--ritz-tol`` replaces the Ritz basis' compression tolerance (default
``seisrack.dynamics.planar.PLANAR_RITZ_TOL``): a smaller basis, faster and less accurate.
"""

from __future__ import annotations

import argparse
import datetime as dt
import os
import platform
import subprocess
import time
from pathlib import Path

from threadpoolctl import threadpool_limits

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent


def _commit() -> str:
    try:
        return subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, check=True,
                              capture_output=True, text=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "?"


def _case(path: str, motion, mu: float | None = None, tol: float | None = None) -> dict:  # noqa: ANN001
    import numpy as np

    from seisrack.analysis.rack3d import run_rack_3d
    from seisrack.dynamics.planar import PlanarSliders, planar_basis
    from seisrack.model import compile_rack, load_rack, with_friction

    spec = load_rack(ROOT / path)
    if mu is not None:
        spec = with_friction(spec, mu, mu)
    model = compile_rack(spec)
    basis = "auto"
    if tol is not None:
        sl = PlanarSliders(model.pallet_dof_x, model.pallet_dof_z, model.pallet_mass,
                           model.pallet_mu_static, model.pallet_mu_dynamic)
        M = model.M_sparse
        basis = planar_basis(M, model.K_sparse, sl, np.column_stack([M @ model.r_x,
                                                                     M @ model.r_z]),
                             "reduced", tol=tol)
    run_rack_3d(model, motion.__class__(motion.x[:201], motion.z[:201], None, motion.dt,
                                        motion.names), save_every=None, basis=basis)  # warm
    t0, c0 = time.perf_counter(), time.process_time()
    resp = run_rack_3d(model, motion, save_every=None, basis=basis)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    h = resp.history
    return {"rack": path, "mu": "file" if mu is None else mu, "dofs": model.n_dof,
            "pallets": model.n_pallets, "basis": h.basis["size"], "events": len(h.events),
            "substeps": h.n_substeps, "falls": len(resp.falls), "wall": wall, "cpu": cpu,
            "peak": float(resp.peak_sliding[:, 2].max()) if resp.n_pallets else 0.0}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--skip-warehouse", action="store_true")
    ap.add_argument("--ritz-tol", type=float, default=None)
    ap.add_argument("--out", default=str(HERE / "results" / "rack3d.md"))
    args = ap.parse_args()
    from seisrack.motion import generate_ec8_record
    from seisrack.motion.components import combine

    a = generate_ec8_record(ag=0.25, duration=20.0, dt=0.01, seed=1)
    b = generate_ec8_record(ag=0.25, duration=20.0, dt=0.01, seed=2)
    motion = combine(a, b)
    load0 = os.getloadavg()
    commit = _commit()  # at the start: the code this process imports
    start = time.perf_counter()
    rows = []
    with threadpool_limits(1):
        rows.append(_case("examples/paper_rack_3d.toml", motion, tol=args.ritz_tol))
        if not args.skip_warehouse:
            rows.append(_case("examples/warehouse_rack_3d.toml", motion, tol=args.ritz_tol))
    load1 = os.getloadavg()
    lines = [
        "# 3D racks with planar sliding pallets: run time",
        "",
        f"Written by `benchmarks/rack3d.py` ({dt.datetime.now(dt.UTC):%Y-%m-%d %H:%M} UTC, "
        f"{(time.perf_counter() - start) / 60:.1f} min) at commit {commit}. Reports numbers; "
        "never asserts on time.",
        "",
        f"- Machine: {platform.machine()}, {os.cpu_count()} cores, {platform.platform()}, "
        f"Python {platform.python_version()}; one BLAS thread; numba kernels serial.",
        f"- Load average (1, 5, 15 min) before: {', '.join(f'{x:.2f}' for x in load0)}; "
        f"after: {', '.join(f'{x:.2f}' for x in load1)} (shared 2-core machine: tens of % "
        "of noise).",
        "- Record: two EC8 artificial accelerograms (type 1, ground C, ag 0.25 g, seeds 1 and "
        "2), 20 s at 0.01 s, down-aisle and cross-aisle; analysis dt 5 ms; `save_every=None` "
        "(peaks, falls and impacts over every step). One timed run after a 2 s warm-up.",
        f"- Ritz tolerance: {'default' if args.ritz_tol is None else args.ritz_tol}.",
        "- Peer: none (no tool we know of does rack time histories with planar stick–slip "
        "pallets; OpenSees has no planar friction pallet element).",
        "",
        "| rack | DOFs | pallets | basis | events | sub-steps | falls | peak sliding | wall | "
        "CPU | target |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        target = "≤ 10 s" if "warehouse" in r["rack"] else "–"
        lines.append(f"| {r['rack']} | {r['dofs']} | {r['pallets']} | {r['basis']} | "
                     f"{r['events']} | {r['substeps']} | {r['falls']} | "
                     f"{r['peak'] * 1e3:.1f} mm | {r['wall']:.2f} s | {r['cpu']:.2f} s | "
                     f"{target} |")
    text = "\n".join(lines) + "\n"
    out = Path(args.out)
    out.write_text(text, encoding="utf-8")
    print(text)


if __name__ == "__main__":
    main()
