"""Design quantities, pallet identity and filtered floor accelerations of a rack run (issue 14,
item 6).

References: the design operators must equal the element end forces of
``seisrack.fe.recovery.element_end_forces`` (k·T·u_e of each element, independent code); the
connector moment must equal the beam end moment in a static equilibrium state (the beam end node
carries no external moment), and ``k·rotation``; under gravity the upright axial forces at the
base must balance the vertical support reactions. Full-rate peaks must not depend on
``save_every``. The low-pass filter is checked on sines against the Butterworth magnitude
response (|H|² of the order-4 filter applied forward and backward).
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse.linalg as sla

from analysis_inputs import paper_model, short_record
from seisrack.analysis import run_rack
from seisrack.analysis.peaks import design_history
from seisrack.analysis.rack import lowpass
from seisrack.fe.recovery import base_reactions, design_operators, element_end_forces
from seisrack.model import compile_rack, load_rack, with_friction

THREE = "examples/three_level_rack.toml"


@pytest.fixture(scope="module")
def three():
    return compile_rack(with_friction(load_rack(THREE), 0.2))


@pytest.fixture(scope="module")
def three_run(three):
    return run_rack(three, short_record())


def _static(model, ax=3.0):
    f = model.total_mass_sparse() @ model.r_x * ax - model.g * (model.M_sparse @ model.r_y)
    return sla.spsolve(model.K_sparse.tocsc(), f)[None, :]


def test_design_operators_equal_element_end_forces(three):
    d = design_operators(three)
    U = np.random.default_rng(1).normal(size=(4, three.n_dof)) * 1e-3
    f = element_end_forces(three, U)
    beam = np.flatnonzero(three.element_kind == 1)
    n_bay = three.upright_x.size - 1
    # the left end of L2-B3 is the beam element of level 2, bay 3 starting at upright 3
    k = three.mesh.elements[beam, 0]
    e = beam[(three.element_storey[beam] == 1) & (three.element_line[beam] == 2)
             & np.isclose(three.nodes[k, 0], three.upright_x[2])][0]
    col = (1 * n_bay + 2) * 2
    assert d.beam_labels[col] == "L2-B3-left"
    np.testing.assert_allclose(U @ d.beam_moment[:, col].toarray()[:, 0], -f[:, e, 2])
    np.testing.assert_allclose(U @ d.beam_shear[:, col].toarray()[:, 0], f[:, e, 1])
    # axial force at the top of the segment below level 2 of upright 4, tension positive
    col = 3 * 4 + 2
    assert d.axial_labels[col] == "U4-L2"
    e = three.upright_below_elements[3, 1]
    np.testing.assert_allclose(U @ d.axial[:, col].toarray()[:, 0], f[:, e, 3])


def test_connector_equilibrium_and_gravity(three):
    d = design_operators(three)
    U = _static(three)
    beam_m = (U @ d.beam_moment)[0]
    conn = (U @ d.connector_moment)[0]
    idx = [d.beam_labels.index(lab) for lab in d.connector_labels]
    assert len(idx) == 2 * 3 * 3  # every beam end of the 3 x 3 rack is semi-rigid
    # equal to the beam end moment up to the consistent-mass moment load of the gravity
    np.testing.assert_allclose(conn, beam_m[idx], atol=1e-3 * np.abs(conn).max())
    k = three.mesh.spring_k[three.mesh.springs[:, 1] >= 0][0]
    np.testing.assert_allclose(conn, k * (U @ d.connector_rotation)[0], rtol=1e-12)
    # gravity alone: base axial forces balance the vertical reactions
    Ug = sla.spsolve(three.K_sparse.tocsc(), -three.g * (three.M_sparse @ three.r_y))[None]
    n_base = (Ug @ d.axial)[0].reshape(4, 4)[:, 0]
    np.testing.assert_allclose(-n_base, base_reactions(three, Ug)[0, :, 1], rtol=1e-9)
    weight = three.g * 18 * 800.0
    assert weight < -n_base.sum() < weight * 1.05  # pallets + part of the members' weight


def test_design_peaks_full_rate_and_save_every(three, three_run):
    r1 = three_run
    r7 = run_rack(three, short_record(), save_every=7)
    s1, s7 = r1.design_peaks(), r7.design_peaks()
    for key in ("interstorey_drift_ratio", "beam_end_moment_Nm", "beam_end_shear_N",
                "connector_moment_Nm", "connector_rotation_rad", "upright_axial_force_N",
                "upright_moment_section_Nm"):
        assert s1[key]["peak_abs"] == pytest.approx(s7[key]["peak_abs"], rel=1e-12), key
        assert s1[key]["max_abs"] > 0
    assert s1["upright_n_m"] == s7["upright_n_m"]
    # with every step kept, the tracker's extremes are those of the histories
    for name, key in (("drift", "interstorey_drift_ratio"), ("beam_moment", "beam_end_moment_Nm"),
                      ("axial", "upright_axial_force_N")):
        h = design_history(r1, name, gravity=False)
        np.testing.assert_allclose(s1[key]["seismic_max"], h.max(axis=0), rtol=1e-12)
        np.testing.assert_allclose(s1[key]["seismic_min"], h.min(axis=0), rtol=1e-12)
        tot = design_history(r1, name)
        np.testing.assert_allclose(s1[key]["peak_abs"], np.abs(tot).max(axis=0), rtol=1e-12)
    # drift from the level displacements and the storey heights (1.5 m each)
    disp = r1.beam_displacement
    drift = np.diff(np.c_[np.zeros(disp.shape[0]), disp], axis=1) / 1.5
    np.testing.assert_allclose(design_history(r1, "drift", gravity=False), drift, atol=1e-12)
    # (N, M) pairs: |N| at the largest-|N| step is the axial envelope
    nm = s1["upright_n_m"]
    n_env = s1["upright_axial_force_N"]["peak_abs"]
    np.testing.assert_allclose([abs(n) for n, _ in nm["at_max_abs_N"]], n_env, rtol=1e-12)
    m_env = s1["upright_moment_section_Nm"]["peak_abs"]
    np.testing.assert_allclose([abs(m) for _, m in nm["at_max_abs_M"]], m_env, rtol=1e-12)
    pk = r1.peaks()
    assert pk["interstorey_drift_ratio"] == s1["interstorey_drift_ratio"]["max_abs"]


def test_pallet_ids_and_labels(three, three_run):
    s = three_run.summary()
    labels = [p["label"] for p in s["pallets"]]
    assert [p["id"] for p in s["pallets"]] == list(range(1, 19))
    assert labels[:4] == ["L1-B1-S1", "L1-B1-S2", "L1-B2-S1", "L1-B2-S2"]
    assert labels[-1] == "L3-B3-S2" and len(set(labels)) == 18
    assert three.pallet_bay.tolist() == [0, 0, 1, 1, 2, 2] * 3
    assert s["pallets_at_risk"] == three_run.pallets_at_risk()  # 1-based ids, as everywhere


def test_warehouse_labels_unique():
    model = compile_rack(load_rack("examples/warehouse_rack.toml"))
    bay = model.pallet_bay
    assert bay.min() == 0 and bay.max() == 19
    x = model.nodes[model.pallet_node[:, 0], 0]
    assert np.all((x > model.upright_x[bay]) & (x < model.upright_x[bay + 1]))


def test_lowpass_magnitude():
    h, fc = 1e-3, 20.0
    t = np.arange(0, 4.0, h)
    for f, gain in ((5.0, 1.0), (120.0, 0.0)):
        a = np.sin(2 * np.pi * f * t)[:, None]
        y = lowpass(a, h, fc)[1000:-1000]
        expect = 1.0 / (1.0 + (f / fc) ** 8)  # |H|^2 of the order-4 Butterworth
        assert np.abs(y).max() == pytest.approx(expect, abs=2e-3)
        assert np.abs(y).max() == pytest.approx(gain, abs=2e-3)
    assert np.array_equal(lowpass(a, h, 600.0), a)  # above Nyquist: unchanged


def test_filtered_acceleration_reported_and_independent_of_save_every():
    model = paper_model(0.3)
    r1 = run_rack(model, short_record())
    r5 = run_rack(model, short_record(), save_every=5, accel_filter_hz=10.0)
    r5b = run_rack(model, short_record(), save_every=5)
    pk = r1.peaks()
    assert pk["acceleration_filter_hz"] == 20.0
    assert pk["beam_acceleration_filtered_m_s2"] == pytest.approx(
        r5b.peaks()["beam_acceleration_filtered_m_s2"], rel=1e-12)
    assert pk["beam_acceleration_filtered_m_s2"] <= pk["beam_acceleration_m_s2"] * 1.001
    assert r5.peaks()["acceleration_filter_hz"] == 10.0
    np.testing.assert_allclose(np.abs(r1.beam_acceleration_filtered).max(axis=0),
                               pk["per_level"]["beam_acceleration_filtered_m_s2"])
    with pytest.raises(ValueError, match="accel_filter_hz"):
        run_rack(model, short_record(), accel_filter_hz=0.0)
    # below the lowest cut-off: refused by name (1e-7 Hz once ended in a LinAlgError of the
    # filter's design); the lowest one runs
    with pytest.raises(ValueError, match="accel_filter_hz.*>= 0.1 Hz"):
        run_rack(model, short_record(), accel_filter_hz=1e-7)
    assert run_rack(model, short_record(), accel_filter_hz=0.1).peaks()[
        "acceleration_filter_hz"] == 0.1
