"""Nonlinear connections and P-Δ on a 3D rack against OpenSees (issue 21: the last item of
"every command on a 3D rack"): the 3D paper rack shaken into yielding (in both horizontal
directions, or down-aisle only), seisrack vs OpenSeesPy.

Reference: OpenSeesPy (3.7.1 when written) running the script of ``seisrack export opensees``
for the same compiled 3D rack with ``hysteresis=spec.hysteresis``: 6 DOF per node,
``elasticBeamColumn`` members (seisrack's element: periods equal within 1e-8,
``tests/test_export_opensees_3d.py``), ``Truss`` bracing, every connection a ``zeroLength``
rotational spring about its axis (rz for a connector and a base plate in down-aisle bending,
rx for a base plate in cross-aisle bending) with the law's OpenSees material (``ElasticPP``,
``Pinching4`` without damage), ``geomTransf PDelta`` (``GEOM_TRANSF = "PDelta"``) against
seisrack's ``[second_order] p_delta = true, form = "p_delta_only"`` (the same chord term,
``tests/test_fe_pdelta_3d.py``), gravity applied first (``gravity()``, a static step held
constant), pallets rigid (OpenSees: their masses on their supports; seisrack:
``with_friction(spec, 1e6)``, no pallet slides), Newmark average acceleration with Newton
(NormDispIncr 1e-10), the same dt = 5 ms, damping C = a1 K_initial (= a1 K_E). Ground
motion: El Centro 1940 N-S × 1.5 down-aisle and the same record 4 s later × 1.5 cross-aisle
(not in case (b)), 30 s, then 30 s of
free vibration (20 s did not settle the elastic-plastic rack: 5.3 % of its drift in the last
2 s); both programs interpolate the 10 ms record linearly.

Compared (acceptance of issue 21: within 2 %): the peak level displacement in each direction,
the residual down-aisle drift (the mean of the last 2 s, settled), and the peak moment of every
connector; the base plates' peak moments too, and a cross-aisle base plate must yield (the
cross-aisle ground motion bends the base plates about x past their yield).

The cases: (a) elastic-perfectly plastic connectors (My 2.5 kN·m) and base plates (My 60 N·m:
the base plates are all but pinned down-aisle, and yield cross-aisle too), P-Δ off, both
directions. (b) the same laws WITH P-Δ, down-aisle motion only, the damping
C = a1 K_E on both sides (seisrack's ``[damping] stiffness_term = "elastic"``, set here;
OpenSees' betaKinit: ``PDeltaCrdTransf3d::getInitialGlobalStiffMatrix`` leaves the geometric
N/L terms out of the initial stiffness). Measured (OpenSeesPy 3.7.1): peak −0.010 %, residual
drift +0.12 % (3.085 mm vs 3.081 mm, peak 100 mm), connector peak moments within 0.10 %; with
``stiffness_term = "with_p_delta"`` (a1 (K_E + K_G), seisrack's default) the
residual drift is −5.7 % off. With BOTH directions the EPP + P-Δ rack is not compared: its
residual drift differs by 22.6 % (a1 K_E) or 15.6 % (a1 (K_E + K_G)), and by 26 % with no
damping at all (seisrack −11.4 mm, OpenSees −15.5 mm, peaks within 0.7 %), so the gap is a
model difference, not the damping: in seisrack the down-aisle drift of this symmetric rack
is the same with or without the cross-aisle motion (3.084 vs 3.085 mm), in OpenSees the
cross-aisle motion moves it from 3.081 to 2.515 mm. Not established which difference couples
them there: OpenSees' PDelta transformation takes each member's current axial force (the
cross-aisle overturning changes the uprights' forces), seisrack's K_G the gravity forces,
and the rigid pallets differ (below). (c) the pinched law without damage on the connectors
(asymmetric, as in ``tests/test_opensees_hinges.py``) and a hardening pinched envelope on the
base plates (yield at 0.3 mrad, 48 N·m, then 0.7, 1.8, 2.6 kN·m at 5, 15, 40 mrad), so that
the base plates yield about both axes while the rack keeps its down-aisle base stiffness:
with P-Δ, both directions.

Differences that remain are model differences, not the integration: a rigid pallet in
seisrack moves with the mean of its supports (a mass on the mean), in OpenSees its mass is
split on the supports; the two differ when the front and rear beams move differently (in
cross-aisle bending of the frames): the moment histories of the cross-aisle base plates differ
by 3.4 % of their peak in both cases, their peaks by 0.2 % at most. With P-Δ and both
directions (c) the connectors' moment histories differ by up to 4 % of their peak, 0.4 % in
(a), 0.92 % in (b) (there the down-aisle base plates' by 12.8 %: at My = 60 N·m they switch
between ±My, and the switching instants differ).
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
from seisrack.motion.components import combine

ROOT = Path(__file__).resolve().parents[1]
RACK = ROOT / "examples" / "paper_rack_3d.toml"
K_CONNECTION = 160e3  # N·m/rad, [connections] of the paper rack (Table 1)
DT = 0.005
SECONDS = 30.0
SHIFT = 4.0  # s: the cross-aisle component is the record this much later
SCALE = 1.5
FREE_VIBRATION = 30.0
TOL = 0.02  # issue 21

_EPP = Hysteresis(HingeLaw("elastic-plastic", K_CONNECTION, yield_moment=2500.0),
                  HingeLaw("elastic-plastic", K_CONNECTION, yield_moment=60.0))
#: case -> (laws, P-Δ, cross-aisle component)
CASES = {
    "elastic-plastic": (_EPP, False, True),
    "elastic-plastic-p-delta-down-aisle": (_EPP, True, False),
    "pinching": (Hysteresis(
        HingeLaw("pinching", K_CONNECTION, envelope_rotation=(0.01, 0.03, 0.06, 0.10),
                 envelope_moment=(1600.0, 2400.0, 2800.0, 3000.0),
                 negative_envelope_rotation=(0.008, 0.025, 0.05, 0.09),
                 negative_envelope_moment=(1280.0, 2000.0, 2300.0, 2450.0),
                 reload_rotation_ratio=0.3, reload_moment_ratio=0.2, unload_moment_ratio=0.05,
                 negative_reload_rotation_ratio=0.4, negative_reload_moment_ratio=0.25,
                 negative_unload_moment_ratio=0.1),
        HingeLaw("pinching", K_CONNECTION, envelope_rotation=(0.0003, 0.005, 0.015, 0.04),
                 envelope_moment=(48.0, 700.0, 1800.0, 2600.0),
                 reload_rotation_ratio=0.3, reload_moment_ratio=0.2, unload_moment_ratio=0.05)),
        True, True),
}


def rack_spec(case: str):
    """The 3D paper rack with the case's laws, rigid pallets, P-Δ (chord form) on or off."""
    laws, p_delta, _cross = CASES[case]
    spec = with_friction(load_rack(RACK), 1e6)
    # OpenSees' rayleigh with betaKinit: a1 K_E (the default is a1 (K_E + K_G))
    return replace(spec, hysteresis=laws, second_order=replace(
        spec.second_order, p_delta=p_delta, form="p_delta_only"),
        damping=replace(spec.damping, stiffness_term="elastic"))


