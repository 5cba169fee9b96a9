"""Benchmark of the stick–slip engine (issue #3): steps per second after warm-up.

Structure: a 50-DOF shear chain (10 t floors, Rayleigh-free stiffness-proportional damping)
carrying 8 sliding masses (400 kg, mu = 0.25) on DOFs spread over its height, under a seeded,
band-limited ground acceleration that makes the masses slide many times. 20,000 steps.

Run: ``python benchmarks/engine.py`` (or ``make bench``). Reports; never asserts on time.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from seisrack.dynamics import Sliders, simulate


def build(n: int = 50, m: int = 8, seed: int = 1):
    rng = np.random.default_rng(seed)
    mass = np.full(n, 1.0e3)
    k = np.full(n, 5.0e7)
    K = np.zeros((n, n))
    for i in range(n):
        K[i, i] += k[i]
        if i + 1 < n:
            K[i, i] += k[i + 1]
            K[i, i + 1] = K[i + 1, i] = -k[i + 1]
    M = np.diag(mass)
    w1 = np.sqrt(np.linalg.eigvalsh(np.linalg.solve(M, K)).min())
    C = (2 * 0.02 / w1) * K
    dofs = np.linspace(n // 8, n - 1, m).astype(int)
    sliders = Sliders(dofs, np.full(m, 400.0), 0.25, 0.25)
    n_steps = 20_000
    dt = 1e-3
    t = np.arange(n_steps + 1) * dt
    ag = np.zeros_like(t)
    for f in rng.uniform(0.5, 8.0, 30):
        ag += np.sin(2 * np.pi * f * t + rng.uniform(0, 2 * np.pi))
    ag *= 0.35 * 9.81 / np.max(np.abs(ag))
    return M, C, K, sliders, dt, ag


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--python", action="store_true", help="also time the pure-Python twin")
    args = ap.parse_args()
    M, C, K, sl, dt, ag = build()
    n_steps = ag.size - 1
    for method in ("exact", "newmark"):  # warm-up / compile
        simulate(M, C, K, sl, dt=dt, ground_accel=ag[:200], backend="numba", method=method)
    rows = []
    for method in ("exact", "newmark"):
        for energy in (True, False):
            best = np.inf
            for _ in range(args.repeat):
                t0 = time.perf_counter()
                res = simulate(M, C, K, sl, dt=dt, ground_accel=ag, backend="numba",
                               track_energy=energy, method=method)
                best = min(best, time.perf_counter() - t0)
            rows.append(("numba", energy, best, res))
    if args.python:
        t0 = time.perf_counter()
        res = simulate(M, C, K, sl, dt=dt, ground_accel=ag, backend="python")
        rows.append(("python", True, time.perf_counter() - t0, res))
    print(f"engine benchmark: {M.shape[0]} DOFs, {sl.count} sliders, {n_steps} steps, dt={dt}")
    print(f"{'backend':8s} {'method':8s} {'energy':6s} {'wall [s]':>9s} {'steps/s':>10s} "
          f"{'events':>7s} {'substeps':>9s} {'configs':>7s} {'energy err':>10s}")
    for name, energy, wall, res in rows:
        err = res.energy_error() if energy else float("nan")
        print(f"{name:8s} {res.method:8s} {str(energy):6s} {wall:9.4f} {n_steps / wall:10.0f} "
              f"{len(res.events):7d} {res.n_substeps:9d} {res.n_configurations:7d} {err:10.2e}")
    print("(wall time includes validation, modal transform and output assembly)")


if __name__ == "__main__":
    main()
