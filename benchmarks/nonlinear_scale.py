"""Nonlinear connections at warehouse scale (issue 22's nonlinear targets), measured as they
stand: the default engines (the 1D Newmark kernel with hinges in 2D, the planar kernel with
hinges in 3D; the local engine does not take hinges), one BLAS thread, numba warm, each case in
its own process (peak memory = its max RSS). Reports numbers; never asserts on time.

Cases (the issue's wording, and what is run):
- "the nonlinear paper rack with sliding pallets (mu 0.3, El Centro): <= 2x the linear run":
  ``examples/paper_rack_nonlinear.toml`` and ``examples/paper_rack.toml``, both with mu 0.3,
  El Centro 1940 N-S, 30 s, dt 5 ms, ``save_every=1`` (as ``benchmarks/scale.py``), best of 5;
- "2D warehouse example with every connector and base nonlinear (bilinear), 400 pallets of
  which most slide, 20 s: <= 10 s": ``examples/warehouse_rack.toml`` with bilinear laws on
  every connector (M_y 7 kN·m, 10 mrad on the doubled 700 kN·m/rad) and base plate (M_y
  6 kN·m), hardening 3 %, mu 0.15 (so that pallets slide), one EC8 component (ag 0.25 g,
  ground C, seed 1), 20 s;
- "3D 5 x 10 example with nonlinear connectors: <= 20 s": the frames of
  ``examples/warehouse_rack_3d.toml`` at 5 bays x 10 levels (150 pallets) and the example
  itself (10 bays x 5 levels, 150 pallets), bilinear connectors (M_y 3.5 kN·m, 10 mrad on
  350 kN·m/rad) and base plates (M_y 3 kN·m), hardening 3 %, two EC8 components (seeds 1
  and 2), 20 s.
The yield moments are illustrative (about 10 mrad of elastic rotation), not catalogue values.
Writes ``benchmarks/results/nonlinear_scale.md``. Run::

    python benchmarks/nonlinear_scale.py [--seconds 20] [--out FILE] [--cases paper,2d_warehouse]

It takes about 45 min on a 2-core machine, most of it the 3D cases (``--cases``: a subset).
"""

from __future__ import annotations

import argparse
import dataclasses
import datetime as dt
import json
import os
import platform
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent

_LAWS = """
[hysteresis.beam_to_upright]
law = "bilinear"
yield_moment = {conn}
hardening_ratio = 0.03

[hysteresis.base]
law = "bilinear"
yield_moment = {base}
hardening_ratio = 0.03
"""


def _edit(text: str, old: str, new: str, name: str) -> str:
    if old not in text:
        raise SystemExit(f"{name} changed: {old!r} not found")
    return text.replace(old, new)


def _variant(tmp: Path, case: str) -> Path:
    """The rack file of a warehouse case, written into ``tmp``."""
    if case == "2d_warehouse":
        name = "examples/warehouse_rack.toml"
        text = (ROOT / name).read_text(encoding="utf-8")
        text = _edit(text, "mu_static = 0.3\nmu_dynamic = 0.3",
                     "mu_static = 0.15\nmu_dynamic = 0.15", name)
        text = _edit(text, "[damping]", _LAWS.format(conn=7000.0, base=6000.0) + "\n[damping]",
                     name)
    else:
        name = "examples/warehouse_rack_3d.toml"
        text = (ROOT / name).read_text(encoding="utf-8")
        text = _edit(text, "[damping]", _LAWS.format(conn=3500.0, base=3000.0) + "\n[damping]",
                     name)
        if case == "3d_5x10":
            text = _edit(text, "bays = {count = 10,", "bays = {count = 5,", name)
            text = _edit(text, "levels = {count = 5,", "levels = {count = 10,", name)
    out = tmp / f"{case}.toml"
    out.write_text(text, encoding="utf-8")
    return out