def components(case: str) -> tuple[np.ndarray, np.ndarray, float]:
    rec = load_builtin_record("elcentro_1940_ns")
    n = int(round(SECONDS / rec.dt)) + 1
    s = int(round(SHIFT / rec.dt))
    cross = CASES[case][2]
    return SCALE * rec.accel[:n], SCALE * rec.accel[s:s + n] * cross, rec.dt


def opensees_history(model, spec, case: str) -> dict[str, np.ndarray]:
    ax, az, dt_rec = components(case)
    ns: dict = {"__name__": "rack_ops"}
    exec(compile(opensees_script(model, pallets="rigid", hysteresis=spec.hysteresis),
                 "rack_ops.py", "exec"), ns)
    ns["GEOM_TRANSF"] = "PDelta" if spec.second_order.p_delta else "Linear"
    k = int(round(dt_rec / DT))

    def resample(a: np.ndarray) -> np.ndarray:
        a = np.concatenate([a, np.zeros(int(round(FREE_VIBRATION / dt_rec)))])
        return np.interp(np.arange((a.size - 1) * k + 1) / k, np.arange(a.size), a)

    out = ns["history"](resample(ax), DT, agz=resample(az))
    return {key: np.asarray(v, dtype=float) for key, v in out.items()}


@pytest.fixture(scope="module", params=sorted(CASES))
def pair(request):
    """(case, seisrack response, OpenSees histories), one run each."""
    pytest.importorskip("openseespy.opensees")
    spec = rack_spec(request.param)
    model = compile_rack(spec)
    ax, az, dt_rec = components(request.param)
    res = run_rack(model, combine(Record(ax, dt_rec, "x"), Record(az, dt_rec, "z")), dt=DT,
                   free_vibration=FREE_VIBRATION)
    return request.param, res, opensees_history(model, spec, request.param)


