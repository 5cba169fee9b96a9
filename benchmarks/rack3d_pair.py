"""Paired process timing of the 150-pallet 3D example (``examples/warehouse_rack_3d.toml``)
against another checkout (issue 21: "no slower than before"). Each side runs in its own
process, alternated A B A B: compile the example, a 2 s warm run, then one 20 s run of the two
EC8 components (as ``benchmarks/rack3d.py``) timed by ``time.process_time``; the first pair
is not counted (file cache). Prints one line per process and the medians and pair ratios;
never asserts on time. Run::

    python benchmarks/rack3d_pair.py --base /tmp/base [--pairs 4] [--no-energy]

``--base``: the other checkout's root (its ``src`` goes first on the path of its processes;
a checkout before the energy balance runs without it whatever ``--no-energy`` says).
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def _one(examples: str, energy: bool) -> None:
    """One side: print ``RUN <cpu s> EVENTS <n> WORK <counters>``."""
    from threadpoolctl import threadpool_limits

    from seisrack.model import compile_rack, load_rack
    from seisrack.motion import generate_ec8_record
    from seisrack.motion.components import combine

    try:  # the checkout before the one-rack path
        from seisrack.analysis.rack3d import run_rack_3d as run
        kw: dict = {}
    except ImportError:
        from seisrack.analysis import run_rack as run
        kw = {"track_energy": energy}
    a = generate_ec8_record(ag=0.25, duration=20.0, dt=0.01, seed=1)
    b = generate_ec8_record(ag=0.25, duration=20.0, dt=0.01, seed=2)
    motion = combine(a, b)
    model = compile_rack(load_rack(Path(examples) / "warehouse_rack_3d.toml"))
    warm = motion.__class__(motion.x[:201], motion.z[:201], None, motion.dt, motion.names)
    with threadpool_limits(1):
        run(model, warm, save_every=None, basis="auto", **kw)
        c0 = time.process_time()
        resp = run(model, motion, save_every=None, basis="auto", **kw)
        cpu = time.process_time() - c0
    h = resp.history
    print(f"RUN {cpu:.4f} EVENTS {len(h.events)} WORK {h.work}", flush=True)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--base", help="root of the checkout to pair against (required)")
    ap.add_argument("--pairs", type=int, default=4, help="counted pairs (after one uncounted)")
    ap.add_argument("--no-energy", action="store_true")
    ap.add_argument("--one", default=None, help=argparse.SUPPRESS)  # internal: one side
    args = ap.parse_args()
    energy = not args.no_energy
    if args.one is not None:
        _one(args.one, energy)
        return
    if args.base is None:
        ap.error("--base is required")
    sides = {"base": Path(args.base).resolve(), "this": ROOT}
    times: dict[str, list[float]] = {"base": [], "this": []}
    for i in range(args.pairs + 1):
        for name, root in sides.items():
            env = dict(os.environ, PYTHONPATH=str(root / "src"))
            cmd = [sys.executable, __file__, "--one", str(root / "examples")]
            if not energy:
                cmd.append("--no-energy")
            load = os.getloadavg()[0]
            out = subprocess.run(cmd, env=env, check=True, capture_output=True,
                                 text=True).stdout.strip().splitlines()[-1]
            print(f"pair {i} {name} load {load:.2f} {out}", flush=True)
            if i > 0:
                times[name].append(float(out.split()[1]))
    ratios = [t / b for t, b in zip(times["this"], times["base"], strict=True)]
    print(f"median run: base {statistics.median(times['base']):.2f} s, this "
          f"{statistics.median(times['this']):.2f} s; pair ratios this/base "
          + ", ".join(f"{x:.3f}" for x in ratios)
          + f" (median {statistics.median(ratios):.3f})")


if __name__ == "__main__":
    main()
