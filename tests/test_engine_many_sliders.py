"""Forty independent sliders on a ten-storey shear building: the engine against the reference.

Reference: the project's own event-driven solver, ``seisrack.dynamics.reference.
simulate_reference``, which shares no code with the engine: it integrates each constant-contact
phase with DOP853 (rtol 1e-11) and locates every stick/slip/reversal by root finding on the
dense output (see its module docstring and ``tests/test_reference_solver.py``, where it is
itself checked against the paper's §II closed form and Chopra §3.2). ``test_engine_examples.py``
compares the two on one slider; here the engine's set-valued contact logic is stressed with
many sliders that switch independently and load each other through the structure.

Case: a 10-storey shear building (3000 kg per storey, 8 MN/m per storey, dense M and K),
stiffness-proportional damping C = a1 K with 2 % at the first period of the building with every
slider stuck (0.93 s), so the exact modal kernel applies. It carries 40 sliders, four per
storey, with masses 50-400 kg and mu_s 0.15-0.45 (two shuffled ramps) and mu_d = 0.8 mu_s, under
the first 8 s of the bundled El Centro 1940 N-S record (PGA 0.31 g at 2.15 s), interpolated
linearly between its 10 ms samples in both solvers. Measured (reference run ~9 s): 36 of 40
sliders slide (smallest peak 1.07 mm, largest 0.171 m), 31 with three phases or more; the
other 4 never slide.

Acceptance, per slider: peak |sliding| within 1 % of the reference (with a 1 µm floor, see
``FLOOR``), the same number of sliding phases (a reversal starts one) and the same sequence of
event kinds; and for the whole run the friction bound |F| <= mu_s N (1 + 1e-9) and the energy
balance (relative residual < 1e-6). Measured at dt = 2 ms: exact kernel 6e-8 on the peaks;
Newmark 0.52 %, on slider 10 (1.47 mm, one grazing slip whose window the O(dt²) force error
shifts), and 0.14 % at 1 ms; at 5 ms Newmark misses (2.7 %), hence dt = 2 ms for both.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
import pytest

from seisrack.dynamics import Sliders, simulate
from seisrack.dynamics.reference import simulate_reference
from seisrack.motion.records import load_builtin_record

N_STOREY = 10
STOREY_MASS = 3000.0  # [kg]
STOREY_K = 8.0e6  # [N/m]
ZETA1 = 0.02  # damping ratio at the first period (sliders stuck)
DURATION = 8.0  # [s] of El Centro 1940 N-S: the strong phase; reference run ~9 s
DT = 2e-3  # [s] engine step and the grid on which both solvers' peaks are sampled
TOL = 0.01  # relative, on each slider's peak |sliding|
# Absolute floor of the peak comparison. A slider that never slides has a peak of pure round-off
# in both solvers (the engine's sliding is w - u_node of two ~0.1 m numbers: ~3e-16 m measured),
# so a relative test on it is meaningless. 1 µm is far below engineering interest (peaks here
# reach 0.17 m), yet 1000x below the smallest real slide (1.07 mm), so a slider that slides in
# one solver and not in the other still fails.
FLOOR = 1e-6  # [m]


@dataclass(frozen=True)
class Case:
    M: np.ndarray  # (n, n) [kg]
    C: np.ndarray  # (n, n) [N·s/m]
    K: np.ndarray  # (n, n) [N/m]
    dof: np.ndarray  # (m,)
    mass: np.ndarray  # (m,) [kg]
    mu_s: np.ndarray  # (m,)
    mu_d: np.ndarray  # (m,)
    t_rec: np.ndarray  # (n_rec,) [s]
    a_rec: np.ndarray  # (n_rec,) [m/s²]


@functools.cache
def _case() -> Case:
    n = N_STOREY
    K = np.zeros((n, n))
    for i in range(n):  # storey i joins floor i to floor i - 1 (the ground for i = 0)
        K[i, i] += STOREY_K
        if i + 1 < n:
            K[i, i] += STOREY_K
            K[i, i + 1] = K[i + 1, i] = -STOREY_K
    M = STOREY_MASS * np.eye(n)
    rng = np.random.default_rng(1)  # shuffles the ramps so each storey gets a mix
    dof = np.repeat(np.arange(n), 4)
    mass = np.linspace(50.0, 400.0, dof.size)[rng.permutation(dof.size)]
    mu_s = np.linspace(0.15, 0.45, dof.size)[rng.permutation(dof.size)]
    # 2 % at the first period of the loaded building (every slider stuck): a1 = 2 zeta / omega1
    M_stuck = M + np.diag(np.bincount(dof, weights=mass, minlength=n))
    w1 = math.sqrt(float(np.min(np.linalg.eigvals(np.linalg.solve(M_stuck, K)).real)))
    C = (2.0 * ZETA1 / w1) * K
    rec = load_builtin_record("elcentro_1940_ns")
    n_rec = int(round(DURATION / rec.dt)) + 1
    a_rec = np.asarray(rec.accel[:n_rec], dtype=float)
    return Case(M, C, K, dof, mass, mu_s, 0.8 * mu_s, np.arange(n_rec) * rec.dt, a_rec)


@functools.cache
def _reference():
    c = _case()
    return simulate_reference(
        c.M, c.C, c.K, c.dof, c.mass, c.mu_s, c.mu_d, duration=DURATION,
        ground_accel=lambda t: float(np.interp(t, c.t_rec, c.a_rec)), save_dt=DT,
        max_step=float(c.t_rec[1]),  # one record interval: DOP853 sees each kink of a_g
    )


def _engine(method: str, mu_s: np.ndarray | None = None):
    c = _case()
    mu_s = c.mu_s if mu_s is None else mu_s
    t = np.arange(int(round(DURATION / DT)) + 1) * DT
    return simulate(
        c.M, c.C, c.K, Sliders(c.dof, c.mass, mu_s, 0.8 * mu_s), dt=DT,
        ground_accel=np.interp(t, c.t_rec, c.a_rec), method=method,
    )


def _kinds(events, j: int) -> list[str]:
    return [e.kind for e in events if e.slider == j]


def _mismatches(eng, ref) -> list[str]:
    """Per-slider differences beyond the acceptance, as readable lines (empty: agreement)."""
    out = []
    peak_eng = np.max(np.abs(eng.sliding), axis=0)
    peak_ref = np.max(np.abs(ref.sliding), axis=0)
    for j, (a, b) in enumerate(zip(peak_eng, peak_ref, strict=True)):
        if abs(a - b) > max(TOL * b, FLOOR):
            out.append(f"slider {j}: peak sliding {a:.7g} m vs {b:.7g} m (reference), "
                       f"{100 * abs(a - b) / max(b, FLOOR):.3f} %")
        if eng.sliding_phases(j) != ref.sliding_phases(j):
            out.append(f"slider {j}: {eng.sliding_phases(j)} sliding phases vs "
                       f"{ref.sliding_phases(j)}")
        elif _kinds(eng.events, j) != _kinds(ref.events, j):
            out.append(f"slider {j}: events {_kinds(eng.events, j)} vs {_kinds(ref.events, j)}")
    return out


def test_the_case_exercises_many_sliders():
    """Guards the case itself: most sliders must slide, most of them several times."""
    ref = _reference()
    assert ref.status == "ok"
    peak = np.max(np.abs(ref.sliding), axis=0)
    phases = np.array([ref.sliding_phases(j) for j in range(peak.size)])
    assert np.sum(peak > 1e-3) >= 30, peak
    assert np.sum(phases >= 3) >= 25, phases
    assert np.sum(ref.u[-1] != 0) > 0 and np.max(peak) < 0.5  # moderate, physical sliding


@pytest.mark.parametrize("method", ["exact", "newmark"])
def test_every_slider_matches_the_reference(method):
    c, ref = _case(), _reference()
    eng = _engine(method)
    assert eng.status == "ok"
    assert eng.method == method
    assert eng.t.shape == ref.t.shape
    failures = _mismatches(eng, ref)
    assert not failures, f"{len(failures)} mismatches ({method}):\n" + "\n".join(failures)
    # Coulomb bound, with the normal force the engine used
    cap = c.mu_s[None, :] * eng.normal
    assert np.all(np.abs(eng.friction) <= cap * (1.0 + 1e-9))
    assert eng.energy_error() < 1e-6


def test_a_one_percent_change_of_one_mu_is_detected():
    """The comparison can fail: mu_s of slider 20 (storey 6, 274 kg) raised by 1 % in the engine
    input only. Measured: 3 sliders then miss the 1 % (up to 5 %)."""
    mu_s = _case().mu_s.copy()
    mu_s[20] *= 1.01
    assert _mismatches(_engine("exact", mu_s), _reference())
