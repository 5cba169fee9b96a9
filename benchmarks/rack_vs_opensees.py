"""seisrack against OpenSeesPy on the paper rack (issue #5, item 5): speed and peak results.

Both programs get the same compiled rack (``examples/paper_rack.toml``: nodes, members, semi-rigid
springs, consistent member mass, pallet masses, stiffness-proportional damping C = a0 M + a1 K),
the same ground acceleration and the same step dt = 5 ms:

- seisrack: ``run_rack(model, record, dt=0.005, rigid_companion=False)``, numba warm, best of
  ``--repeat`` runs (it includes the recovery of base shear and upright moments);
- OpenSees: the script written by ``seisrack export opensees`` for the same rack, executed by
  ``benchmarks/opensees_rack.py`` (``build_from_export``: dispBeamColumn + Elastic section with
  -cMass, zeroLength rotational springs, pallets on ElasticPP zeroLength "friction" springs of
  initial stiffness kInit), then Newmark average acceleration + Newton, one run, build +
  analysis. The elasticBeamColumn demonstration rows use the hand-built ``osr.build`` (the
  export never writes that element).

Records: the EC8 Type 1 / ground C / 0.3 g / 15 s synthetic (seed 1, dt 5 ms; the paper's §IV
motion) and El Centro 1940 NS (dt 10 ms, run at 5 ms). Friction: mu = 100 (no sliding), 0.6,
0.3 (static = dynamic); OpenSees at kInit = 1e8 and 1e9 N/m.

Writes ``benchmarks/results/rack_vs_opensees.md`` and the parity reference
``tests/data/opensees_reference.json`` (El Centro, first 10 s, mu = 100), then prints the table.
Reports; never asserts. Run: ``python benchmarks/rack_vs_opensees.py`` (needs openseespy).
"""

from __future__ import annotations

import argparse
import datetime as _dt
import importlib.metadata
import json
import os
import platform
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import opensees_rack as osr  # noqa: E402
from seisrack.analysis.rack import run_rack  # noqa: E402
from seisrack.dynamics import Sliders, simulate  # noqa: E402
from seisrack.model import compile_rack, load_rack, with_friction  # noqa: E402
from seisrack.motion import Record, generate_ec8_record, load_builtin_record  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
RACK = ROOT / "examples" / "paper_rack.toml"
RESULTS = ROOT / "benchmarks" / "results" / "rack_vs_opensees.md"
REFERENCE = ROOT / "tests" / "data" / "opensees_reference.json"
DT = 0.005
MUS = (osr.NO_SLIDING_MU, 0.6, 0.3)
K_INITS = (1e8, 1e9)
#: the parity check of tests/test_opensees_parity.py
PARITY_RECORD = "elcentro_1940_ns"
PARITY_SECONDS = 10.0
PARITY_K_INIT = 1e9


def records(elcentro_seconds: float | None = None) -> list[Record]:
    ec8 = generate_ec8_record(type=1, ground="C", ag=0.3, duration=15, dt=0.005, seed=1)
    elc = load_builtin_record(PARITY_RECORD)
    if elcentro_seconds is not None:
        elc = truncate(elc, elcentro_seconds)
    return [ec8, elc]


def truncate(rec: Record, seconds: float) -> Record:
    n = int(round(seconds / rec.dt)) + 1
    return Record(rec.accel[:n], rec.dt, f"{rec.name} (first {seconds:g} s)",
                  provenance=rec.provenance)


def seisrack_run(model, rec: Record, repeat: int):
    """(response, best run_rack wall time, best engine-only wall time)."""
    run_rack(model, rec, dt=DT, rigid_companion=False)  # warm-up (numba compile, caches)
    best, res = np.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        res = run_rack(model, rec, dt=DT, rigid_companion=False)
        best = min(best, time.perf_counter() - t0)
    # the stick-slip engine alone, as run_rack calls it (no recovery of forces and moments)
    k = int(round(rec.dt / DT))
    t = np.arange((rec.n - 1) * k + 1) * DT
    ag = np.interp(t, rec.time, rec.accel)
    sl = Sliders(model.pallet_dofs[:, 0, 0], model.pallet_mass, model.pallet_mu_static,
                 model.pallet_mu_dynamic)
    best_engine = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        simulate(model.M, model.C, model.K, sl, dt=DT, ground_accel=ag, influence=model.r_x,
                 g=model.g)
        best_engine = min(best_engine, time.perf_counter() - t0)
    return res, best, best_engine


