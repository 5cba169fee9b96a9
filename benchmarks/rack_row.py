"""A rack row in seconds? (issue 22): the local engine (``seisrack.dynamics.local``) beside
today's planar engine (``run_rack_3d``) on the example's frames, 20 s of two EC8 artificial
components (ag 0.25 g, ground C, seeds 1 and 2), one BLAS thread, numba warm.

Cases: the 150-pallet example (10 bays x 5 levels); the bays series 10, 20, 40, 80 at 5 levels
(fitted exponent of the run time); the levels series 5, 8, 12 at 20 bays; the issue's 40 x 8
row (960 pallets); the 2D warehouse example (400 pallets, linear connections) on the local
engine beside the 2D engine. Each case runs in its own process (peak memory = its max RSS);
the local engine's basis is built and timed apart from the run. Today's planar engine runs
where it finishes in reasonable time (up to 20 bays). Reports numbers; never asserts on time.
Writes ``benchmarks/results/rack_row.md``. Run::

    python benchmarks/rack_row.py [--quick] [--out FILE]
"""

from __future__ import annotations

import argparse
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


def _variant(tmp: Path, bays: int, levels: int) -> Path:
    text = (ROOT / "examples/warehouse_rack_3d.toml").read_text(encoding="utf-8")
    for old, new in (("bays = {count = 10,", f"bays = {{count = {bays},"),
                     ("levels = {count = 5,", f"levels = {{count = {levels},")):
        if old not in text:
            raise SystemExit(f"examples/warehouse_rack_3d.toml changed: {old!r} not found")
        text = text.replace(old, new)
    out = tmp / f"row_{bays}x{levels}.toml"
    out.write_text(text, encoding="utf-8")
    return out


def _motion(seconds: float, two: bool = True):  # noqa: ANN202
    """The EC8 pair (seeds 1 and 2) over ``seconds``; its down-aisle component alone unless
    ``two`` (a 2D rack takes one horizontal component)."""
    from seisrack.motion import generate_ec8_record
    from seisrack.motion.components import combine

    a = generate_ec8_record(ag=0.25, duration=20.0, dt=0.01, seed=1)
    b = generate_ec8_record(ag=0.25, duration=20.0, dt=0.01, seed=2)
    mo = combine(a, b)
    n = int(round(seconds / mo.dt)) + 1
    if not two:
        return mo.__class__(mo.x[:n], None, None, mo.dt, (mo.names[0], "", ""))
    return mo.__class__(mo.x[:n], mo.z[:n], None, mo.dt, mo.names)


