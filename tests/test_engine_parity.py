"""Parity of the numba kernel and its pure-Python twin (issue #3: "a pure-Python twin that is
tested for parity"; the pattern of pystrata, which runs the same validation under both).

Both backends execute the same source (``_kernel.py``); they may differ only by floating-point
round-off (numba may fuse or reorder operations), so results must agree to 1e-12 relative on a
short run with several slips, sticks and reversals, for classical (diagonal modal) and
non-classical (dense modal) damping. The exact-propagator kernel (``_kernel_exact.py``) is held
to 1e-10: its constrained modes come from ``eigh``, which numba and numpy take from different
LAPACK builds, and the accelerations recovered from equilibrium amplify that round-off by the
stiffest ω².
"""

from __future__ import annotations

import numpy as np
import pytest

from seisrack.dynamics import Sliders, simulate

DT = 5e-3
N_STEPS = 300


def _problem(dense_damping: bool):
    t = np.arange(N_STEPS + 1) * DT
    M = np.diag([100.0, 80.0, 60.0])
    K = 1e5 * np.array([[2.0, -1.0, 0.0], [-1.0, 2.0, -1.0], [0.0, -1.0, 1.0]])
    C = 0.01 * K
    if dense_damping:
        C = C.copy()
        C[0, 0] += 300.0  # a dashpot to the ground: not diagonal in the modal basis
    sl = Sliders(dof=[0, 2, 1, -1], mass=[300.0, 500.0, 200.0, 50.0],
                 mu_static=[0.2, 0.3, 0.15, 0.25], mu_dynamic=[0.15, 0.3, 0.1, 0.2])
    ag = 3.0 * np.sin(2 * np.pi * 1.3 * t) + 2.0 * np.sin(2 * np.pi * 3.1 * t)
    force = np.zeros((t.size, 3))
    force[:, 1] = 500.0 * np.sin(2 * np.pi * 0.9 * t)
    av = 2.0 * np.sin(2 * np.pi * 2.2 * t)
    return M, C, K, sl, dict(dt=DT, ground_accel=ag, force=force, vertical_accel=av)


FIELDS = ("q", "qd", "qdd", "slider_u", "slider_v", "sliding", "friction", "u", "v", "a")


@pytest.mark.parametrize(
    ("dense_damping", "method"),
    [(False, "newmark"), (True, "newmark"), (False, "exact")],
    ids=["classical", "non-classical", "exact"],
)
def test_numba_python_parity(dense_damping, method):
    M, C, K, sl, kw = _problem(dense_damping)
    fast = simulate(M, C, K, sl, backend="numba", method=method, **kw)
    slow = simulate(M, C, K, sl, backend="python", method=method, **kw)
    assert fast.method == slow.method == method
    rtol = 1e-12 if method == "newmark" else 1e-10
    assert (fast.backend, slow.backend) == ("numba", "python")
    assert fast.status == slow.status == "ok"
    kinds = [e.kind for e in slow.events]
    assert len(kinds) >= 10 and {"slip", "stick"} <= set(kinds)
    assert [(e.slider, e.kind) for e in fast.events] == [(e.slider, e.kind) for e in slow.events]
    t_f = np.array([e.time_s for e in fast.events])
    t_s = np.array([e.time_s for e in slow.events])
    assert np.max(np.abs(t_f - t_s)) <= rtol * N_STEPS * DT
    assert fast.n_substeps == slow.n_substeps
    assert np.array_equal(fast.stuck, slow.stuck)
    for name in FIELDS:
        a, b = getattr(fast, name), getattr(slow, name)
        scale = max(float(np.max(np.abs(b))), 1e-300)
        assert np.max(np.abs(a - b)) <= rtol * scale, name
    # on the run's energy scale: a term that is a small difference of large ones (the
    # composite steps' "algorithmic" energy) carries their round-off
    escale = max(float(np.max(np.abs(b))) for b in slow.energy.values())
    for key, b in slow.energy.items():
        a = fast.energy[key]
        assert np.max(np.abs(a - b)) <= rtol * escale, key
    # the work counters: the same work on both backends (the Newmark kernel's; none for the
    # exact one), every step a trial, every trial at least one solve
    assert fast.work == slow.work
    if method == "newmark":
        w = fast.work
        assert set(w) == {"trials", "newton_iterations", "factorisations", "location_trials"}
        assert w["trials"] >= N_STEPS + w["location_trials"]
        assert w["newton_iterations"] >= w["trials"]
        assert 1 <= w["factorisations"] <= w["newton_iterations"]
        assert w["location_trials"] > 0
    else:
        assert fast.work == {}
