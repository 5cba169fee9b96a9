"""A rack whose friction is above any demand behaves as the same rack with its pallets rigidly
attached (issue #5 acceptance, first consistency test).

The reference is computed here, independently of the stick–slip engine (which integrates in
modal coordinates with the pallets as separate masses held by contact forces):

* a direct Newmark average-acceleration integration (Newmark 1959; Chopra, *Dynamics of
  Structures*, §5.4, Table 5.4.2) of ``M_total ü + C u̇ + K u = -M_total r a_g`` in physical
  coordinates, with ``M_total = model.total_mass_matrix()`` (pallet masses added on their
  nodes, paper §IV: "the supported masses" rigidly attached) and the same C, K. Same scheme,
  same dt: the two must agree to round-off.
* the exact solution of the same linear ODE for a piecewise-linear ground acceleration
  (``scipy.signal.lsim`` with ``interp=True``, matrix exponential of the state-space form).
  Newmark's period error is O((ω dt)²) (Chopra Fig. 5.5.2), so at dt = 5 ms and T1 = 0.65 s the
  peak beam displacement must agree within 0.1 %.

The record is El Centro 1940 N-S (0-5 s, dt = 10 ms), analysed at dt = 5 ms: ``run_rack``
interpolates it linearly, which is exactly the excitation both references see. The engine runs
with ``method="newmark"`` for the first reference; with the exact modal propagators (the default
here) it must match the exact ``lsim`` solution to 1e-7 instead.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from analysis_inputs import paper_model, short_record
from seisrack.analysis import run_rack

MU_RIGID = 50.0  # far above any beam acceleration / g of the record (alpha ~ 0.7)
DT = 0.005  # [s] analysis step, half the record's


def newmark_total_mass(model, ag: np.ndarray, dt: float) -> np.ndarray:
    """(n_t, n_dof) [m] displacements of the rack with rigidly attached pallets (Chopra §5.4)."""
    M, C, K, r = model.total_mass_matrix(), model.C, model.K, model.r_x  # noqa: N806
    n_t, n = ag.size, M.shape[0]
    p = -np.outer(ag, M @ r)
    u = np.zeros((n_t, n))
    v = np.zeros(n)
    a = np.linalg.solve(M, p[0] - C @ v - K @ u[0])
    khat = K + 2.0 / dt * C + 4.0 / dt**2 * M
    lu = np.linalg.inv(khat)
    for i in range(n_t - 1):
        rhs = p[i + 1] + M @ (4.0 / dt**2 * u[i] + 4.0 / dt * v + a) + C @ (2.0 / dt * u[i] + v)
        u[i + 1] = lu @ rhs
        v_new = 2.0 / dt * (u[i + 1] - u[i]) - v
        a = 4.0 / dt**2 * (u[i + 1] - u[i]) - 4.0 / dt * v - a
        v = v_new
    return u


@pytest.fixture(scope="module")
def rigid_case():
    model = paper_model(MU_RIGID)
    rec = short_record()
    resp = run_rack(model, rec, dt=DT, method="newmark", basis="full")
    return model, rec, resp


def test_nothing_slides_and_forces_stay_below_friction(rigid_case):
    model, _, resp = rigid_case
    assert not resp.sliding_occurred()
    assert np.max(np.abs(resp.pallet_sliding)) < 1e-12
    # the demand (alpha) is well below mu, so the contact never reached its limit
    assert max(resp.simplified_check()["alpha"]) < 0.1 * MU_RIGID


def test_matches_direct_newmark_on_total_mass(rigid_case):
    model, rec, resp = rigid_case
    t = np.arange(resp.t.size) * DT
    ag = np.interp(t, rec.time, rec.accel)
    u = newmark_total_mass(model, ag, DT)
    for lv, dofs in enumerate(model.level_dofs[0]):
        ref = u[:, dofs].mean(axis=1)
        scale = np.max(np.abs(ref))
        assert np.max(np.abs(resp.beam_displacement[:, lv] - ref)) < 1e-8 * scale
    # the pallets move with their nodes: pallet friction = pallet mass x absolute node accel
    a_node = np.gradient(np.gradient(u[:, model.pallet_dofs[:, 0, 0]], DT, axis=0), DT, axis=0)
    inertia = model.pallet_mass * (a_node + ag[:, None])
    scale = np.max(np.abs(inertia))
    assert np.max(np.abs(resp.pallet_friction[5:-5] - inertia[5:-5])) < 0.05 * scale


def test_matches_exact_linear_solution_within_0p1_percent(rigid_case):
    model, rec, resp = rigid_case
    M, C, K, r = model.total_mass_matrix(), model.C, model.K, model.r_x  # noqa: N806
    n = M.shape[0]
    Minv = np.linalg.inv(M)  # noqa: N806
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K, -Minv @ C]])  # noqa: N806
    B = np.concatenate([np.zeros(n), -r])[:, None]  # noqa: N806
    dofs = model.level_dofs[0][0]
    out = np.zeros((1, 2 * n))
    out[0, dofs] = 1.0 / len(dofs)
    _, y, _ = signal.lsim(signal.StateSpace(A, B, out, np.zeros((1, 1))), rec.accel, rec.time,
                          interp=True)
    peak_exact = np.max(np.abs(y))
    peak = np.max(np.abs(resp.beam_displacement[::2, 0]))  # at the record's time points
    assert peak == pytest.approx(peak_exact, rel=1e-3)
    # the exact modal propagators solve the same piecewise-linear problem in closed form
    exact = run_rack(model, rec, dt=DT, method="exact", rigid_companion=False, basis="full")
    hist = exact.beam_displacement[::2, 0]
    assert np.max(np.abs(hist - y)) < 1e-7 * peak_exact


def test_sliding_rack_differs_from_rigid(rigid_case):
    """The comparison above can fail: with mu = 0.3 the response is clearly different."""
    _, rec, resp = rigid_case
    low = run_rack(paper_model(0.3), rec, dt=DT, rigid_companion=False)
    assert low.sliding_occurred()
    assert low.peaks()["beam_displacement_m"] < 0.8 * resp.peaks()["beam_displacement_m"]
