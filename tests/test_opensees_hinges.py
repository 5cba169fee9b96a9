"""Nonlinear connectors and base plates against OpenSees (issue 12): the paper rack shaken into
yielding, seisrack vs OpenSeesPy.

Reference: OpenSeesPy (3.7.1 when written) running the script of ``seisrack export opensees``
for the same compiled rack with ``hysteresis=spec.hysteresis``: dispBeamColumn members (exactly
seisrack's elements), every connection a ``zeroLength`` rotational spring with the law's
OpenSees material — (a) ``ElasticPP`` (= ``Steel01`` with b = 0), (b) ``Pinching4`` without
damage — pallets rigidly attached (``equalDOF``; in seisrack ``with_friction(spec, 1e6)``: no
pallet slides), Newmark average acceleration (γ = 1/2, β = 1/4) with Newton (NormDispIncr
1e-10), the same dt = 5 ms, the same ground motion (El Centro 1940 NS, first 30 s, × 1.5,
then 30 s of free vibration; both interpolate the 10 ms record linearly), the same damping
C = a0 M + a1 K with the INITIAL stiffness (seisrack: ``model.damping_coefficients``; OpenSees:
``rayleigh(0, 0, a1, 0)``, betaKinit). P-Δ is OFF in both (``[second_order] p_delta = false``;
the export writes a Linear transformation and no gravity load).

The pinching law is asymmetric on the connectors (another negative envelope and other negative
ratios), so matching moment histories also check the sign convention: the zeroLength
deformation u_j − u_i is seisrack's hinge rotation u[a] − u[b] (``model.hinge_dofs``). Both
laws have rForce > uForce (see docs/theory/hysteresis.md §4.6 on OpenSees' flat segments).

Compared (acceptance of issue 12: within 2 %): the peak |beam-level displacement|, the
residual drift (the mean beam-level displacement over the last 2 s of free vibration,
settled), and the moment history of every hinge (max |ΔM| over time relative to the largest
|M|). seisrack runs twice per law: with the full modal basis (the same equations as OpenSees)
and with the default ``basis="auto"`` (what a user gets: above 50 DOFs a Ritz basis). Measured
when written (OpenSeesPy 3.7.1.2), both bases: peak −6.9e-5 (EPP) and −5.9e-6 (pinching),
residual drift −7.5e-4 and −1.9e-4, hinge moments ≤ 4.3e-4 and ≤ 5.4e-4 — the same scheme
and step on both sides. The residual drift is the sensitive check of a reduced basis: a Ritz
basis that kept the peaks within 1.2e-3 was measured 29 % off in residual drift.

With P-Δ (``test_p_delta_with_elastic_stiffness_damping_matches``, elastic-plastic, full
basis): seisrack's chord form against ``geomTransf PDelta`` with gravity first, the damping
a1 K_E on both sides (``[damping] stiffness_term = "elastic"``, set here; OpenSees'
betaKinit: the PDelta transformation's initial stiffness has no geometric term). Measured:
peak +4.4e-5, residual drift −9.1e-4 (21.79 mm vs 21.81 mm), hinge moment histories within
2.1e-3 of their peaks; with ``stiffness_term = "with_p_delta"`` (a1 (K_E + K_G)) the same run
is +4.4e-3, +5.9e-3 and 3.4e-2 off.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from seisrack.analysis.rack import run_rack
from seisrack.export import opensees_script
from seisrack.model import compile_rack, load_rack, with_friction
from seisrack.model.hinge_law import HingeLaw
from seisrack.model.spec import Hysteresis
from seisrack.motion import Record, load_builtin_record

ROOT = Path(__file__).resolve().parents[1]
RACK = ROOT / "examples" / "paper_rack.toml"
K_CONNECTION = 160e3  # N·m/rad, [connections] of the paper rack (Table 1)
DT = 0.005
SECONDS = 30.0
SCALE = 1.5
FREE_VIBRATION = 30.0
TOL = 0.02  # issue 12
BASES = ("full", "auto")

LAWS = {
    # as examples/paper_rack_nonlinear.toml: theta_y = 15.6 mrad (connectors), 18.8 (bases)
    "elastic-plastic": Hysteresis(
        HingeLaw("elastic-plastic", K_CONNECTION, yield_moment=2500.0),
        HingeLaw("elastic-plastic", K_CONNECTION, yield_moment=3000.0)),
    # asymmetric connectors (hooked tabs: weaker and more pinched in hogging), symmetric bases
    "pinching": Hysteresis(
        HingeLaw("pinching", K_CONNECTION, envelope_rotation=(0.01, 0.03, 0.06, 0.10),
                 envelope_moment=(1600.0, 2400.0, 2800.0, 3000.0),
                 negative_envelope_rotation=(0.008, 0.025, 0.05, 0.09),
                 negative_envelope_moment=(1280.0, 2000.0, 2300.0, 2450.0),
                 reload_rotation_ratio=0.3, reload_moment_ratio=0.2, unload_moment_ratio=0.05,
                 negative_reload_rotation_ratio=0.4, negative_reload_moment_ratio=0.25,
                 negative_unload_moment_ratio=0.1),
        HingeLaw("pinching", K_CONNECTION, envelope_rotation=(0.0125, 0.03, 0.06, 0.10),
                 envelope_moment=(2000.0, 2700.0, 3100.0, 3300.0),
                 reload_rotation_ratio=0.3, reload_moment_ratio=0.2, unload_moment_ratio=0.05)),
}


def rack_spec(law: str):
    """The paper rack with ``LAWS[law]``, rigid pallets, P-Δ off."""
    spec = with_friction(load_rack(RACK), 1e6)
    spec = replace(spec, hysteresis=LAWS[law],
                   second_order=replace(spec.second_order, p_delta=False))
    assert spec.hysteresis.nonlinear and not spec.second_order.p_delta
    return spec


def ground_motion() -> Record:
    rec = load_builtin_record("elcentro_1940_ns")
    n = int(round(SECONDS / rec.dt)) + 1
    return Record(rec.accel[:n] * SCALE, rec.dt, rec.name)


def opensees_history(model, hysteresis, rec: Record, dt: float,
                     free_vibration: float, geom_transf: str = "Linear") -> dict[str, np.ndarray]:
    """Run the exported script (rigid pallets) on the record resampled to ``dt``."""
    script = opensees_script(model, pallets="rigid", hysteresis=hysteresis)
    ns: dict = {"__name__": "rack_ops"}
    exec(compile(script, "rack_ops.py", "exec"), ns)
    ns["GEOM_TRANSF"] = geom_transf
    ag = np.concatenate([rec.accel, np.zeros(int(round(free_vibration / rec.dt)))])
    k = int(round(rec.dt / dt))
    ag = np.interp(np.arange((ag.size - 1) * k + 1) / k, np.arange(ag.size), ag)
    out = ns["history"](ag, dt)
    return {key: np.asarray(v, dtype=float) for key, v in out.items()}


@pytest.fixture(scope="module", params=sorted(LAWS))
def peer(request):
    """(law, spec, model, OpenSees histories): one OpenSees run per law."""
    pytest.importorskip("openseespy.opensees")
    spec = rack_spec(request.param)
    model = compile_rack(spec)
    ops = opensees_history(model, spec.hysteresis, ground_motion(), DT, FREE_VIBRATION)
    return request.param, spec, model, ops


@pytest.fixture(scope="module", params=BASES)
def pair(request, peer):
    """seisrack with the full modal basis (the same equations as OpenSees) and with the
    default ``basis="auto"`` (what a user runs) against the same OpenSees run."""
    law, _spec, model, ops = peer
    res = run_rack(model, ground_motion(), dt=DT, free_vibration=FREE_VIBRATION,
                   basis=request.param)
    return f"{law}, basis {request.param}", request.param, res, ops


def test_same_grid_and_no_sliding(pair) -> None:
    _law, _basis, res, ops = pair
    assert not res.sliding_occurred()
    assert ops["t"].shape == res.t.shape
    np.testing.assert_allclose(ops["t"], res.t, atol=1e-9)


def test_hinges_yield_clearly(pair) -> None:
    _law, _basis, res, _ops = pair
    peaks = res.hinges.peaks()
    duct = [p["ductility"] for p in peaks]
    assert all(p["yielded"] for p in peaks if p["kind"] == "base")
    assert max(duct) > 2.5, duct  # clearly inelastic, and the rack stands (finite response)


def test_peak_displacement_within_2_percent(pair) -> None:
    law, basis, res, ops = pair
    s = np.abs(res.beam_displacement[:, 0]).max()
    o = np.abs(ops["level_displacement"][:, 0]).max()
    assert abs(s / o - 1) < TOL, f"{law}: seisrack {s:.6f} m, OpenSees {o:.6f} m"
    if basis == "full":  # same equations, scheme and step: far tighter (measured <= 7e-5)
        assert abs(s / o - 1) < 1e-3


def residual_drift(d: np.ndarray) -> float:
    """The settled drift: the mean of the last 2 s of free vibration (several periods), after
    checking that they move by less than 5 % of it."""
    tail = d[-int(round(2.0 / DT)):]
    drift = float(tail.mean())
    assert np.ptp(tail) < 0.05 * abs(drift), (np.ptp(tail), drift)
    return drift


def test_residual_drift_within_2_percent(pair) -> None:
    law, _basis, res, ops = pair
    s = residual_drift(res.beam_displacement[:, 0])
    o = residual_drift(ops["level_displacement"][:, 0])
    assert abs(o) > 5e-3  # a real permanent drift (about 5-15 % of the peak), not noise
    assert abs(s / o - 1) < TOL, f"{law}: seisrack {s:.6f} m, OpenSees {o:.6f} m"


def test_hinge_moment_histories(pair) -> None:
    law, _basis, res, ops = pair
    ms, mo = res.hinges.moment, ops["spring_force"]
    assert ms.shape == mo.shape
    scale = np.abs(mo).max(axis=0)
    err = np.abs(ms - mo).max(axis=0) / scale
    assert err.max() < TOL, f"{law}: {dict(zip(res.hinges.labels, err.round(5), strict=True))}"
    rot_err = np.abs(res.hinges.rotation - ops["spring_deformation"]).max(axis=0)
    assert rot_err.max() < TOL * np.abs(ops["spring_deformation"]).max()


def test_pinching_sign_convention_matters() -> None:
    """The asymmetric law gives other moments for the mirrored rotation history, so the moment
    agreement above is a check of the export's orientation (not a symmetric coincidence)."""
    from seisrack.dynamics._hysteresis import _hyst_drive

    code, par = LAWS["pinching"].beam_to_upright.pack()

    def moments(theta: np.ndarray) -> np.ndarray:
        m, kt = np.empty_like(theta), np.empty_like(theta)
        _hyst_drive(code, par, theta, m, kt)
        return m

    theta = 0.03 * np.sin(np.linspace(0, 6 * np.pi, 600)) * np.linspace(0.2, 1, 600)
    assert np.abs(moments(theta) + moments(-theta)).max() > 100.0  # N·m: not odd