def opensees_analyze_only(model, rec: Record, k_init: float) -> float | None:
    """OpenSees at its fastest: build + one ``analyze(n, dt)`` call, no read-out, no fallback.

    None if that call stopped early (a step failed to converge without the fallbacks)."""
    ops = osr._ops()
    t0 = time.perf_counter()
    osr.build_from_export(model, k_init=k_init)
    ops.timeSeries("Path", 1, "-dt", float(rec.dt), "-values", *np.asarray(rec.accel).tolist())
    ops.pattern("UniformExcitation", 1, 1, "-accel", 1)
    ops.constraints("Transformation")
    ops.numberer("RCM")
    ops.system("BandGeneral")
    ops.integrator("Newmark", 0.5, 0.25)
    ops.test("NormDispIncr", 1e-10, 25)
    ops.algorithm("Newton")
    ops.analysis("Transient")
    ok = ops.analyze(int(round(rec.duration / DT)), DT)
    elapsed = time.perf_counter() - t0
    ops.wipe()
    return elapsed if ok == 0 else None


def peaks_of(p: dict[str, Any]) -> dict[str, float]:
    return {
        "disp": p["beam_displacement_m"],
        "acc": p["beam_acceleration_m_s2"],
        "force": p["total_friction_force_N"],
        "slide": float(max(p["pallet_sliding_m"])),
        "resid": float(max(np.abs(p["pallet_residual_m"]))),
    }


def machine() -> dict[str, str]:
    cpu = platform.processor() or ""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass

    def ver(name: str) -> str:
        try:
            return importlib.metadata.version(name)
        except importlib.metadata.PackageNotFoundError:
            return "not installed"

    return {
        "cpu": f"{cpu} ({os.cpu_count()} logical CPUs)",
        "os": platform.platform(),
        "python": platform.python_version(),
        "numpy": np.__version__,
        "numba": ver("numba"),
        "seisrack": ver("seisrack"),
        "openseespy": ver("openseespy"),
    }


def pct(a: float, b: float) -> str:
    if b == 0:
        return "—" if a == 0 else "∞"
    return f"{100.0 * (a / b - 1.0):+.2f}"


def run_all(args: argparse.Namespace) -> tuple[list[dict[str, Any]], list[str]]:
    spec = load_rack(RACK)
    rows: list[dict[str, Any]] = []
    for rec in records(args.elcentro_seconds):
        for mu in MUS:
            model = compile_rack(with_friction(spec, mu))
            res, t_sr, t_eng = seisrack_run(model, rec, args.repeat)
            p_sr = peaks_of(res.peaks())
            n_slip = sum(1 for e in res.events if e.kind == "slip")
            rows.append(dict(record=rec.name, mu=mu, solver="seisrack", k=None, wall=t_sr,
                             ratio=None, failed=None, retried=None, n_slip=n_slip,
                             engine=t_eng, fast=None, **p_sr))
            print(f"[{rec.name}] mu={mu:g} seisrack {t_sr:.3f} s (engine {t_eng:.3f} s)",
                  flush=True)
            variants = [(k, "disp") for k in K_INITS]
            if args.elastic_demo and mu == osr.NO_SLIDING_MU:
                variants.append((1e9, "elastic"))
            for k, element in variants:
                o = osr.run(model, rec, k_init=k, dt=DT, element=element)
                p_os = peaks_of(o.peaks())
                fast = (opensees_analyze_only(model, rec, k)
                        if k == 1e8 and element == "disp" else None)
                if fast is None and k == 1e8 and element == "disp":
                    fast = "stopped"
                label = "OpenSees" if element == "disp" else "OpenSees elasticBeamColumn*"
                rows.append(dict(record=rec.name, mu=mu, solver=label, k=k, wall=o.wall_time_s,
                                 ratio=o.wall_time_s / t_sr, failed=o.failed_steps,
                                 retried=o.retried_steps, n_slip=None, ref=p_sr,
                                 engine=None, fast=fast, eng_ref=t_eng, **p_os))
                print(f"[{rec.name}] mu={mu:g} {label} kInit={k:.0e} {o.wall_time_s:.2f} s "
                      f"(x{o.wall_time_s / t_sr:.1f}), failed {o.failed_steps}, "
                      f"retried {o.retried_steps}", flush=True)
    return rows, [r.name for r in records(args.elcentro_seconds)]


