"""The rack time history converges at second order as the analysis dt is halved (Newmark), and
does not depend on dt at all with the exact modal propagators.

The Newmark kernel integrates each contact phase with Newmark's average-acceleration rule
(second order, Chopra §5.4) and locates every stick/slip event inside the step
(docs/theory/stick_slip_engine.md §4), so the histories converge as O(dt²): the difference
between the runs at dt and dt/2 shrinks ~4× per halving. The record (El Centro 1940 N-S, 0-5 s,
dt = 10 ms) is piecewise linear, so every run sees the same excitation (``run_rack``
interpolates it linearly onto the finer grid) and only the integration error changes. The order
is measured by regressing log(difference) on log(dt), as diffrax does.

The exact kernel (``method="exact"``, the default for this stiffness-proportionally damped rack)
solves each contact phase in closed form for the piecewise-linear excitation, so refining dt
changes only round-off and the event-location tolerance: the histories agree to 1e-8 of
their peaks for every dt.
"""

from __future__ import annotations

import numpy as np
import pytest

from analysis_inputs import paper_model, short_record
from seisrack.analysis import run_rack

SUBSTEPS = (2, 4, 8, 16)  # dt = 5, 2.5, 1.25, 0.625 ms (record dt 10 ms)


def _order(diffs: list[float]) -> float:
    h = np.array([1.0 / k for k in SUBSTEPS[:-1]])  # dt of the coarser run of each pair
    return float(np.polyfit(np.log(h), np.log(diffs), 1)[0])


@pytest.fixture(scope="module", params=[0.3, 0.6])
def runs(request):
    rec = short_record()
    model = paper_model(request.param)
    out = {}
    for k in SUBSTEPS:
        resp = run_rack(model, rec, dt=rec.dt / k, rigid_companion=False, method="newmark")
        assert resp.sliding_occurred()
        out[k] = resp
    return out


def _successive(runs, get) -> list[float]:
    """max |x(dt) - x(dt/2)| at the time points of the coarsest run, per halving."""
    vals = [get(runs[k])[::k // SUBSTEPS[0]] for k in SUBSTEPS]
    return [float(np.max(np.abs(a - b))) for a, b in zip(vals[:-1], vals[1:], strict=True)]


def test_beam_displacement_history_second_order(runs):
    d = _successive(runs, lambda r: r.beam_displacement[:, 0])
    ratios = [a / b for a, b in zip(d[:-1], d[1:], strict=True)]
    assert 1.8 < _order(d) < 2.3, (d, ratios)
    assert all(3.0 < q < 5.5 for q in ratios), ratios


def test_pallet_sliding_history_second_order(runs):
    d = _successive(runs, lambda r: r.pallet_sliding[:, 0])
    assert 1.8 < _order(d) < 2.3, d


def test_peak_sliding_second_order(runs):
    peaks = [runs[k].pallet_peak_sliding()[0] for k in SUBSTEPS]
    d = [abs(a - b) for a, b in zip(peaks[:-1], peaks[1:], strict=True)]
    assert 1.6 < _order(d) < 2.5, (peaks, d)


def test_peak_displacement_converges(runs):
    """A peak over a grid jumps between neighbouring samples from run to run, so its
    successive differences are irregular at the 1e-6 level. They are bounded, though, by the
    history differences (|max|a| - max|b|| <= max|a - b|), which shrink ~4x per halving."""
    step = [k // SUBSTEPS[0] for k in SUBSTEPS]
    x = [runs[k].beam_displacement[::s, 0] for k, s in zip(SUBSTEPS, step, strict=True)]
    peaks = [float(np.max(np.abs(v))) for v in x]
    d_peak = [abs(a - b) for a, b in zip(peaks[:-1], peaks[1:], strict=True)]
    d_hist = [float(np.max(np.abs(a - b))) for a, b in zip(x[:-1], x[1:], strict=True)]
    assert all(p <= h * (1 + 1e-12) for p, h in zip(d_peak, d_hist, strict=True))
    assert 1.8 < _order(d_hist) < 2.3
    assert abs(peaks[0] - peaks[-1]) < 1e-3 * peaks[-1]  # 5 ms is already within 0.1 %


@pytest.mark.parametrize("mu", [0.3, 0.6])
def test_exact_method_is_independent_of_dt(mu):
    rec = short_record()
    model = paper_model(mu)
    runs = {k: run_rack(model, rec, dt=rec.dt / k, rigid_companion=False) for k in (1, 2, 4)}
    assert all(r.history.method == "exact" for r in runs.values())
    assert runs[1].sliding_occurred()
    for get in (lambda r: r.beam_displacement[:, 0], lambda r: r.pallet_sliding[:, 0]):
        base = get(runs[1])
        scale = float(np.max(np.abs(base)))
        for k in (2, 4):
            assert np.max(np.abs(get(runs[k])[::k] - base)) < 1e-8 * scale
    assert [len(r.history.events) for r in runs.values()] == [len(runs[1].history.events)] * 3