def _settled(d: np.ndarray) -> float:
    tail = d[-int(round(2.0 / DT)):]
    drift = float(tail.mean())
    assert np.ptp(tail) < 0.05 * abs(drift), (np.ptp(tail), drift)
    return drift


@pytest.mark.slow
def test_same_grid_no_sliding_and_yielding_both_ways(pair) -> None:
    case, res, ops = pair
    assert not res.sliding_occurred()
    np.testing.assert_allclose(ops["t"], res.t, atol=1e-9)
    peaks = {p["hinge"]: p for p in res.hinges.peaks()}
    assert max(p["ductility"] for h, p in peaks.items() if h.startswith("connector")) > 1.5
    if CASES[case][2]:
        assert any(p["yielded"] for h, p in peaks.items() if h.endswith("cross-aisle")), case


@pytest.mark.slow
def test_peak_displacements_within_2_percent(pair) -> None:
    case, res, ops = pair
    for d, key in enumerate(("level_displacement", "level_displacement_z")[:1 + CASES[case][2]]):
        s = np.abs(res.beam_displacement[:, 0, d]).max()
        o = np.abs(ops[key][:, 0]).max()
        assert abs(s / o - 1) < TOL, f"{case}, direction {d}: seisrack {s:.6f}, OpenSees {o:.6f}"


@pytest.mark.slow
def test_residual_drift_within_2_percent(pair) -> None:
    case, res, ops = pair
    s = _settled(res.beam_displacement[:, 0, 0])
    o = _settled(ops["level_displacement"][:, 0])
    # a settled permanent drift (measured: 0.41 mm for the elastic-plastic case, its peak
    # 93 mm; 10.5 mm for the pinched one, peak 67 mm)
    assert abs(o) > 2e-4
    assert abs(s / o - 1) < TOL, f"{case}: seisrack {s:.6f} m, OpenSees {o:.6f} m"


@pytest.mark.slow
def test_peak_hinge_moments_within_2_percent(pair) -> None:
    case, res, ops = pair
    ms, mo = res.hinges.moment, ops["spring_force"]
    assert ms.shape == mo.shape
    # the hinges that the motion loads (down-aisle only: not the cross-aisle base plates)
    on = np.abs(mo).max(axis=0) > 1e-3 * np.abs(mo).max()
    ms, mo = ms[:, on], mo[:, on]
    labels = [h for h, x in zip(res.hinges.labels, on, strict=True) if x]
    err = np.abs(np.abs(ms).max(axis=0) / np.abs(mo).max(axis=0) - 1)
    assert err.max() < TOL, f"{case}: {dict(zip(labels, err.round(5), strict=True))}"
    # the sign convention of the rotational zeroLength about rx and rz: the histories agree
    # (not only the magnitudes), within the model difference of the rigid pallets above
    hist = np.abs(ms - mo).max(axis=0) / np.abs(mo).max(axis=0)
    conn = np.array([h.startswith("connector") for h in labels])
    # down-aisle only (b): the 60 N·m base plates sit at ±My most of the time and their
    # histories differ at the instants they switch (measured 12.8 % of their peak there;
    # connectors 0.92 %)
    base_tol = 0.1 if CASES[case][2] else 0.15
    assert hist[conn].max() < 0.05 and hist[~conn].max() < base_tol, hist
