"""Where the nonlinear path's slip-event chatter comes from (issue 22): the nonlinear paper rack
(``examples/paper_rack_nonlinear.toml``, mu 0.3, El Centro 1940 N-S 30 s as
``benchmarks/scale.py``) on the 1D Newmark kernel with hinges.

Two series against a reference run (the default Ritz basis at dt 0.5 ms):
- the step: dt 5, 2.5, 1 ms with the default basis (events against dt);
- the basis at dt 5 ms: its first k vectors only (the stiffest ones left out), k from the
  default size down to 4.
Each row: CPU of one run (warm), slip events, and the differences from the reference of the
largest pallet sliding, the largest level displacement, the hinge peak moments (largest
difference over the hinges, relative to the largest peak moment) and the final level
displacement (residual drift). Reports numbers; never asserts. Writes
``benchmarks/results/nonlinear_chatter.md``. Run::

    python benchmarks/nonlinear_chatter.py [--out FILE]
"""

from __future__ import annotations

import argparse
import datetime as dt
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))


def _measure(model, rec, step, basis):  # noqa: ANN001, ANN202
    from seisrack.analysis import run_rack

    run_rack(model, rec, dt=step, basis=basis)  # warm (numba, the cached preparation)
    c0 = time.process_time()
    r = run_rack(model, rec, dt=step, basis=basis)
    return time.process_time() - c0, r


def _values(r):  # noqa: ANN001, ANN202
    peaks = np.array([p["peak_moment_Nm"] for p in r.hinges.peaks()])
    return (float(r.pallet_peak_sliding().max()), float(np.abs(r.beam_displacement).max()),
            peaks, float(np.abs(r.beam_displacement[-1]).max()))


def main() -> None:
    from threadpoolctl import threadpool_limits

    from scale import record
    from seisrack.analysis.prepare import prepare_run
    from seisrack.dynamics.basis import Basis
    from seisrack.model import compile_rack, load_rack
    from seisrack.model.spec import with_friction

    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default=str(HERE / "results" / "nonlinear_chatter.md"))
    args = ap.parse_args()
    load0 = os.getloadavg()
    rec = record(30.0, 1.0)
    model = compile_rack(with_friction(load_rack(ROOT / "examples" / "paper_rack_nonlinear.toml"),
                                       0.3))
    b0 = prepare_run(model).basis
    hz = np.sqrt(b0.w2) / (2.0 * np.pi)
    rows = []
    with threadpool_limits(1):
        t_ref, ref = _measure(model, rec, 0.0005, "auto")
        s_ref, d_ref, m_ref, res_ref = _values(ref)

        def row(label: str, step: float, basis) -> None:  # noqa: ANN001
            t, r = _measure(model, rec, step, basis)
            s, d, m, res = _values(r)
            rows.append(
                f"| {label} | {1e3 * step:g} | {1e3 * t:.0f} ms | {len(r.history.events)} | "
                f"{100 * (s - s_ref) / s_ref:+.2f} % | {100 * (d - d_ref) / d_ref:+.2f} % | "
                f"{100 * np.max(np.abs(m - m_ref)) / m_ref.max():.2f} % | "
                f"{1e3 * res:.3f} mm | {r.history.energy_error():.1e} |")

        for step in (0.005, 0.0025, 0.001):
            row(f"default basis ({b0.size} vectors, up to {hz[-1]:.0f} Hz)", step, "auto")
        for k in range(b0.size - 2, 3, -2):
            b = Basis(phi=b0.phi[:, :k], w2=b0.w2[:k], kind="reduced", n_modes=k)
            row(f"first {k} vectors (up to {hz[k - 1]:.0f} Hz)", 0.005, b)
    commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"],
                            capture_output=True, text=True, check=False).stdout.strip()
    load1 = os.getloadavg()
    lines = [
        "# Slip-event chatter on the nonlinear path: the step and the stiff Ritz vectors "
        "(issue 22)", "",
        f"Written by `benchmarks/nonlinear_chatter.py` ({dt.datetime.now(dt.UTC):%Y-%m-%d %H:%M}"
        f" UTC) at commit {commit}; load average before {load0[0]:.2f}, after {load1[0]:.2f}; "
        "one BLAS thread, numba warm, CPU of one run. Reports numbers; never asserts.", "",
        f"Nonlinear paper rack, mu 0.3, El Centro 30 s. Default basis: {b0.size} Ritz vectors, "
        f"{', '.join(f'{f:.0f}' for f in hz)} Hz. Reference: the default basis at dt 0.5 ms "
        f"({len(ref.history.events)} events, {1e3 * t_ref:.0f} ms; largest sliding "
        f"{1e3 * s_ref:.2f} mm, level displacement {1e3 * d_ref:.2f} mm, residual "
        f"{1e3 * res_ref:.3f} mm).", "",
        "| basis | dt [ms] | run CPU | events | largest sliding | largest level displacement "
        "| hinge peak moments (largest difference) | residual drift | energy error |",
        "|---|---|---|---|---|---|---|---|---|",
        *rows,
    ]
    Path(args.out).write_text("\n".join(lines) + "\n", encoding="utf-8")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