def table(rows: list[dict[str, Any]]) -> str:
    head = ("| record | μ | solver | kInit [N/m] | wall [s] | OpenSees / seisrack | "
            "engine-only / analyze-only [s] | ratio of those | "
            "peak disp [mm] (Δ %) | peak abs. acc [m/s²] (Δ %) | peak total friction [kN] "
            "(Δ %) | max sliding [mm] | failed / retried steps |")
    sep = "|" + "---|" * 13
    out = [head, sep]
    for r in rows:
        ref = r.get("ref")

        def cell(key: str, scale: float, fmt: str, r: dict[str, Any] = r, ref=ref) -> str:
            v = f"{r[key] * scale:{fmt}}"
            return v if ref is None else f"{v} ({pct(r[key], ref[key])})"

        mu = "100 (no sliding)" if r["mu"] == osr.NO_SLIDING_MU else f"{r['mu']:g}"
        k = "—" if r["k"] is None else f"{r['k']:.0e}"
        ratio = "—" if r["ratio"] is None else f"{r['ratio']:.0f}×"
        steps = "—" if r["failed"] is None else f"{r['failed']} / {r['retried']}"
        if r["engine"] is not None:
            lean, lean_ratio = f"{r['engine']:.3f}", "—"
        elif r["fast"] == "stopped":
            lean, lean_ratio = "stops at 1st failed step", "—"
        elif r["fast"] is not None:
            lean, lean_ratio = f"{r['fast']:.3f}", f"{r['fast'] / r['eng_ref']:.0f}×"
        else:
            lean, lean_ratio = "—", "—"
        out.append(
            f"| {r['record']} | {mu} | {r['solver']} | {k} | {r['wall']:.3f} | {ratio} | "
            f"{lean} | {lean_ratio} | "
            f"{cell('disp', 1e3, '.2f')} | {cell('acc', 1.0, '.3f')} | "
            f"{cell('force', 1e-3, '.3f')} | {r['slide'] * 1e3:.3f} | {steps} |"
        )
    return "\n".join(out)


