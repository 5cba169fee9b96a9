"""Friction bounds, energy balance and the pallet fall check of a rack time history.

Physics (paper §II Eqs 2–3, §IV.B):

* Coulomb's law bounds the horizontal force of a beam on a pallet by μs·N, N = m (g + a_v);
  while a pallet slides the force is exactly μd·N.
* Hence the total contact force between beams and pallets never exceeds Σ μs·m·g, and reaches
  Σ μ·m·g (μ = μs = μd) when all pallets slide at once: "the total force is capped at μ·M·g"
  (paper Table 2: the contact force saturates for μ = 0.30).
* The work of the ground equals kinetic + strain energy + damping + friction dissipation; the
  engine's discrete identity closes to round-off (docs/theory/stick_slip_engine.md §6).
* A pallet whose sliding reaches its free distance (``sliding_limit``) may fall: issue #5 item 2.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from analysis_inputs import RECORD_NAME, model_from, paper_model, paper_with, short_record
from seisrack.analysis import run_rack
from seisrack.motion import Record, load_builtin_record


@settings(max_examples=8, deadline=None)
@given(mu_s=st.floats(0.05, 1.2), ratio=st.floats(0.5, 1.0))
def test_friction_never_exceeds_mu_static_n(mu_s, ratio):
    rec = short_record()
    model = paper_model(round(mu_s, 3), round(mu_s, 3) * round(ratio, 3))
    resp = run_rack(model, rec, rigid_companion=False)
    n = resp.pallet_mass * resp.g
    bound = resp.pallet_mu_static * n
    assert np.all(np.abs(resp.pallet_friction) <= bound * (1 + 1e-9) + 1e-9)
    total = np.abs(resp.contact_force.sum(axis=1))
    assert np.all(total <= bound.sum() * (1 + 1e-9))
    # while a pallet slides, the force is mu_d N (Eq. 3)
    sliding = ~resp.history.stuck
    if sliding.any():
        f = np.abs(resp.pallet_friction)[sliding]
        np.testing.assert_allclose(f, np.broadcast_to(resp.pallet_mu_dynamic * n,
                                                      sliding.shape)[sliding], rtol=1e-9)
    assert resp.history.energy_error() < 1e-6


def test_total_force_capped_at_mu_m_g_when_all_slide():
    mu = 0.3
    rec = short_record()
    resp = run_rack(paper_model(mu), rec)
    cap = mu * resp.pallet_mass.sum() * resp.g  # paper: mu M g, 0.3 x 1600 kg x 9.81 m/s2
    peak = resp.peaks()["total_friction_force_N"]
    assert peak <= cap * (1 + 1e-12)
    assert peak == pytest.approx(cap, rel=1e-9)  # all four pallets slide together: saturated
    all_slide = np.all(~resp.history.stuck, axis=1)
    assert all_slide.any()
    np.testing.assert_allclose(np.abs(resp.contact_force.sum(axis=1))[all_slide], cap,
                               rtol=1e-9)
    # above the demand the cap is not reached
    high = run_rack(paper_model(5.0), rec, rigid_companion=False)
    assert high.peaks()["total_friction_force_N"] < 0.5 * 5.0 * resp.pallet_mass.sum() * high.g


def test_friction_bound_with_vertical_motion():
    """With a vertical record N = m (g + a_v): the bound follows N(t), not m g."""
    rec = short_record()
    # a vertical record: half of El Centro's 5-10 s segment (any record of the same dt/length)
    later = load_builtin_record(RECORD_NAME).accel[rec.n - 1: 2 * rec.n - 1]
    vert = Record(0.5 * later, rec.dt, name="vertical")
    resp = run_rack(paper_model(0.4), rec, vertical=vert, rigid_companion=False)
    n = resp.history.normal
    av = np.interp(resp.t, vert.time, vert.accel)  # run_rack interpolates onto its grid
    np.testing.assert_allclose(n, resp.pallet_mass * (resp.g + av[:, None]), rtol=1e-12)
    assert np.all(np.abs(resp.pallet_friction) <= resp.pallet_mu_static * n * (1 + 1e-9) + 1e-9)
    assert resp.sliding_occurred()
    assert resp.history.energy_error() < 1e-6


@pytest.mark.parametrize("mu", [0.3, 0.6, 50.0])
def test_energy_balance_closes(mu):
    resp = run_rack(paper_model(mu), short_record(), rigid_companion=False)
    err = resp.history.energy_error()
    assert err < 1e-6, err
    e = resp.energy
    assert e["input"].max() > 1.0  # J: the test is not vacuous
    if mu < 1:
        assert e["friction"][-1] > 0.0  # sliding dissipates
        assert np.all(np.diff(e["friction"]) >= -1e-9 * e["friction"][-1])


def test_fall_check_flags_pallet_beyond_its_limit():
    """P1 gets a 5 mm limit, the others keep their free distances (50–100 mm)."""
    d = paper_with(0.6)
    free = run_rack(model_from(d), short_record(), rigid_companion=False)
    peak = free.pallet_peak_sliding()
    assert 0.005 < peak[0] < 0.05 and np.all(peak < 0.05)  # slides, but not to the uprights
    assert free.pallets_at_risk() == []
    d["pallets"][0]["sliding_limit"] = 0.005
    resp = run_rack(model_from(d), short_record(), rigid_companion=False)
    assert resp.pallets_at_risk() == [1]  # 1-based ids, as every output numbers pallets
    util = resp.fall_utilisation()
    assert util[0] == pytest.approx(peak[0] / 0.005, rel=1e-9) and util[0] > 1
    assert np.all(util[1:] < 1)
    s = resp.summary()
    # the summary numbers pallets from 1 (issue 14), as the library method does
    assert s["pallets_at_risk"] == [1] and s["pallets"][0]["fall_utilisation"] > 1


def test_fall_check_uses_the_side_it_slid_towards():
    """Limits are one-sided: P1 (bay 1, left) has 50 mm to its upright and 100 mm to P2."""
    resp = run_rack(paper_model(0.3), short_record(), rigid_companion=False)
    s = resp.pallet_sliding
    np.testing.assert_allclose(resp.pallet_limit_neg, [0.05, 0.10, 0.05, 0.10])
    expect = np.maximum(s.max(axis=0).clip(0) / resp.pallet_limit_pos,
                        (-s.min(axis=0)).clip(0) / resp.pallet_limit_neg)
    np.testing.assert_allclose(resp.fall_utilisation(), expect)
    assert resp.pallets_at_risk() == [int(j) for j in np.flatnonzero(expect >= 1)]
