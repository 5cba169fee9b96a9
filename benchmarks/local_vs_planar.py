"""The local engine against the planar engine with its basis tightened (issue 22, validation
item 2), on the example's frames: the 150-pallet example (10 bays x 5 levels) and a 20-bay
row, 20 s of two EC8 artificial components (ag 0.25 g, ground C, seeds 1 and 2), one BLAS
thread.

Reference: the default (planar) engine with its Ritz basis tightened (compression tolerance
``--ref-tol`` instead of 0.1, no size cap) at half the default step; beside it the same
engine with its default basis at both steps, so that the reference's own convergence is
seen. Acceptance of the issue: every
pallet's peak sliding within 0.5 % of the largest peak or 1 mm, the beam levels' peak
displacements within 0.5 %, the same fallen pallets with fall times within two steps.
Each run in its own process. Reports numbers; never asserts. Writes
``benchmarks/results/local_vs_planar.md``. Run::

    python benchmarks/local_vs_planar.py [--bays 10 20] [--seconds 20] [--ref-tol 0.03]
        [--runs engine:tol:dt,...] [--jobs N] [--out FILE]
"""

from __future__ import annotations

import argparse
import datetime as dt
import json
import os
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))


def run_case(path: str, seconds: float, engine: str, tol: float, step: float) -> dict:
    """One run in this process (called through ``--case``)."""
    from threadpoolctl import threadpool_limits

    import rack_row
    from seisrack.analysis import prepare_run, run_rack
    from seisrack.dynamics.run_basis import planar_basis
    from seisrack.model import compile_rack, load_rack

    model = compile_rack(load_rack(Path(path)))
    mo = rack_row._motion(seconds)  # noqa: SLF001
    out: dict = {}
    with threadpool_limits(1):
        if engine == "local":
            prep = prepare_run(model, engine="local", design=False)
            if tol > 0:  # a tightened local basis (compression tolerance; the default 0.1)
                from dataclasses import replace

                from seisrack.analysis.operators import rack_operators
                from seisrack.dynamics.local.racks import rack_basis

                bas = rack_basis(model, prep.sliders, tol=tol)
                prep = replace(prep, basis=bas,
                               ops=rack_operators(model, bas.phi, design=False))
            out["basis"] = int(prep.basis.size)
            kw = {"engine": "local"}
        else:
            prep0 = prepare_run(model, design=False)
            if tol > 0:
                loads = np.column_stack([model.M_sparse @ r for r in model.influence])
                bas = planar_basis(model.M_sparse, model.K_sparse, prep0.sliders, loads,
                                   tol=tol, max_size=100_000)
                prep = prepare_run(model, basis=bas, design=False)
            else:
                prep = prep0
            out["basis"] = int(prep.basis.w2.size)
            kw = {}
        c0 = time.process_time()
        r = run_rack(model, mo, dt=step, prepared=prep, save_every=None, throw=False, **kw)
        out["cpu"] = time.process_time() - c0
    h = r.history
    out.update(status=h.status, events=len(h.events), energy=h.energy_error(),
               peaks=r.pallet_peak_sliding().tolist(),
               levels=np.asarray(r._level_peak("beam_displacement")).tolist(),  # noqa: SLF001
               falls={str(f.pallet): f.time_s for f in r.falls})
    return out


def _spawn(*args: str) -> dict:
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    res = subprocess.run([sys.executable, __file__, "--case", *args], capture_output=True,
                         text=True, env=env, check=False)
    if res.returncode != 0:
        return {"error": (res.stderr.strip().splitlines() or ["failed"])[-1]}
    return json.loads(res.stdout.strip().splitlines()[-1])


