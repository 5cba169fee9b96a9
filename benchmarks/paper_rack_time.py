"""Time one full ``run_rack`` of the paper rack (mu 0.3, 30 s El Centro, dt 5 ms), as
``case_paper`` in ``scale.py``: best of N CPU (``time.process_time``) and wall, one BLAS
thread, numba warm. Optional: ``--profile`` (cProfile of one run), ``--kernel`` (engine
``simulate`` alone vs the rest). Reports; never asserts on time. Run::

    python benchmarks/paper_rack_time.py [-n 15] [--save-every none] [--cold] [--profile]
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time
from pathlib import Path

import numpy as np
from threadpoolctl import threadpool_limits

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from scale import DT, ROOT, record  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("-n", type=int, default=15)
    ap.add_argument("--save-every", default="1")
    ap.add_argument("--profile", action="store_true")
    ap.add_argument("--cold", action="store_true",
                    help="a freshly compiled model for every run (compile not timed): "
                         "nothing cached per model (basis, operators)")
    ap.add_argument("--dump", default=None, help="save peaks to this .npz")
    args = ap.parse_args()
    save_every = None if args.save_every == "none" else int(args.save_every)

    from seisrack.analysis import run_rack
    from seisrack.model import compile_rack, load_rack
    from seisrack.model.spec import with_friction

    spec = with_friction(load_rack(ROOT / "examples" / "paper_rack.toml"), 0.3)
    model = compile_rack(spec)
    rec = record(30.0, 1.0)
    warm = dataclasses.replace(rec, accel=3.0 * rec.accel[:int(round(2.0 / rec.dt)) + 1])
    run_rack(model, warm, dt=DT, save_every=save_every)
    run_rack(model, rec, dt=DT, save_every=save_every)

    def run():
        return run_rack(model, rec, dt=DT, save_every=save_every)

    if args.profile:
        import cProfile
        import pstats

        pr = cProfile.Profile()
        pr.enable()
        for _ in range(20):
            run()
        pr.disable()
        pstats.Stats(pr).sort_stats("cumulative").print_stats(45)
        pstats.Stats(pr).sort_stats("tottime").print_stats(30)
        return
    cpus, walls = [], []
    for _ in range(args.n):
        if args.cold:
            model = compile_rack(spec)
        c0, t0 = time.process_time(), time.perf_counter()
        res = run()
        walls.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - c0)
    h = res.history
    print(f"paper rack run_rack{' (cold model)' if args.cold else ''}, "
          f"save_every={save_every}: best CPU {1e3 * min(cpus):.2f} ms, "
          f"best wall {1e3 * min(walls):.2f} ms, median CPU {1e3 * np.median(cpus):.2f} ms "
          f"(n={args.n}); events {len(h.events)}, basis {h.basis}")
    if args.dump:
        fp = {}
        for k, v in res.full_peaks.items():
            for kk, vv in (v.items() if isinstance(v, dict) else [("", v)]):
                if vv is not None:
                    fp[f"{k}.{kk}" if kk else k] = np.asarray(vv)
        np.savez(args.dump, disp=res.beam_displacement, acc=res.beam_acceleration,
                 shear=res.base_shear, sliding=res.pallet_sliding,
                 friction=res.pallet_friction, energy=np.array(list(h.energy.values())),
                 events=np.array([(e.time_s, e.slider) for e in h.events]),
                 **{"peak_" + k: v for k, v in fp.items()})


if __name__ == "__main__":
    with threadpool_limits(1):
        main()
