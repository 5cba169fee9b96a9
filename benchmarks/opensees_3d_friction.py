"""The 3D paper rack's pallets on OpenSees' flatSliderBearing against seisrack's exact planar
stick–slip (issue 21): how the regularised peer's sliding depends on its elastic stage
``K_INIT`` and the step.

``examples/paper_rack_3d.toml`` with every pallet at μ = 0.3, El Centro 1940 NS (built in)
from rest (a zero sample prepended), cross-aisle 0.6 of the same record; seisrack's
``run_rack(basis="full")`` and the script of ``seisrack export opensees`` (pallets
``friction``: one flatSliderBearing per support with a Coulomb friction model), both at the
record step divided by ``--sub``. Prints, per pallet, the peak sliding magnitude and the final
sliding (x, z) of both, and their ratio. Reports only; never asserts.

Run: ``python benchmarks/opensees_3d_friction.py [--k-init 1e7] [--sub 10] [--seconds 12]``
(needs openseespy). Measured (2 cores shared): ``--k-init 1e6 --sub 5 --seconds 12``: peak
ratio 1.05–1.08, 96 s in OpenSees; ``--k-init 1e7 --sub 10 --seconds 12``: 0.99–1.02, final
sliding within 1.3 mm, 189 s.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from seisrack.analysis import run_rack
from seisrack.analysis.rack import resample
from seisrack.export import opensees_script
from seisrack.model import compile_rack, load_rack
from seisrack.model.spec import with_friction
from seisrack.motion.components import combine
from seisrack.motion.records import Record, load_builtin_record


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--k-init", type=float, default=1e7, help="[N/m] bearing elastic stage")
    ap.add_argument("--sub", type=int, default=10, help="analysis steps per record step")
    ap.add_argument("--seconds", type=float, default=12.0, help="[s] of the record")
    ap.add_argument("--mu", type=float, default=0.3)
    args = ap.parse_args()
    model = compile_rack(with_friction(load_rack("examples/paper_rack_3d.toml"), args.mu))
    rec = load_builtin_record("elcentro_1940_ns")
    dt = rec.dt / args.sub
    a = np.concatenate([[0.0], resample(rec.accel, args.sub)])[: int(args.seconds / dt)]
    motion = combine(Record(a, dt, "x"), Record(0.6 * a, dt, "z"))
    t0 = time.perf_counter()
    resp = run_rack(model, motion, basis="full")
    t1 = time.perf_counter()
    ns: dict = {"__name__": "rack_ops"}
    exec(compile(opensees_script(model, pallets="friction", k_init=args.k_init), "rack_ops.py",
                 "exec"), ns)
    h = ns["history"](list(motion.x), dt, "friction", agz=list(motion.z))
    t2 = time.perf_counter()
    s_ops = np.array(h["pallet_sliding"])
    s = resp.directional("pallet_sliding")
    peak, peak_ops = (np.hypot(x[..., 0], x[..., 1]).max(axis=0) for x in (s, s_ops))
    print(f"K_INIT {args.k_init:g} N/m, dt {dt:g} s, {args.seconds:g} s, mu {args.mu:g}")
    print(f"{'pallet':>6} {'seisrack peak':>14} {'OpenSees peak':>14} {'ratio':>6}   "
          "final sliding seisrack / OpenSees [mm]")
    for p in range(model.n_pallets):
        print(f"{p + 1:>6} {1e3 * peak[p]:>11.2f} mm {1e3 * peak_ops[p]:>11.2f} mm "
              f"{peak_ops[p] / peak[p]:>6.3f}   {np.round(1e3 * s[-1, p], 2).tolist()} / "
              f"{np.round(1e3 * s_ops[-1, p], 2).tolist()}")
    print(f"wall time: seisrack {t1 - t0:.1f} s, OpenSees {t2 - t1:.1f} s")


if __name__ == "__main__":
    main()