@pytest.fixture(scope="module")
def p_delta_pair():
    """The elastic-plastic case WITH P-Δ: seisrack's chord form (``form = "p_delta_only"``)
    against OpenSees' ``geomTransf PDelta`` with gravity applied first, the damping
    C = a1 K_E on both sides (seisrack's ``[damping] stiffness_term = "elastic"``, set here;
    OpenSees' betaKinit: its initial stiffness has no geometric term,
    ``PDeltaCrdTransf2d/3d::getInitialGlobalStiffMatrix``). Full modal basis."""
    pytest.importorskip("openseespy.opensees")
    spec = rack_spec("elastic-plastic")
    spec = replace(spec, second_order=replace(spec.second_order, p_delta=True,
                                              form="p_delta_only"),
                   damping=replace(spec.damping, stiffness_term="elastic"))
    model = compile_rack(spec)
    ops = opensees_history(model, spec.hysteresis, ground_motion(), DT, FREE_VIBRATION,
                           geom_transf="PDelta")
    res = run_rack(model, ground_motion(), dt=DT, free_vibration=FREE_VIBRATION, basis="full")
    return res, ops


@pytest.mark.slow
def test_p_delta_with_elastic_stiffness_damping_matches(p_delta_pair) -> None:
    res, ops = p_delta_pair
    assert not res.sliding_occurred()
    s = np.abs(res.beam_displacement[:, 0]).max()
    o = np.abs(ops["level_displacement"][:, 0]).max()
    assert abs(s / o - 1) < TOL, f"peak: seisrack {s:.6f} m, OpenSees {o:.6f} m"
    s = residual_drift(res.beam_displacement[:, 0])
    o = residual_drift(ops["level_displacement"][:, 0])
    assert abs(o) > 5e-3
    assert abs(s / o - 1) < TOL, f"residual drift: seisrack {s:.6f} m, OpenSees {o:.6f} m"
    ms, mo = res.hinges.moment, ops["spring_force"]
    err = np.abs(ms - mo).max(axis=0) / np.abs(mo).max(axis=0)
    assert err.max() < TOL, dict(zip(res.hinges.labels, err.round(5), strict=True))