def run_case(engine: str, path: str, seconds: float) -> dict:
    """One case in this process (called through ``--case``)."""
    from threadpoolctl import threadpool_limits

    from seisrack.model import compile_rack, load_rack

    model = compile_rack(load_rack(Path(path)))
    mo = _motion(seconds, two=model.ndm == 3)
    out: dict = {"dofs": model.n_dof, "pallets": model.n_pallets}
    with threadpool_limits(1):
        if engine == "planar":
            from seisrack.analysis import run_rack

            small = mo.__class__(mo.x[:201], mo.z[:201], None, mo.dt, mo.names)
            run_rack(model, small, save_every=None)  # warm: numba and the cached basis
            c0, w0 = time.process_time(), time.perf_counter()
            r = run_rack(model, mo, save_every=None)
            peaks = r.pallet_peak_sliding()
            out.update(cpu=time.process_time() - c0, wall=time.perf_counter() - w0,
                       basis=r.history.basis["size"], events=len(r.history.events),
                       peak=float(peaks.max()), falls=len(r.falls),
                       work=r.history.work, energy=r.history.energy_error(),
                       peaks=peaks.tolist(), fell=sorted(f.pallet for f in r.falls))
        else:
            from seisrack.analysis import prepare_run, run_rack

            c0 = time.process_time()
            # the design quantities' dense (basis, k) operators are left out on a long row, as
            # the engine-only call this benchmark made before (peaks, falls, levels kept)
            prep = prepare_run(model, engine="local", design=False)
            b = prep.basis
            out["basis_cpu"] = time.process_time() - c0
            small = mo.__class__(mo.x[:21], None if mo.z is None else mo.z[:21], None, mo.dt,
                                 mo.names)
            run_rack(model, small, dt=mo.dt / 2, engine="local", prepared=prep,
                     save_every=None)  # warm numba
            c0, w0 = time.process_time(), time.perf_counter()
            r = run_rack(model, mo, dt=mo.dt / 2, engine="local", prepared=prep,
                         save_every=None, throw=False)
            h = r.history
            peaks = r.pallet_peak_sliding()
            out.update(cpu=time.process_time() - c0, wall=time.perf_counter() - w0,
                       basis=b.size, block=int(b.bmax), slices=b.n_slices,
                       basis_error=b.error.get("static_energy_max"), events=len(h.events),
                       peak=float(peaks.max()), falls=len(r.falls),
                       work=h.work, energy=h.energy_error(), status=h.status,
                       peaks=peaks.tolist(), fell=sorted(f.pallet for f in r.falls))
    out["max_rss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    return out


def _spawn(engine: str, path: Path, seconds: float) -> dict:
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    res = subprocess.run([sys.executable, __file__, "--case", engine, str(path), str(seconds)],
                         capture_output=True, text=True, env=env, check=False)
    if res.returncode != 0:
        return {"error": res.stderr.strip().splitlines()[-1] if res.stderr else "failed"}
    return json.loads(res.stdout.strip().splitlines()[-1])


def _commit() -> str:
    try:
        return subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, check=True,
                              capture_output=True, text=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "?"


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--case", nargs=3, metavar=("ENGINE", "PATH", "SECONDS"))
    ap.add_argument("--quick", action="store_true", help="5 s of record, fewer cases")
    ap.add_argument("--out", default=str(HERE / "results" / "rack_row.md"))
    args = ap.parse_args()
    if args.case:
        print(json.dumps(run_case(args.case[0], args.case[1], float(args.case[2]))))
        return
    import numpy as np

    seconds = 5.0 if args.quick else 20.0
    commit = _commit()
    load0 = os.getloadavg()
    start = time.perf_counter()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        t = Path(tmp)
        cases = [(10, 5, True), (20, 5, True), (40, 5, False), (80, 5, False),
                 (20, 8, False), (20, 12, False), (40, 8, False)]
        if args.quick:
            cases = [(10, 5, True), (20, 5, False), (40, 5, False)]
        for bays, levels, with_planar in cases:
            path = _variant(t, bays, levels)
            label = f"3D {bays} x {levels}"
            rows.append((label, "local", _spawn("local", path, seconds)))
            print(rows[-1], flush=True)
            if with_planar:
                rows.append((label, "planar (today)", _spawn("planar", path, seconds)))
                print(rows[-1], flush=True)
        rows.append(("2D warehouse example", "local",
                     _spawn("local", ROOT / "examples/warehouse_rack.toml", seconds)))
    load1 = os.getloadavg()
    fit = _fit(rows, seconds)
    text = _report(rows, seconds, commit, load0, load1, time.perf_counter() - start, fit)
    Path(args.out).write_text(text, encoding="utf-8")
    print(text)
    del np


def _fit(rows, seconds):  # noqa: ANN001, ANN202
    import numpy as np

    out = {}
    for key, sel in (("bays", lambda lb: lb.endswith(" x 5")), ("levels",
                                                               lambda lb: "3D 20 x" in lb)):
        pts = [(lb, r["cpu"]) for lb, eng, r in rows if eng == "local" and sel(lb)
               and "cpu" in r]
        if len(pts) >= 2:
            x = [int(lb.split()[1]) if key == "bays" else int(lb.split()[3]) for lb, _ in pts]
            y = [c for _, c in pts]
            out[key] = (float(np.polyfit(np.log(x), np.log(y), 1)[0]), x)
    return out


def _report(rows, seconds, commit, load0, load1, elapsed, fit) -> str:  # noqa: ANN001
    import numpy as np

    lines = [
        "# A rack row: the local engine beside today's planar engine (issue 22)",
        "",
        f"Written by `benchmarks/rack_row.py` ({dt.datetime.now(dt.UTC):%Y-%m-%d %H:%M} UTC, "
        f"{elapsed / 60:.1f} min) at commit {commit}. Reports numbers; never asserts on time.",
        "",
        f"- Machine: {platform.machine()}, {os.cpu_count()} cores, {platform.platform()}, "
        f"Python {platform.python_version()}; one BLAS thread; numba warm.",
        f"- Load average (1, 5, 15 min) before: {', '.join(f'{x:.2f}' for x in load0)}; after: "
        f"{', '.join(f'{x:.2f}' for x in load1)} (a 2-core machine shared with other jobs: "
        "CPU times are the process's own, wall times include the waits).",
        f"- Record: two EC8 artificial accelerograms (type 1, ground C, ag 0.25 g, seeds 1 and 2),"
        f" {seconds:g} s at 0.01 s, down-aisle and cross-aisle; analysis dt 5 ms; peaks, falls "
        "and level displacements over every step.",
        "- Local engine: basis tol 0.03 (the default), half-bay slices, patch one bay each "
        "way; basis built once (its CPU time apart); energy error = max |input − (ΔKE + ΔSE "
        "+ damping + friction)| / max input.",
        "",
        "| rack | engine | DOFs | pallets | basis (largest block) | basis error | basis CPU | "
        "events | Newton its | factorisations | local solves (in retries) | "
        "inexact: frozen contacts / slipped at step end / frozen steps | falls | "
        "peak sliding | energy error | run CPU | wall | peak memory |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for label, eng, r in rows:
        if "error" in r and "cpu" not in r:
            lines.append(f"| {label} | {eng} | – | – | – | – | – | – | – | – | – | – | – | – | "
                         f"– | failed: {r['error']} | – | – |")
            continue
        w = r.get("work", {})
        blk = f" ({r['block']})" if "block" in r else ""
        be = f"{r['basis_error']:.3f}" if r.get("basis_error") is not None else "–"
        bc = f"{r['basis_cpu']:.1f} s" if "basis_cpu" in r else "–"
        en = f"{r['energy']:.1e}" if r.get("energy") is not None else "–"
        ls = f"{w['local_solves']} ({w.get('retry_local_solves', '–')})" \
            if "local_solves" in w else "–"
        inexact = (f"{w['frozen_contacts']} / {w.get('slipped_at_step_end', '–')} / "
                   f"{w.get('frozen_steps', '–')}") if "frozen_contacts" in w else "–"
        lines.append(
            f"| {label} | {eng} | {r['dofs']} | {r['pallets']} | {r['basis']}{blk} | {be} | "
            f"{bc} | {r['events']} | {w.get('newton_iterations', '–')} | "
            f"{w.get('factorisations', '–')} | {ls} | {inexact} | {r['falls']} | "
            f"{r['peak'] * 1e3:.1f} mm | {en} | {r['cpu']:.1f} s | {r['wall']:.1f} s | "
            f"{r['max_rss_mb']:.0f} MB |")
    lines.append("")
    by = {(lb, eng): r for lb, eng, r in rows}
    for lb, eng, r in rows:
        other = by.get((lb, "planar (today)"))
        if eng != "local" or other is None or "peaks" not in r or "peaks" not in other:
            continue
        a, b = np.asarray(r["peaks"]), np.asarray(other["peaks"])
        d = np.abs(a - b)
        tol = np.maximum(0.005 * b.max(), 1e-3)
        lines.append(
            f"- {lb}: local vs today's planar engine (its default Ritz basis, not tightened): "
            f"largest difference of a pallet's peak sliding {d.max() * 1e3:.2f} mm "
            f"({d.max() / max(b.max(), 1e-300) * 100:.2f} % of the largest peak), "
            f"{int((d > tol).sum())} of {d.size} pallets beyond 0.5 % of the peak or 1 mm; "
            f"falls {len(r['fell'])} vs {len(other['fell'])}"
            f"{' (same pallets)' if r['fell'] == other['fell'] else ' (different pallets)'}.")
    lines.append("")
    for key, (e, xs) in fit.items():
        lines.append(f"- Fitted exponent of the local engine's run CPU time against the number "
                     f"of {key} ({', '.join(map(str, xs))}): **{e:.2f}**.")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    main()