def _ec8(seconds: float, two: bool):  # noqa: ANN202
    from seisrack.motion import generate_ec8_record
    from seisrack.motion.components import combine

    a = generate_ec8_record(ag=0.25, duration=20.0, dt=0.01, seed=1)
    n = int(round(seconds / a.dt)) + 1
    if not two:
        return dataclasses.replace(a, accel=a.accel[:n])
    b = generate_ec8_record(ag=0.25, duration=20.0, dt=0.01, seed=2)
    mo = combine(a, b)
    return mo.__class__(mo.x[:n], mo.z[:n], None, mo.dt, mo.names)


def _summary(r) -> dict:  # noqa: ANN001
    h = r.history
    peaks = r.pallet_peak_sliding()
    out = {"method": h.method, "basis": h.basis.get("size"),
           "basis_error": h.basis.get("static_energy_error"),
           "capped": h.basis.get("capped_directions"), "events": len(h.events),
           "slid": int((peaks > 1e-3).sum()), "peak": float(peaks.max()) if peaks.size else 0.0,
           "status": h.status, "energy": float(h.energy_error()), "work": dict(h.work)}
    if r.hinges is not None:
        duct = [p["ductility"] for p in r.hinges.peaks() if p.get("ductility") is not None]
        out["yielded"] = int(sum(d > 1.0 for d in duct))
        out["hinges"] = len(r.hinges.labels)
        out["ductility"] = float(max(duct)) if duct else 0.0
    return out