def compare(run: dict, ref: dict, step: float) -> dict:
    """The issue's measures of ``run`` against ``ref``."""
    p, q = np.array(run["peaks"]), np.array(ref["peaks"])
    tol = np.maximum(0.005 * q.max(), 1e-3)
    lv, lr = np.array(run["levels"]), np.array(ref["levels"])
    on = lr > 1e-9
    fa, fb = run["falls"], ref["falls"]
    common = sorted(set(fa) & set(fb), key=int)
    dts = [abs(fa[k] - fb[k]) / step for k in common]
    return {"peak_diff_mm": 1e3 * float(np.abs(p - q).max()),
            "peak_diff_pct": 100 * float(np.abs(p - q).max() / q.max()),
            "beyond": int(np.sum(np.abs(p - q) > tol)),
            "level_pct": 100 * float(np.max(np.abs(lv[on] / lr[on] - 1))),
            "falls": (len(fa), len(fb), len(set(fa) ^ set(fb))),
            "fall_steps_max": max(dts, default=0.0)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bays", type=int, nargs="+", default=[10, 20])
    ap.add_argument("--seconds", type=float, default=20.0)
    ap.add_argument("--ref-tol", type=float, default=0.03)
    ap.add_argument("--runs", default=None,
                    help="engine:tol:dt,... (tol 0: the default basis); the last is the "
                         "reference (default: local at 5 and 2.5 ms, planar default at 5 and "
                         "2.5 ms, planar at --ref-tol and 2.5 ms)")
    ap.add_argument("--jobs", type=int, default=1, help="runs at once (each its own process)")
    ap.add_argument("--out", type=Path, default=HERE / "results" / "local_vs_planar.md")
    a = ap.parse_args()
    import rack_row

    t0, load0 = time.time(), os.getloadavg()
    commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"],
                            capture_output=True, text=True, check=False).stdout.strip()
    runs = [("local", 0.0, 0.005), ("local", 0.0, 0.0025), ("planar", 0.0, 0.005),
            ("planar", 0.0, 0.0025), ("planar", a.ref_tol, 0.0025)]
    if a.runs:
        runs = [(e, float(t), float(d)) for e, t, d in
                (r.split(":") for r in a.runs.split(","))]
    ref_e, ref_tol, ref_dt = runs[-1]
    lines = []
    with tempfile.TemporaryDirectory() as tmp:
        for bays in a.bays:
            path = rack_row._variant(Path(tmp), bays, 5)  # noqa: SLF001
            with ThreadPoolExecutor(max_workers=max(a.jobs, 1)) as pool:
                res = list(pool.map(lambda r, p=path: _spawn(str(p), str(a.seconds), r[0],
                                                               str(r[1]), str(r[2])), runs))
            print(bays, json.dumps([{k: v for k, v in r.items()
                                     if k not in ("peaks", "levels", "falls")}
                                    for r in res]), flush=True)
            ref = res[-1]
            for (e, tol, st), r in zip(runs, res, strict=True):
                name = f"{e}, " + (f"basis tol {tol}" if tol else "default basis") + \
                    f", dt {1e3 * st:g} ms"
                if "error" in r:
                    lines.append(f"| {bays} x 5 | {name} | " + " | ".join(["–"] * 10)
                                 + f" | failed: {r['error']} |")
                    continue
                c = compare(r, ref, 0.005) if r is not ref else None
                cells = ("reference", "–", "–", "–", "–", "–") if c is None else (
                    f"{c['peak_diff_mm']:.2f} mm ({c['peak_diff_pct']:.2f} %)",
                    str(c["beyond"]), f"{c['level_pct']:.3f} %",
                    f"{c['falls'][0]} / {c['falls'][1]}", str(c["falls"][2]),
                    f"{c['fall_steps_max']:.1f}")
                lines.append(f"| {bays} x 5 | {name} | {r['basis']} | {r['events']} | "
                             + " | ".join(cells) + f" | {r['energy']:.1e} | "
                             f"{r['cpu']:.1f} s | {r['status']} |")
    load1 = os.getloadavg()
    head = [
        "# The local engine against the planar engine with its basis tightened (issue 22)",
        "",
        f"Written by `benchmarks/local_vs_planar.py` "
        f"({dt.datetime.now(dt.UTC):%Y-%m-%d %H:%M} UTC, "
        f"{(time.time() - t0) / 60:.1f} min) at commit {commit}. Reports numbers; never "
        "asserts.",
        "",
        f"- Machine: 2 cores; one BLAS thread; load average before {load0[0]:.2f}, "
        f"after {load1[0]:.2f}.",
        f"- Record: two EC8 artificial accelerograms (type 1, ground C, ag 0.25 g, seeds 1 "
        f"and 2), {a.seconds:g} s, down-aisle and cross-aisle; the example's frames "
        "(`examples/warehouse_rack_3d.toml`) with 10 or 20 bays, 5 levels, 3 pallets per "
        "bay.",
        f"- Reference: the {ref_e} engine, basis at compression tolerance {ref_tol} "
        f"(the default 0.1; no size cap), dt {1e3 * ref_dt:g} ms. Differences are against it: the "
        "largest difference of a pallet's peak sliding (and in % of the largest peak), "
        "the pallets beyond 0.5 % of the largest peak or 1 mm, the largest relative "
        "difference of a beam level's peak displacement, falls (run / reference), pallets "
        "falling in one run only, the largest difference of a common fall time in 5 ms "
        "steps.",
        "",
        "| rack | engine | basis | events | largest peak difference | pallets beyond | "
        "level peaks | falls | falls in one only | fall time (steps) | energy error | "
        "run CPU | status |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    a.out.write_text("\n".join(head + lines) + "\n", encoding="utf-8")
    print(a.out.read_text(encoding="utf-8"))


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--case":
        path, seconds, engine, tol, step = sys.argv[2:7]
        print(json.dumps(run_case(path, float(seconds), engine, float(tol), float(step))))
    else:
        main()
