"""The local stick–slip engine (issue 22): per-pallet events inside one global step.

References (independent of the engine):
- the event-driven reference solver :func:`seisrack.dynamics.reference.simulate_reference`
  (DOP853 on each constant-contact phase, transitions decided at the acceleration level, the
  paper's §III.A) for a two-storey frame carrying three pallets with mu_d < mu_s, two of them
  on the same support: measured errors 2.7e-3, 6.5e-4, 1.7e-4 m at dt 5, 2.5, 1.25 ms (peak
  0.36 m), fitted order 2.0, the 54 events of the reference at 2.5 and 1.25 ms;
- the event-driven block on a rigid platform with circular Coulomb friction
  (``tests/test_engine_planar._block_reference``) under two sinusoidal components: measured
  8.2e-5, 2.2e-5, 5.8e-6 m at dt 5, 2.5, 1.25 ms, order 1.98 (the planar engine: 4.2e-4,
  2.1e-4, 5.1e-5);
- the planar engine (``simulate`` with PlanarSliders, full basis, exact event location) on a
  flexible four-DOF frame with two pallets sliding in the plane: 2.3e-5 m apart at dt 2 ms
  (0.07 % of the peak), the same 37 events.
The energy balance input = kinetic + strain + damping + friction closes to 1e-9 of the input
(an identity of the trapezoidal rule in impulse form, docs/theory/local_engine.md §3).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from seisrack.dynamics import PlanarSliders
from seisrack.dynamics.local import LocalSliders
from seisrack.dynamics.local.engine import memory_estimate, simulate_local
from seisrack.dynamics.reference import simulate_reference
from seisrack.errors import InputError, SolverError

sys.path.insert(0, str(Path(__file__).parent))
from test_engine_planar import (  # noqa: E402
    MUD,
    MUS,
    _block_reference,
    _frame,
    _run_planar,
    ax_fn,
    az_fn,
)

M2 = np.diag([800.0, 800.0])
K2 = np.array([[3.5e6, -1.5e6], [-1.5e6, 1.5e6]])
C2 = 1e-3 * K2 + 0.2 * M2
DOF = [0, 1, 1]
MASS = np.array([400.0, 300.0, 500.0])
MU_S = np.array([0.3, 0.25, 0.2])
MU_D = np.array([0.25, 0.25, 0.15])


def _ag(t):
    return 5.0 * np.sin(2 * np.pi * 1.1 * t) * np.exp(-0.2 * t)


def _mdof(dt, t_end=4.0, **kw):
    t = np.arange(0, t_end + dt / 2, dt)
    return t, simulate_local(M2, C2, K2, LocalSliders(DOF, MASS, MU_S, MU_D), dt=dt,
                             ground=_ag(t)[:, None], influence=np.ones((1, 2)), tol=1e-6,
                             **kw)


def test_mdof_converges_to_the_event_driven_reference_at_order_two():
    t_end = 4.0
    ref = simulate_reference(M2, C2, K2, DOF, MASS, MU_S, MU_D, duration=t_end,
                             ground_accel=_ag, save_dt=0.000625)
    dts = [0.005, 0.0025, 0.00125]
    errs = []
    for dt in dts:
        t, h = _mdof(dt, t_end)
        idx = np.rint(t / 0.000625).astype(int)
        errs.append(np.abs(h.sliding[:, :, 0] - ref.sliding[idx]).max())
        assert h.energy_error() < 1e-8
        if dt < 0.005:
            assert len(h.events) == len(ref.events)
    order = np.polyfit(np.log(dts), np.log(errs), 1)[0]
    assert order > 1.8, (errs, order)
    assert errs[-1] < 1e-3 * np.abs(ref.sliding).max()


def _block(dt, backend="auto"):
    t = np.arange(0.0, 6.0 + dt / 2, dt)
    sl = LocalSliders(np.array([[[-1, -1]]]), 500.0, MUS, MUD)
    h = simulate_local(np.eye(1), np.zeros((1, 1)), np.eye(1) * 100.0, sl, dt=dt,
                       ground=np.column_stack([ax_fn(t), az_fn(t)]),
                       influence=np.zeros((2, 1)), tol=1e-6, backend=backend)
    return t, h


def test_block_in_the_plane_converges_at_order_two():
    ref, n_seg = _block_reference(ax_fn, az_fn, MUS, MUD, 9.81, 6.0)
    assert n_seg >= 5
    dts = [0.005, 0.0025, 0.00125]
    errs = []
    for dt in dts:
        t, h = _block(dt)
        errs.append(np.abs(h.sliding[:, 0, :] - ref(t)).max())
    order = np.polyfit(np.log(dts), np.log(errs), 1)[0]
    assert order > 1.8, (errs, order)
    assert errs[0] < 2e-4


def test_flexible_frame_in_the_plane_equals_the_planar_engine():
    M, C, K = _frame()
    dt = 0.002
    t = np.arange(0, 6 + dt / 2, dt)
    gx, gz = 0.5 * ax_fn(t), 0.5 * az_fn(t)
    hp = _run_planar(M, C, K, PlanarSliders([0, 1], [2, 3], [400.0, 500.0], [0.3, 0.25],
                                                [0.22, 0.2]), dt=dt, ground_x=gx,
                         influence_x=[1, 1, 0, 0], ground_z=gz, influence_z=[0, 0, 1, 1],
                         basis="full")
    sl = LocalSliders(np.array([[[0, 2]], [[1, 3]]]), [400.0, 500.0], [0.3, 0.25],
                      [0.22, 0.2])
    hl = simulate_local(M, C, K, sl, dt=dt, ground=np.column_stack([gx, gz]),
                        influence=np.array([[1, 1, 0, 0], [0, 0, 1, 1.0]]), tol=1e-8)
    peak = np.abs(hp.sliding).max()
    assert peak > 0.02
    assert np.abs(hl.sliding - hp.sliding).max() < 2e-3 * peak
    assert len(hl.events) == len(hp.events)
    assert hl.energy_error() < 1e-8
    # the friction law: |force| <= mu_s N when stuck, = mu_d N when sliding
    f = np.hypot(hl.friction[..., 0], hl.friction[..., 1])
    v = np.hypot(hl.velocity[..., 0], hl.velocity[..., 1])
    cap_s = np.array([0.3, 0.25]) * hl.normal
    cap_d = np.array([0.22, 0.2]) * hl.normal
    assert np.all(f[hl.stuck] <= cap_s[hl.stuck] * (1 + 1e-6))
    sliding = (~hl.stuck) & (v > 1e-6)
    assert sliding.sum() > 100
    assert np.allclose(f[sliding], cap_d[sliding], rtol=1e-6)


def test_python_twin_equals_numba():
    pytest.importorskip("numba")
    _, a = _mdof(0.005, 1.5, backend="numba")
    _, b = _mdof(0.005, 1.5, backend="python")
    assert len(a.events) >= 3
    assert np.allclose(a.sliding, b.sliding, rtol=0, atol=1e-12)
    assert np.allclose(a.q, b.q, rtol=0, atol=1e-12 * np.abs(a.q).max())


def test_chunks_and_save_every_do_not_change_the_result():
    _, a = _mdof(0.005, 2.0)
    _, b = _mdof(0.005, 2.0, chunk_steps=37, save_every=5)
    assert np.array_equal(b.sliding, a.sliding[b.sample_index])
    assert [(e.slider, e.kind) for e in a.events] == [(e.slider, e.kind) for e in b.events]
    # times: t_offset + k dt of the chunk against k dt, equal to round-off
    assert np.allclose([e.time_s for e in a.events], [e.time_s for e in b.events], rtol=0,
                       atol=1e-12)


def test_bad_input():
    t = np.zeros(11)
    sl = LocalSliders([0], 100.0, 0.3)
    with pytest.raises(InputError) as exc:
        LocalSliders(np.zeros((2, 1, 3), dtype=int), 100.0, 0.3)
    assert exc.value.field == "sliders.support"
    with pytest.raises(InputError) as exc:
        LocalSliders([0], 100.0, 0.2, 0.3)
    assert exc.value.field == "sliders.mu_dynamic[0]"
    with pytest.raises(InputError) as exc:
        simulate_local(M2, C2, K2, sl, dt=0.01, ground=t[:, None])
    assert exc.value.field == "influence"
    with pytest.raises(InputError) as exc:
        simulate_local(M2, C2, K2, sl, dt=0.01, ground=t[:, None], influence=np.ones((1, 2)),
                       hinges=object())
    assert exc.value.field == "hinges"
    with pytest.raises(InputError) as exc:
        simulate_local(M2, C2, K2, LocalSliders([5], 100.0, 0.3), dt=0.01,
                       ground=t[:, None], influence=np.ones((1, 2)))
    assert exc.value.field == "sliders.support"
    with pytest.raises(InputError) as exc:  # the supports of a pallet in two slices
        simulate_local(M2, C2, K2, LocalSliders(np.array([[[0], [1]]]), 100.0, 0.3), dt=0.01,
                       ground=t[:, None], influence=np.ones((1, 2)), slices=[0, 1])
    assert exc.value.field == "sliders.support[0]"


def test_a_response_that_overflows_is_an_error_not_a_result():
    """Only the first coordinate was checked for finiteness: a ground motion of 1e300 m/s²
    overflowed the pallets' forces and the other coordinates, and the run ended "ok" with
    zero sliding. Every coordinate and force is checked now."""
    t = np.arange(0, 1.0 + 0.005 / 2, 0.005)
    with pytest.raises(SolverError, match="non-finite"):
        simulate_local(M2, C2, K2, LocalSliders(DOF, MASS, MU_S, MU_D), dt=0.005,
                       ground=1e300 * _ag(t)[:, None], influence=np.ones((1, 2)), tol=1e-6)


def test_a_run_too_large_is_refused_before_allocating():
    t = np.zeros(100_001)
    sl = LocalSliders(DOF, MASS, MU_S, MU_D)
    with pytest.raises(InputError) as exc:
        simulate_local(M2, C2, K2, sl, dt=0.001, ground=t[:, None],
                       influence=np.ones((1, 2)), max_memory=1e6)
    assert exc.value.field == "n_steps" and "GiB" in str(exc.value)
    _, h = _mdof(0.005, 0.1)
    need = memory_estimate(21, 20, h.local_basis.size, 3, h.local_basis)
    assert need > 21 * 8 * (2 * h.local_basis.size + 18)


def test_a_step_retried_with_its_onsets_in_turn_matches_the_reference(monkeypatch):
    """The retry of a step whose Newton iteration fails (every pallet stuck at the start held,
    then the slip onsets released one at a time, earliest first; docs/theory/local_engine.md
    §4.5), forced on every step by a one-iteration Newton limit in the pure-Python twin: the
    same event-driven reference as above (``simulate_reference``), two of the three pallets on
    one support, so onsets inside one step interact through it."""
    from seisrack.dynamics.local import _kernel

    monkeypatch.setattr(_kernel, "_NEWTON_MAX", 1)
    t_end, dt = 2.5, 0.0025
    ref = simulate_reference(M2, C2, K2, DOF, MASS, MU_S, MU_D, duration=t_end,
                             ground_accel=_ag, save_dt=0.000625)
    t, h = _mdof(dt, t_end, backend="python")
    assert h.status == "ok", h.status
    assert h.work["retried_steps"] > 100
    assert h.work["placed_onsets"] >= 3
    assert h.work["frozen_contacts"] == 0 and h.work["loose_steps"] == 0
    idx = np.rint(t / 0.000625).astype(int)
    err = np.abs(h.sliding[:, :, 0] - ref.sliding[idx]).max()
    # the normal path: 6.5e-4 m at 2.5 ms over 4 s (peak 0.36 m)
    assert err < 1e-3, err
    assert len(h.events) == len(ref.events)
    assert h.energy_error() < 1e-8
