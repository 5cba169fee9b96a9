"""Ground motions benchmark: response spectrum and artificial-record generation, with peers.

Run: ``python benchmarks/motion.py``. Reports numbers, asserts nothing.

Spectrum: 200 log-spaced periods 0.02–5 s, 5 % damping, a 15 s record at dt = 5 ms (El Centro
1940 N-S, bundled, linearly resampled). Reference: ``scipy.signal.lsim`` on the record upsampled
≥ 10× (≥ 100 points per period), at 40 of the 200 periods, followed by rest for one period
(as seisrack's default) or not (as eqsig).
Generation: EC8 type 1, ground C, a_gR = 0.3 g, 15 s, dt = 10 ms, seeds 0–6.
Peers: eqsig (spectrum; it has no spectrum-compatible generator), pyrotd/REQPY if installed.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable

import numpy as np
from scipy import signal

from seisrack.motion import (
    ec8_spectrum,
    generate_ec8_record,
    load_builtin_record,
    response_spectrum,
)


def best_time(f: Callable[[], object], repeat: int = 20) -> tuple[float, float]:
    """(min, mean) wall time [s] over ``repeat`` calls after one warm-up call."""
    f()
    ts = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        f()
        ts.append(time.perf_counter() - t0)
    return min(ts), float(np.mean(ts))


def lsim_sd(a: np.ndarray, dt: float, T: float, z: float, tail: bool) -> float:
    up = max(10, int(math.ceil(100 * dt / T)))
    w = 2 * math.pi / T
    if tail:
        a = np.concatenate([a, np.zeros(int(math.ceil(T / dt)))])
    t = np.arange((a.size - 1) * up + 1) * dt / up
    fine = np.interp(t, np.arange(a.size) * dt, a)
    sys = signal.lti([[0, 1], [-w * w, -2 * z * w]], [[0], [-1]], [[1, 0]], [[0]])
    return float(np.max(np.abs(signal.lsim(sys, fine, t, interp=True)[1])))


def main() -> None:
    rec = load_builtin_record("elcentro_1940_ns")
    dt = 0.005
    n = int(15.0 / dt) + 1
    a = np.interp(np.arange(n) * dt, rec.time, rec.accel)
    T = np.geomspace(0.02, 5.0, 200)
    z = 0.05
    print(f"record: El Centro 1940 NS, 15 s at dt = {dt} s ({n} samples); {T.size} periods "
          f"{T[0]}-{T[-1]} s, damping {z}")
    # reference on every 5th period (40 of 200): lsim on the upsampled record is slow
    sub = np.arange(0, T.size, 5)
    print(f"computing the lsim reference at {sub.size} of the periods (about a minute)...")
    ref_fv = np.array([lsim_sd(a, dt, t, z, True) for t in T[sub]])
    ref_nofv = np.array([lsim_sd(a, dt, t, z, False) for t in T[sub]])

    rows = []
    for backend in ("numba", "numpy"):
        for fv in (True, False):
            f = lambda b=backend, fv=fv: response_spectrum(a, dt, T, z, backend=b,  # noqa: E731
                                                           free_vibration=fv)
            tm = best_time(f, 200 if backend == "numba" else 1)
            err = np.abs(f().sd[sub] / (ref_fv if fv else ref_nofv) - 1)
            rows.append((f"seisrack {backend}, free vib. {'on' if fv else 'off'}", tm, err, T[sub]))
    try:
        import eqsig

        f = lambda: eqsig.sdof.pseudo_response_spectra(a, dt, T, z)  # noqa: E731
        tm = best_time(f, 5)
        sd = f()[0][sub]
        rows.append(("eqsig pseudo_response_spectra vs ref. without free vib.", tm,
                     np.abs(sd / ref_nofv - 1), T[sub]))
        rows.append(("eqsig pseudo_response_spectra vs ref. with free vib.", tm,
                     np.abs(sd / ref_fv - 1), T[sub]))
    except ImportError:
        print("eqsig not installed")
    try:
        import pyrotd  # noqa: F401

        print("pyrotd installed but not benchmarked here")
    except ImportError:
        pass
    print()
    print(f"{'response spectrum':60s} {'min [ms]':>9s} {'mean [ms]':>9s} {'max err %':>10s} "
          f"{'at T [s]':>9s}")
    for name, (tmin, tmean), err, per in rows:
        k = int(np.argmax(err))
        print(f"{name:60s} {1e3 * tmin:9.2f} {1e3 * tmean:9.2f} {100 * err[k]:10.3f} "
              f"{per[k]:9.3f}")

    print()
    target = ec8_spectrum(1, "C", 0.3)
    generate_ec8_record(target, seed=100)  # warm-up
    # check grid: denser than, and offset from, the generator's own matching grid
    Tc = np.geomspace(0.05, 4.0, 331)
    recs, times = [], []
    for rep in range(3):  # the same 7 records three times: min and mean over 21 timings
        for seed in range(7):
            t0 = time.perf_counter()
            rec_ = generate_ec8_record(target, seed=seed)
            times.append(time.perf_counter() - t0)
            if rep == 0:
                recs.append(rec_)
    ratios = np.array([response_spectrum(r.accel, r.dt, Tc, z).psa / target.psa(Tc) for r in recs])
    mean = ratios.mean(axis=0)
    v_end = [abs(np.trapezoid(r.accel, dx=r.dt)) for r in recs]
    # final displacement of the piecewise-linear record, exactly (as the baseline correction)
    d_end = []
    for r in recs:
        v = np.concatenate([[0.0], np.cumsum(0.5 * r.dt * (r.accel[1:] + r.accel[:-1]))])
        d_end.append(abs(np.sum(r.dt * v[:-1] + r.dt**2 * (r.accel[:-1] / 3 + r.accel[1:] / 6))))
    print(f"generation ({target.name}, ag = 0.3 g, 15 s, dt = 0.01 s, seeds 0-6)")
    print(f"  time per record [s]: min {min(times):.3f}  mean {np.mean(times):.3f}  "
          f"max {max(times):.3f}  (after warm-up, 3 x 7 records)")
    print(f"  each record / target over 0.05-4 s ({Tc.size} periods): {ratios.min():.3f} .. "
          f"{ratios.max():.3f}; records within ±10 % everywhere: "
          f"{np.sum(np.all(abs(ratios - 1) <= .1, axis=1))}/{len(recs)}")
    print("  record-wise range: "
          + ", ".join(f"{r.min():.3f}-{r.max():.3f}" for r in ratios))
    print("  iterations: " + ", ".join(str(r.meta["iterations"]) for r in recs))
    print(f"  suite mean / target: {mean.min():.3f} .. {mean.max():.3f}")
    print(f"  mean PGA / (ag S): {np.mean([r.pga for r in recs]) / target.pga:.3f}")
    print(f"  max |final velocity| [m/s]: {max(v_end):.2e}; max |final displacement| [m]: "
          f"{max(d_end):.2e}")
    print("  peers: eqsig has no spectrum-compatible generator; REQPY not installed "
          "(issue #4 quotes 7-8 s per record)")


if __name__ == "__main__":
    main()