def write_reference(spec_path: Path) -> dict[str, Any]:
    """OpenSees peak beam displacement of the parity case, with provenance."""
    spec = load_rack(spec_path)
    model = compile_rack(with_friction(spec, osr.NO_SLIDING_MU))
    rec = truncate(load_builtin_record(PARITY_RECORD), PARITY_SECONDS)
    out: dict[str, Any] = {
        "description": (
            "OpenSeesPy peak horizontal beam-level displacement (mean ux of the level's nodes, "
            "relative to the ground) of examples/paper_rack.toml with every pallet held "
            "(mu = 100), El Centro 1940 NS, first 10 s, dt = 5 ms. Written by "
            "benchmarks/rack_vs_opensees.py; read by tests/test_opensees_parity.py."
        ),
        "rack": "examples/paper_rack.toml",
        "record": PARITY_RECORD,
        "record_seconds": PARITY_SECONDS,
        "dt_s": DT,
        "mu": osr.NO_SLIDING_MU,
        "peak_beam_displacement_m": {},
        "peak_beam_acceleration_m_s2": {},
        "failed_steps": {},
    }
    for k in K_INITS:
        o = osr.run(model, rec, k_init=k, dt=DT)
        p = o.peaks()
        out["peak_beam_displacement_m"][f"{k:.0e}"] = p["beam_displacement_m"]
        out["peak_beam_acceleration_m_s2"][f"{k:.0e}"] = p["beam_acceleration_m_s2"]
        out["failed_steps"][f"{k:.0e}"] = o.failed_steps
        settings = o.settings
    out["parity_k_init"] = f"{PARITY_K_INIT:.0e}"
    settings.pop("k_init_N_m", None)
    settings.pop("mu", None)
    out["opensees_model"] = settings | {
        "pallets": "horizontal mass on own node (uy, rz fixed), zeroLength ElasticPP to the beam "
                   "node, yield force mu m g; vertical mass on the beam node",
        "springs": "zeroLength Elastic rotational springs (-doRayleigh 1) between coincident "
                   "nodes tied by equalDOF 1 2 (beam ends) or to a fixed node (bases)",
        "excitation": "UniformExcitation dir 1, Path timeSeries at the record dt",
    }
    out["provenance"] = {
        "openseespy": importlib.metadata.version("openseespy"),
        "opensees": osr.opensees_version(),
        "date": _dt.date.today().isoformat(),
        "machine": machine(),
    }
    REFERENCE.parent.mkdir(parents=True, exist_ok=True)
    REFERENCE.write_text(json.dumps(out, indent=2) + "\n")
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=3, help="seisrack timing repeats (best of)")
    ap.add_argument("--elcentro-seconds", type=float, default=None,
                    help="truncate El Centro (default: the whole 40 s record)")
    ap.add_argument("--no-elastic-demo", dest="elastic_demo", action="store_false",
                    help="skip the elasticBeamColumn -cMass demonstration rows")
    ap.add_argument("--no-write", action="store_true", help="print only")
    args = ap.parse_args()

    rows, _ = run_all(args)
    ref = write_reference(RACK) if not args.no_write else None
    tab = table(rows)
    m = machine()
    cmd = "python benchmarks/rack_vs_opensees.py" + (" " + " ".join(sys.argv[1:])
                                                     if sys.argv[1:] else "")
    speed = [r["ratio"] for r in rows if r["k"] == 1e8 and r["solver"] == "OpenSees"]
    nosl = [abs(r["disp"] / r["ref"]["disp"] - 1) for r in rows
            if r["solver"] == "OpenSees" and r["mu"] == osr.NO_SLIDING_MU]
    lean = [r["fast"] / r["eng_ref"] for r in rows if isinstance(r.get("fast"), float)]
    summary = [
        f"- Speed, OpenSees kInit = 1e8 over seisrack run_rack: {min(speed):.0f}× to "
        f"{max(speed):.0f}× (target ≥ 50×: {'met' if min(speed) >= 50 else 'NOT met'}).",
        f"- Speed, OpenSees analyze-only (one analyze(n, dt) call, no read-out) over the "
        f"seisrack engine alone (simulate, no recovery): {min(lean):.0f}× to {max(lean):.0f}× "
        f"(no-sliding runs; with sliding the single call stops at the first failed step).",
        f"- No sliding (μ = 100), peak beam displacement: largest |Δ| = "
        f"{100 * max(nosl):.3f} % (target ≤ 1 %: {'met' if max(nosl) <= 0.01 else 'NOT met'}).",
        f"- Failed OpenSees steps (after fallbacks): "
        f"{sum(r['failed'] for r in rows if r['failed'] is not None)} in total.",
    ]
    if ref is not None:
        v = ref["peak_beam_displacement_m"][ref["parity_k_init"]]
        summary.append(f"- Parity reference written to tests/data/opensees_reference.json: "
                       f"{v * 1e3:.3f} mm (El Centro, first {PARITY_SECONDS:g} s, "
                       f"kInit {PARITY_K_INIT:.0e}).")
    text = "\n".join([
        "# seisrack vs OpenSeesPy — paper rack (issue #5)",
        "",
        f"Date: {_dt.date.today().isoformat()}. Machine: {m['cpu']}; {m['os']}; Python "
        f"{m['python']}, numpy {m['numpy']}, numba {m['numba']}, openseespy {m['openseespy']}.",
        "",
        f"Command: `{cmd}`",
        "",
        "Rack: examples/paper_rack.toml (2 bays × 1.8 m, 1 level at 2.0 m, 4 × 400 kg pallets, "
        "2 % stiffness-proportional damping at T1). dt = 5 ms in both programs. μ static = "
        "dynamic. Δ % = OpenSees relative to seisrack on the same record and μ. Wall time: "
        "seisrack `run_rack(..., rigid_companion=False)` best of "
        f"{args.repeat} (warm numba, includes recovery of base shear and moments); OpenSees "
        "build + step-by-step analysis with per-step read-out of the recorded quantities. "
        "Engine-only / analyze-only: seisrack `simulate()` alone (no recovery of forces) / "
        "OpenSees build + one `analyze(n, dt)` call with no read-out and no fallbacks "
        "(kInit = 1e8 rows; with sliding, Newton on ElasticPP fails some steps without the "
        "fallbacks, so the single call stops early and no time is given); their ratio is the "
        "solver-against-solver speed. "
        "* elasticBeamColumn -cMass: OpenSees 3.7.1 applies the ground-motion load of element "
        "mass twice (see benchmarks/opensees_rack.py); shown for the record only.",
        "",
        tab,
        "",
        *summary,
        "",
    ])
    if not args.no_write:
        RESULTS.parent.mkdir(parents=True, exist_ok=True)
        RESULTS.write_text(text)
    print()
    print(text)


if __name__ == "__main__":
    main()
