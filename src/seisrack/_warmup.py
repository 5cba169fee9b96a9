"""Compile (and cache) the numba kernels once, so the first real run is fast.

``make install`` runs ``python -m seisrack._warmup`` after ``pip install``, the way a package with
a C extension is built at install time. Without numba this is a no-op.
"""

from __future__ import annotations

import time

import numpy as np


def warmup() -> dict[str, float]:
    """Run tiny problems through every compiled kernel; returns seconds per kernel."""
    from seisrack.dynamics import Sliders, simulate
    from seisrack.dynamics.kernels import numba_available

    timings: dict[str, float] = {}
    if not numba_available():
        return timings
    t0 = time.perf_counter()
    K = np.array([[2.0, -1.0], [-1.0, 1.0]])
    for method in ("exact", "newmark"):
        simulate(np.eye(2), 0.01 * K, K, Sliders([0, 1], [1.0, 1.0], 0.3), dt=0.01,
                 ground_accel=np.sin(np.arange(60) * 0.2), backend="numba", method=method)
    timings["stick-slip engine"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    from seisrack.dynamics import PlanarSliders

    K4 = np.kron(np.eye(2), K)
    ground = np.column_stack([np.sin(np.arange(60) * 0.2), np.cos(np.arange(60) * 0.3)])
    simulate(np.eye(4), 0.01 * K4, K4, PlanarSliders([0, 1], [2, 3], 1.0, 0.3), dt=0.01,
             ground_accel=ground, influence=np.array([[1, 0], [1, 0], [0, 1], [0, 1]]),
             backend="numba", basis="full")
    timings["planar stick-slip engine (3D racks)"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    from seisrack.motion import response_spectrum

    response_spectrum(np.sin(np.arange(400) * 0.1), 0.01, np.array([0.05, 0.5, 2.0]))
    timings["response spectrum"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    from seisrack.motion import generate_ec8_record

    generate_ec8_record(type=1, ground="C", ag=0.1, duration=12.0, dt=0.01, seed=0)
    timings["accelerogram synthesis"] = time.perf_counter() - t0
    return timings


if __name__ == "__main__":
    for name, sec in warmup().items():
        print(f"seisrack: compiled {name} kernel in {sec:.1f} s (cached for later runs)")
