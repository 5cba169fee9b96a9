"""Validation examples 2 and 3: production engine vs the event-driven reference (issue #3).

Source: the paper's §III.B validation examples, with the exact definitions of issue #3 (the
paper's figures are lost): ``seisrack.paper.examples``. The reference is the independent
semi-analytical solver ``seisrack.dynamics.reference.simulate_reference`` (exact switching
times, DOP853 at rtol 1e-11 inside the phases). Acceptance of issue #3, verbatim: at dt = 1 ms
the peaks of every structural displacement and of the relative sliding agree within 0.5 %, and
the count of sliding phases (a reversal starts a new phase) is the same. Each case is one test
so that its reference run (2–4 s; ~20 s for the seven cases; the engine ~0.05 s) happens once.
"""

from __future__ import annotations

import functools

import numpy as np
import pytest

from seisrack.dynamics import simulate
from seisrack.paper.examples import (
    example2,
    example3,
    examples,
    run_engine,
    run_reference,
)

DT = 1e-3
TOL = 0.005  # issue #3: 0.5 %
ZERO = 1e-12  # [m] a peak below this is round-off: the case never slides

# The production engine ("auto" picks the exact modal propagators for these undamped /
# stiffness-proportionally damped examples) meets the 0.5 % in every case. The Newmark kernel is
# also checked, with its one known miss: example 2, mu = 0.5, whose first slip is a grazing one
# (the required friction barely exceeds mu_s N), so Newmark's O(dt^2) force error shifts the
# slip window: peak sliding 0.004135 m vs 0.004113 m (0.55 %). It converges to the reference at
# order 2 (test below). strict=True: an XPASS fails the suite.
_GRAZING = pytest.mark.xfail(
    strict=True, reason="Newmark, grazing slip: 0.55 % > 0.5 % on peak sliding at dt = 1 ms"
)
CASES = [
    pytest.param(
        "example2", f"{mu:.1f}", method,
        marks=_GRAZING if (mu == 0.5 and method == "newmark") else (),
    )
    for method in ("auto", "newmark")
    for mu in example2().mu_values
] + [
    pytest.param("example3", f"{mu:.1f}", method)
    for method in ("auto", "newmark")
    for mu in example3().mu_values
]


@functools.cache
def _reference(name: str, mu: str):
    return run_reference(examples()[name], float(mu), save_dt=DT)


def _numba_simulate(*args, **kwargs):
    return simulate(*args, backend="numba", **kwargs)


def _with_method(method: str):
    def run(*args, **kwargs):
        return simulate(*args, backend="numba", method=method, **kwargs)

    return run


def _rel(a: float, b: float) -> float:
    return abs(a - b) / abs(b)


@pytest.mark.parametrize(("name", "mu", "method"), CASES)
def test_engine_matches_reference(name, mu, method):
    """One case per test; the reference run is cached per (example, mu)."""
    ex = examples()[name]
    ref = _reference(name, mu)
    eng = run_engine(_with_method(method), ex, float(mu), DT)
    assert eng.status == "ok"
    assert eng.method == ("newmark" if method == "newmark" else "exact")
    assert eng.t.shape == ref.t.shape
    failures = []
    # peaks of every structural displacement within 0.5 %
    for j, (a, b) in enumerate(
        zip(np.max(np.abs(eng.u), 0), np.max(np.abs(ref.u), 0), strict=True)
    ):
        if _rel(a, b) > TOL:
            failures.append(f"DOF {j}: {a:.7g} vs {b:.7g} m ({100 * _rel(a, b):.3f} %)")
    # peak of the relative sliding within 0.5 % (both ~0 when the case never slides)
    s_eng = float(np.max(np.abs(eng.sliding[:, 0])))
    s_ref = float(np.max(np.abs(ref.sliding[:, 0])))
    if s_ref < ZERO:
        if s_eng >= ZERO:
            failures.append(f"engine slides ({s_eng:.3g} m), the reference does not")
    elif _rel(s_eng, s_ref) > TOL:
        failures.append(
            f"max |sliding| {s_eng:.7g} m (engine) vs {s_ref:.7g} m (reference): "
            f"{100 * _rel(s_eng, s_ref):.3f} % > 0.5 %"
        )
    # the same count of sliding phases (a reversal starts a new phase) ...
    if eng.sliding_phases(0) != ref.sliding_phases(0):
        failures.append(f"sliding phases {eng.sliding_phases(0)} vs {ref.sliding_phases(0)}")
    # ... and, stronger, the same event sequence with each event within one step
    if [e.kind for e in eng.events] != [e.kind for e in ref.events]:
        failures.append(f"event kinds {eng.events} vs {ref.events}")
    else:
        for e, r in zip(eng.events, ref.events, strict=True):
            if abs(e.time_s - r.time_s) > DT:
                failures.append(f"event {e} vs {r}")
    assert not failures, f"{name} mu={mu}: " + "; ".join(failures)


def test_mu_trend_and_non_sliding_cases():
    """mu = 1.0 (example 2) and mu = 10 (example 3) never slide; smaller mu slides more."""
    res = {
        (name, mu): run_engine(_numba_simulate, examples()[name], float(mu), DT)
        for name, mu, method in (c.values for c in CASES)
        if method == "auto"
    }
    for key in (("example2", "1.0"), ("example3", "10.0")):
        assert res[key].sliding_phases() == 0 and np.max(np.abs(res[key].sliding)) < ZERO
    s3 = [float(np.max(np.abs(res["example3", k].sliding))) for k in ("0.5", "0.3", "0.1")]
    assert s3 == sorted(s3) and s3[0] > 0.01


def test_grazing_case_converges_to_reference():
    """Example 2, mu = 0.5 (grazing first slip). Newmark: within 0.5 % at dt = 0.5 ms, and the
    gap shrinks at order ~2. Exact propagators: only the linear interpolation of the sampled
    force is left, so the peak sliding is within 0.01 % already at dt = 2 ms."""
    ex = examples()["example2"]
    s_ref = float(np.max(np.abs(_reference("example2", "0.5").sliding[:, 0])))
    errs = []
    dts = (2e-3, 1e-3, 5e-4)
    for dt in dts:
        eng = run_engine(_with_method("newmark"), ex, 0.5, dt)
        errs.append(abs(float(np.max(np.abs(eng.sliding[:, 0]))) - s_ref))
    assert errs[-1] / s_ref < TOL
    order = np.polyfit(np.log(dts), np.log(errs), 1)[0]
    assert 1.7 < order < 2.4, order
    for dt in dts:
        eng = run_engine(_with_method("exact"), ex, 0.5, dt)
        err = abs(float(np.max(np.abs(eng.sliding[:, 0]))) - s_ref) / s_ref
        assert err < 1e-4, (dt, err)
