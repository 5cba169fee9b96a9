"""Nonlinear connections and P-Δ on a 3D rack against OpenSees (issue 21: the last item of
"every command on a 3D rack"): the 3D paper rack shaken into yielding (in both horizontal
directions, or down-aisle only), seisrack vs OpenSeesPy.

Reference: OpenSeesPy (3.7.1 when written) running the script of ``seisrack export opensees``
for the same compiled 3D rack with ``hysteresis=spec.hysteresis``: 6 DOF per node,
``elasticBeamColumn`` members (seisrack's element: periods equal within 1e-8,
``tests/test_export_opensees_3d.py``), ``Truss`` bracing, every connection a ``zeroLength``
rotational spring about its axis (rz for a connector and a base plate in down-aisle bending,
rx for a base plate in cross-aisle bending) with the law's OpenSees material (``ElasticPP``,
``Pinching4`` without damage), ``geomTransf PDelta`` (``GEOM_TRANSF = "PDelta"``; in case
(d) ``Linear`` plus seisrack's constant-N chord terms, :func:`constant_axial_p_delta`) against
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
residual drift is −5.7 % off. (c) the pinched law without damage on the connectors
(asymmetric, as in ``tests/test_opensees_hinges.py``) and a hardening pinched envelope on the
base plates (yield at 0.3 mrad, 48 N·m, then 0.7, 1.8, 2.6 kN·m at 5, 15, 40 mrad), so that
the base plates yield about both axes while the rack keeps its down-aisle base stiffness:
with P-Δ, both directions. (d) the laws of (a) WITH P-Δ, both directions, a1 K_E, against
OpenSees with seisrack's constant gravity axial forces (below). (e) the laws of (a) WITH P-Δ of
the CURRENT axial forces (``[second_order] axial = "current"``), both directions, against
OpenSees' ``geomTransf PDelta`` (end of the module): peaks, residual drift and every hinge's
peak moment within 2 % (measured: residual +0.97 %, peaks -0.02 %).

P-Δ with both directions: current against constant axial forces. seisrack's P-Δ is the
linear geometric stiffness K_G of the gravity axial forces, held constant (chord form, the
beams' and the bracing bars' forces included: ``seisrack.fe.geometric``); OpenSees'
``geomTransf PDelta`` takes each member's CURRENT axial force, and the cross-aisle shaking
overturns the frames: the base uprights' axial force swings from its gravity value (−2.03 and
−4.26 kN) to between −14.75 kN and +8.79 kN (tension; up to 3.06 times the gravity force
away from it). Measured, the EPP + P-Δ rack both ways, a1 K_E (scratch runs of this module's
setup, OpenSeesPy 3.7.1):

- OpenSees with the exported ``PDelta`` (current N): residual down-aisle drift 2.515 mm
  (seisrack 3.084 mm: +22.6 %), the front upright line 3.419 mm and the rear 1.610 mm
  (seisrack 3.164 and 3.004 mm), peak 100.39 mm (seisrack 100.00), connector peaks within
  3.7 %, their histories 5.4 % of their peak apart; down-aisle only it is 3.081 mm
  (measured when this case was first tried: +15.6 % with a1 (K_E + K_G) on both sides, +26 %
  with no damping, −11.4 mm against −15.5 mm, so not the damping). The front and rear frames
  are tied down-aisle only through the pallets' masses, and with the overturning forces they
  yield differently.
- OpenSees with ``Linear`` transformations and seisrack's constant gravity forces
  (:func:`constant_axial_p_delta`, case (d); its first ten periods after gravity equal
  seisrack's ``modal`` of the P-Δ rack within 1.8e-12, 1.1e-6 without the bars' term, 3.5e-4
  without the beams' (N = −106 N)): residual drift 3.079 mm (+0.16 %), front 3.104 and rear
  3.054 mm (+1.9 %, −1.6 %; not separated further, the rigid pallets below are the
  difference left in the model), peaks −0.013 % down-aisle and +0.14 %
  cross-aisle, connector peak moments within 0.16 %, base plates' within 0.13 %.

So the 22.6 % is the P-Δ model (constant against current axial forces), not the integration,
the pallets or the damping: with the same constant forces the two programs agree. seisrack now
has the current forces too (``axial = "current"``, case (e)).

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
from seisrack.fe import geometric
from seisrack.fe.assembly import assemble_sparse
from seisrack.fe.modal import modal_analysis
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
    "elastic-plastic-p-delta-constant-axial": (_EPP, True, True),
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
#: cases whose OpenSees model takes seisrack's constant gravity axial forces for its P-Δ
#: (``Linear`` transformations plus :func:`constant_axial_p_delta`), not the current ones
CONSTANT_AXIAL = frozenset({"elastic-plastic-p-delta-constant-axial"})


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


def constant_axial_p_delta(ns: dict, model) -> None:
    """Add seisrack's P-Δ stiffness to the OpenSees rack that ``ns["build"]()`` just built:
    for every member and bar of the exported tables (``MEMBERS``, ``TRUSSES``, in
    ``model.mesh`` order), a ``zeroLength`` from its node i to its node j, oriented along it,
    with an ``Elastic`` material of stiffness N/L in its two transverse directions, N the
    gravity axial force of seisrack's K_G (``static_axial_forces`` of -g M r_y, tension
    positive): the chord term N/L (I - n nᵀ) of ``form = "p_delta_only"`` (a bar's string
    stiffness), held constant. This is the leaning column's stiffness: a pinned column of
    constant N tied to the frame's nodes adds exactly N/L on their relative transverse
    translations (measured: leaning columns on the uprights, ``PDelta`` elements of tiny I
    tied in x and z, loaded to seisrack's N, give the first ten periods of these zeroLengths on
    the uprights within 3.4e-12); the zeroLength adds it without the auxiliary nodes, also for
    the horizontal beams and the inclined bars. OpenSees warns that these zeroLengths are not
    of zero length; it uses only their orientation (no lever arm), as the chord term. Not
    damped (zeroLength's default), as seisrack's a1 K_E."""
    ops = ns["ops"]
    K_E, _ = assemble_sparse(model.mesh)
    N, N_bar = geometric.static_axial_forces(model.mesh, K_E,
                                             -model.g * (model.M_sparse @ model.r_y))
    ends = [m[:2] for m in ns["MEMBERS"]] + [b[:2] for b in ns["TRUSSES"]]
    assert len(ends) == N.size + N_bar.size
    first = ns["N_STRUCTURE_ELEMENTS"] + 1  # rigid pallets add no element
    mat = ns["_SLIDER_MATERIAL"] + 2
    nodes = np.asarray(ns["NODES"], dtype=float)
    for k, ((i, j), n) in enumerate(zip(ends, np.concatenate([N, N_bar]), strict=True)):
        d = nodes[j - 1] - nodes[i - 1]
        ex = d / np.linalg.norm(d)
        yp = (1.0, 0.0, 0.0) if abs(ex[0]) < 0.9 else (0.0, 1.0, 0.0)
        ops.uniaxialMaterial("Elastic", mat + k, float(n) / float(np.linalg.norm(d)))
        ops.element("zeroLength", first + k, i, j, "-mat", mat + k, mat + k, "-dir", 2, 3,
                    "-orient", *(float(c) for c in ex), *yp)


def opensees_script_ns(model, spec, case: str) -> dict:
    """The exported script's namespace, with the case's P-Δ (current or constant N)."""
    ns: dict = {"__name__": "rack_ops"}
    exec(compile(opensees_script(model, pallets="rigid", hysteresis=spec.hysteresis),
                 "rack_ops.py", "exec"), ns)
    ns["GEOM_TRANSF"] = "PDelta" if spec.second_order.p_delta else "Linear"
    if case in CONSTANT_AXIAL:
        ns["GEOM_TRANSF"] = "Linear"
        build = ns["build"]

        def build_with_constant_p_delta(pallets=None):
            build(pallets)
            constant_axial_p_delta(ns, model)

        ns["build"] = build_with_constant_p_delta  # gravity(), history(), modal() build anew
    return ns


def opensees_history(model, spec, case: str) -> dict[str, np.ndarray]:
    ax, az, dt_rec = components(case)
    ns = opensees_script_ns(model, spec, case)
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
    # elastic-plastic with P-Δ, (b) and (d): the 60 N·m base plates sit at ±My most of the
    # time and their histories differ at the instants they switch (measured 12.8 % of their
    # peak in (b), 11.0 % in (d); connectors 0.92 % and 0.51 %)
    laws, p_delta, _cross = CASES[case]
    base_tol = 0.15 if laws is _EPP and p_delta else 0.1
    assert hist[conn].max() < 0.05 and hist[~conn].max() < base_tol, hist


def test_constant_axial_emulation_has_seisrack_periods() -> None:
    """The OpenSees model of the constant-N case (elastic connections: the tangent stiffness
    after gravity is then the initial one) has the periods of seisrack's P-Δ rack."""
    pytest.importorskip("openseespy.opensees")
    case = "elastic-plastic-p-delta-constant-axial"
    spec = replace(rack_spec(case), hysteresis=Hysteresis())
    model = compile_rack(spec)
    T_ops = np.array(opensees_script_ns(model, spec, case)["modal"](10, "rigid",
                                                                   gravity_first=True))
    T = modal_analysis(model, 10).periods
    assert np.abs(T / T_ops - 1).max() < 1e-9  # measured 1.8e-12


# --- (e) P-Δ with the current axial forces ---------------------------------------------------
#: the laws of (a) with ``[second_order] axial = "current"``, both directions, against OpenSees'
#: ``geomTransf PDelta`` (the members' chord term with their current axial force). OpenSees'
#: ``Truss`` bars have no geometric stiffness, so the bars' part of seisrack's current-force
#: term is left out here (its constant gravity part stays: 1.1e-6 on the periods); the bars'
#: part is checked against the full-DOF integrator of ``tests/test_p_delta_current_axial.py``.
#: (``corotTruss`` bars are no like-for-like peer: without any P-Δ, Linear transformations,
#: they move the cross-aisle displacement history 37 % of its peak away from ``Truss`` bars in
#: 10 s of this record, OpenSeesPy 3.7.1, a difference of that element's dynamics, not of P-Δ.)


def _split_rigid_pallets(model):
    """The rigid pallets as OpenSees' exported script has them: each pallet's mass split on
    its supports (one never-sliding slider per support), not a mass on their mean as a
    seisrack pallet is. That difference is small while the front and rear frames move
    together (case (d): residual drift +0.16 %); with the current axial forces they yield
    differently and it is not: with seisrack's own pallets the residual drift of this case is
    2.339 mm against OpenSees' 2.515 mm (-7 %), with the split masses 2.539 mm (+0.97 %)."""
    from seisrack.dynamics.sliders import PlanarSliders

    pd = model.pallet_dofs  # (m, k, 2)
    k = pd.shape[1]
    return PlanarSliders(pd[:, :, 0].reshape(-1, 1), pd[:, :, 1].reshape(-1, 1),
                         np.repeat(model.pallet_mass / k, k), 1e6, 1e6)


@pytest.fixture(scope="module")
def current_pair():
    """(level displacements x and z, hinge moments, energy error) of seisrack and (level
    displacements, spring forces) of OpenSees for (e)."""
    pytest.importorskip("openseespy.opensees")
    from seisrack.analysis.hinges import rack_hinges
    from seisrack.dynamics import simulate
    from seisrack.dynamics.axial import AxialPDelta

    base = rack_spec("elastic-plastic-p-delta-constant-axial")
    spec = replace(base, second_order=replace(base.second_order, axial="current"))
    model = compile_rack(spec)
    a = model.axial_p_delta
    members = a.owner < model.mesh.n_el  # OpenSees' Truss bars: no geometric stiffness
    hinges = replace(rack_hinges(model), axial=AxialPDelta(
        a.axial, a.rows[np.flatnonzero(members)], a.owner[members], a.scale[members],
        a.offset[members]))
    ax, az, dt_rec = components("elastic-plastic-p-delta-constant-axial")
    k = int(round(dt_rec / DT))

    def resample(a: np.ndarray) -> np.ndarray:
        a = np.concatenate([a, np.zeros(int(round(FREE_VIBRATION / dt_rec)))])
        return np.interp(np.arange((a.size - 1) * k + 1) / k, np.arange(a.size), a)

    ag = np.column_stack([resample(ax), resample(az)])
    hist = simulate(model.M_sparse, model.C_sparse, model.K_sparse, _split_rigid_pallets(model),
                    dt=DT, ground_accel=ag, influence=np.column_stack(model.influence),
                    g=model.g, hinges=hinges)
    disp = [(hist.q @ hist.phi[np.asarray(model.level_dofs[d][0])].T).mean(axis=1)
            for d in range(2)]
    ns: dict = {"__name__": "rack_ops"}
    exec(compile(opensees_script(model, pallets="rigid", hysteresis=spec.hysteresis),
                 "rack_ops.py", "exec"), ns)
    ns["GEOM_TRANSF"] = "PDelta"
    out = ns["history"](ag[:, 0], DT, agz=ag[:, 1])
    ops = {key: np.asarray(v, dtype=float) for key, v in out.items()}
    return (disp, hist.hinge_moment, hist.energy_error(),
            [ops["level_displacement"][:, 0], ops["level_displacement_z"][:, 0]],
            ops["spring_force"])


@pytest.mark.slow
def test_current_axial_peaks_and_residual_drift_within_2_percent(current_pair) -> None:
    s, _m, energy_error, o, _mo = current_pair
    assert energy_error < 1e-9
    for d in range(2):
        ps, po = np.abs(s[d]).max(), np.abs(o[d]).max()
        assert abs(ps / po - 1) < TOL, (d, ps, po)
    rs, ro = _settled(s[0]), _settled(o[0])
    # measured (OpenSeesPy 3.7.1): 2.539 mm against 2.515 mm (+0.97 %; with the gravity
    # axial forces held, case (d), both programs give 3.08 mm), peak 100.37 against 100.39 mm
    assert abs(ro) > 2e-4
    assert abs(rs / ro - 1) < TOL, (rs, ro)


@pytest.mark.slow
def test_current_axial_peak_hinge_moments_within_2_percent(current_pair) -> None:
    _s, ms, _e, _o, mo = current_pair
    assert ms.shape == mo.shape
    on = np.abs(mo).max(axis=0) > 1e-3 * np.abs(mo).max()
    err = np.abs(np.abs(ms[:, on]).max(axis=0) / np.abs(mo[:, on]).max(axis=0) - 1)
    assert err.max() < TOL, err