def run_case(case: str, path: str, seconds: float) -> dict:
    """One case in this process (called through ``--case``)."""
    from threadpoolctl import threadpool_limits

    from seisrack.analysis import run_rack
    from seisrack.model import compile_rack, load_rack
    from seisrack.model.spec import with_friction

    out: dict = {}
    with threadpool_limits(1):
        if case == "paper":
            sys.path.insert(0, str(HERE))
            from scale import DT, record

            rec = record(30.0, 1.0)
            for label, name in (("linear", "paper_rack.toml"),
                                ("nonlinear", "paper_rack_nonlinear.toml")):
                model = compile_rack(with_friction(load_rack(ROOT / "examples" / name), 0.3))
                run_rack(model, rec, dt=DT)  # warm
                cpus = []
                for _ in range(5):
                    c0 = time.process_time()
                    r = run_rack(model, rec, dt=DT)
                    cpus.append(time.process_time() - c0)
                out[label] = {"cpu": min(cpus), "all": cpus, "dofs": model.n_dof,
                              "pallets": model.n_pallets, **_summary(r)}
        else:
            model = compile_rack(load_rack(Path(path)))
            mo = _ec8(seconds, two=case != "2d_warehouse")
            warm = _ec8(0.5, two=case != "2d_warehouse")
            run_rack(model, warm, save_every=None, throw=False)  # numba and the cached basis
            c0, w0 = time.process_time(), time.perf_counter()
            r = run_rack(model, mo, save_every=None, throw=False)
            out.update(cpu=time.process_time() - c0, wall=time.perf_counter() - w0,
                       dofs=model.n_dof, pallets=model.n_pallets, **_summary(r))
    out["max_rss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    return out


def _spawn(case: str, path: Path | None, seconds: float) -> dict:
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    res = subprocess.run([sys.executable, __file__, "--case", case, str(path or "-"),
                          str(seconds)], capture_output=True, text=True, env=env, check=False)
    if res.returncode != 0:
        return {"error": res.stderr.strip().splitlines()[-1] if res.stderr else "failed"}
    return json.loads(res.stdout.strip().splitlines()[-1])


def _work(d: dict) -> str:
    """Trials (location trials) / factorisations, the kernel's work counters; – for none."""
    w = d.get("work") or {}
    if "trials" not in w:
        return "–"
    return f"{w['trials']} ({w['location_trials']}) / {w.get('factorisations', '–')}"


def _row(label: str, target: str, d: dict) -> str:
    if "error" in d:
        return (f"| {label} | {target} | – | – | – | – | – | – | – | – | – | – | "
                f"failed: {d['error']} |")
    be = d.get("basis_error")
    return (f"| {label} | {target} | {d['dofs']} | {d['pallets']} | {d['method']} | "
            f"{d['basis']} ({'–' if be is None else f'{be:.3g}'}) | {d['events']} | "
            f"{d['slid']} | {d.get('yielded', '–')}/{d.get('hinges', '–')} "
            f"({d.get('ductility', 0.0):.2f}) | {d['energy']:.1e} | {_work(d)} | "
            f"{d['max_rss_mb']:.0f} MB | **{d['cpu']:.2f} s** |")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seconds", type=float, default=20.0)
    ap.add_argument("--out", default=str(HERE / "results" / "nonlinear_scale.md"))
    ap.add_argument("--case", nargs=3, default=None, help=argparse.SUPPRESS)
    ap.add_argument("--cases", default="paper,2d_warehouse,3d_example,3d_5x10",
                    help="comma-separated cases to run (the others are reported as not run)")
    args = ap.parse_args()
    if args.case:
        case, path, seconds = args.case
        print(json.dumps(run_case(case, path, float(seconds))))
        return
    t0 = time.time()
    load0 = os.getloadavg()
    res: dict = {}
    with tempfile.TemporaryDirectory() as tmp:
        wanted = set(args.cases.split(","))
        res["paper"] = (_spawn("paper", None, 30.0) if "paper" in wanted
                        else {"error": "not run (--cases)"})
        for case in ("2d_warehouse", "3d_example", "3d_5x10"):
            res[case] = (_spawn(case, _variant(Path(tmp), case), args.seconds)
                         if case in wanted else {"error": "not run (--cases)"})
            print(case, res[case], flush=True)
    load1 = os.getloadavg()
    commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"],
                            capture_output=True, text=True, check=False).stdout.strip()
    s = args.seconds
    lines = [
        "# Nonlinear connections at warehouse scale (issue 22's nonlinear targets)", "",
        f"Written by `benchmarks/nonlinear_scale.py` ({dt.datetime.now(dt.UTC):%Y-%m-%d %H:%M}"
        f" UTC, {(time.time() - t0) / 60:.1f} min) at commit {commit}. Reports numbers; never "
        "asserts on time.", "",
        f"- Machine: {platform.machine()}, {os.cpu_count()} cores, {platform.platform()}, "
        f"Python {platform.python_version()}; one BLAS thread; numba warm.",
        f"- Load average (1, 5, 15 min) before: {', '.join(f'{x:.2f}' for x in load0)}; after: "
        f"{', '.join(f'{x:.2f}' for x in load1)} (CPU time of the process; a shared machine).",
        "- Default engines (the local engine takes no hinges). Basis: its size and the largest "
        "static energy error of the loads' static responses it leaves out (0: every direction "
        "kept). Yielded: hinges with a ductility demand above 1, of all, and the largest.", "",
        "| case | target | DOFs | pallets | method | basis (static error) | events | pallets "
        "slid > 1 mm | hinges yielded (max ductility) | energy error | trials (locating) / "
        "factorisations | peak memory | run CPU |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    p = res["paper"]
    if "error" in p:
        lines.append(_row("paper rack, mu 0.3, El Centro 30 s", "", p))
    else:
        for label in ("linear", "nonlinear"):
            d = dict(p[label], max_rss_mb=p["max_rss_mb"])
            lines.append(_row(f"paper rack {label}, mu 0.3, El Centro 30 s (best of 5)",
                              "ratio <= 2" if label == "nonlinear" else "", d))
    lines.append(_row(f"2D warehouse, bilinear everywhere, mu 0.15, EC8 {s:g} s",
                      "<= 10 s", res["2d_warehouse"]))
    lines.append(_row(f"3D example 10 x 5, bilinear, EC8 pair {s:g} s", "", res["3d_example"]))
    lines.append(_row(f"3D 5 x 10, bilinear, EC8 pair {s:g} s", "<= 20 s", res["3d_5x10"]))
    if "error" not in p:
        ratio = p["nonlinear"]["cpu"] / p["linear"]["cpu"]
        lines += ["", f"- Nonlinear / linear paper rack (target <= 2): **{ratio:.1f}x** "
                  f"({p['nonlinear']['events']} events against {p['linear']['events']})."]
    Path(args.out).write_text("\n".join(lines) + "\n", encoding="utf-8")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
