"""Hinge moment–rotation laws (``seisrack.dynamics._hysteresis``) against OpenSees' own uniaxial
materials, closed forms and finite differences.

Oracles:

- ``Elastic``, ``ElasticPP`` and ``Steel01`` (Filippou's bilinear kinematic-hardening steel with
  a1 = a3 = 0: no isotropic hardening) of OpenSees, driven through ``testUniaxialMaterial`` /
  ``setStrain`` (which commits every sample);
- ``Pinching4`` (Lowes, Mitra & Altoontash 2003, "A beam-column joint model for simulating the
  earthquake response of reinforced concrete frames", PEER 2003/10; Lowes & Altoontash 2003,
  J. Struct. Eng. 129(12), 1686-1697; OpenSees documentation of ``uniaxialMaterial Pinching4``)
  with every damage index 0 (gK*, gD*, gF* = 0, gE = 10, dmgType "energy");
- the dissipated energy of a full elastic–perfectly plastic cycle, 4·My·(θmax − My/k);
- central finite differences of the moment for the tangent.

Tolerances: EPP / bilinear 1e-9 of My (measured: 0 against Steel01, 1.6e-15 against ElasticPP,
which computes the same moment through a plastic strain); pinching 1e-9 of the largest envelope
moment (measured: 0, bit-identical, because the envelope and the unload–reload paths are
evaluated with the same operations in the same order as OpenSees, including the negative
envelope's segments written from their outer end). 1e-9 rather than bit-identity because the
pinching path construction decides on exact comparisons (e.g. the end of an unloading line
landing on θ = 0), where a one-ulp difference in a committed moment picks another path.

One deliberate difference, tested as such: an unload–reload segment of exactly zero slope
(rForce = uForce = 0 on the positive side, or rForce = 1) is flat here, while OpenSees replaces
it by a neighbouring segment extrapolated, a jump of several times the strength (measured 2.2e4
N·m on a 2.3e3 N·m envelope).
"""

from __future__ import annotations

import numpy as np
import pytest

from seisrack.dynamics import _hysteresis as H
from seisrack.export.opensees_materials import opensees_uniaxial
from seisrack.model.hinge_law import LAW_CODES, HingeLaw

K_ROT = 2.0e5  # N·m/rad
MY = 4.0e3  # N·m  (θy = 0.02 rad)


# ---------------------------------------------------------------------------- histories

def _ramp(targets, n=25, start=0.0):
    out = [start]
    for a in targets:
        out.extend(np.linspace(out[-1], a, n)[1:])
    return np.array(out)


def _histories():
    """Rotation histories [rad]: growing cycles, partial unload/reload inside loops, small
    reversals, asymmetric amplitudes, returns to zero, and a random walk."""
    rng = np.random.default_rng(20031201)
    growing = _ramp([s * a for a in (0.005, 0.01, 0.02, 0.04, 0.06, 0.09, 0.12, 0.16)
                     for s in (1, -1)] + [0.0])
    partial = _ramp([0.05, 0.02, 0.045, -0.03, -0.01, -0.05, 0.0, 0.07, 0.06, 0.075, -0.08,
                     -0.02, -0.09, 0.03, 0.1, -0.01])
    small = _ramp([0.03, 0.0298, 0.0302, 0.0297, -0.004, -0.0042, -0.0039, 0.05, 0.0499,
                   -0.06, -0.0599, 0.0], n=7)
    asym = _ramp([0.08, -0.01, 0.12, -0.02, 0.15, -0.03, 0.0, -0.1, 0.02, 0.11])
    walk = np.cumsum(rng.normal(0.0, 0.004, 1500))
    steps = _ramp([0.01, -0.01, 0.07, -0.07], n=3)  # large steps crossing several branches
    return {"growing": growing, "partial": partial, "small": small, "asym": asym,
            "walk": walk, "steps": steps}


HIST = _histories()


# ---------------------------------------------------------------------------- laws

def _pinching(**kw):
    base = dict(
        kind="pinching", stiffness=1.0e5,
        envelope_rotation=(0.01, 0.03, 0.06, 0.10),
        envelope_moment=(1.0e3, 1.8e3, 2.2e3, 2.3e3),
        reload_rotation_ratio=0.3, reload_moment_ratio=0.2, unload_moment_ratio=0.05,
    )
    base.update(kw)
    return HingeLaw(**base)


LAWS = {
    "elastic": HingeLaw("elastic", K_ROT),
    "epp": HingeLaw("elastic-plastic", K_ROT, yield_moment=MY),
    "bilinear-2%": HingeLaw("bilinear", K_ROT, yield_moment=MY, hardening_ratio=0.02),
    "bilinear-30%": HingeLaw("bilinear", K_ROT, yield_moment=MY, hardening_ratio=0.3),
    "pinching": _pinching(),
    # asymmetric envelope and pinching (initial slopes equal within 0.1 %)
    "pinching-asym": _pinching(
        negative_envelope_rotation=(0.012, 0.035, 0.07, 0.12),
        negative_envelope_moment=(1.2e3, 1.9e3, 2.1e3, 1.9e3),  # softening last segment
        negative_reload_rotation_ratio=0.45, negative_reload_moment_ratio=0.1,
        negative_unload_moment_ratio=0.0),
    # unload moment ratio above the reload one, reload at the peak rotation
    "pinching-uforce": _pinching(reload_rotation_ratio=1.0, reload_moment_ratio=0.1,
                                 unload_moment_ratio=0.4),
    # a slack connector: reloading at zero moment up to 80 % of the peak rotation (flat
    # plateau: compared with OpenSees in test_flat_pinched_plateau_differs_from_opensees)
    "pinching-slack": _pinching(reload_rotation_ratio=0.8, reload_moment_ratio=0.0,
                                unload_moment_ratio=0.0),
    # the same with a small positive reload moment (no exactly flat segment)
    "pinching-slack-01": _pinching(reload_rotation_ratio=0.8, reload_moment_ratio=0.01,
                                   unload_moment_ratio=0.0),
    # no pinching: rDisp = rForce = uForce = 1 is a (nearly) bilinear-like unload/reload
    "pinching-none": _pinching(reload_rotation_ratio=1.0, reload_moment_ratio=1.0,
                               unload_moment_ratio=1.0),
}
SCALE = {name: (max(max(law.envelope_moment), max(law.negative_envelope_moment or (0,)))
                if law.kind == "pinching" else MY) for name, law in LAWS.items()}


def _drive_py(law, thetas):
    code, par = law.pack()
    st_c = np.empty(H.HYST_NSTATE)
    st_t = np.empty(H.HYST_NSTATE)
    H._hyst_init(code, par, st_c)
    m = np.empty_like(thetas)
    k = np.empty_like(thetas)
    for i, th in enumerate(thetas):
        m[i], k[i] = H._hyst_trial(code, par, st_c, th, st_t)
        st_c[:] = st_t
    return m, k


@pytest.fixture(scope="module")
def numba_build():
    from seisrack.dynamics import _kernel_numba as K

    return K


@pytest.fixture(scope="module")
def ops():
    return pytest.importorskip("openseespy.opensees")


def _drive_ops(ops, law, thetas):
    ops.wipe()
    ops.model("basic", "-ndm", 1, "-ndf", 1)
    ops.uniaxialMaterial(*opensees_uniaxial(law, 1))
    ops.testUniaxialMaterial(1)
    m = np.empty_like(thetas)
    k = np.empty_like(thetas)
    for i, th in enumerate(thetas):
        ops.setStrain(float(th))
        m[i] = ops.getStress()
        k[i] = ops.getTangent()
    ops.wipe()
    return m, k


# ---------------------------------------------------------------------------- OpenSees parity

@pytest.mark.parametrize("hist", sorted(HIST))
@pytest.mark.parametrize("name", sorted(LAWS))
def test_moments_match_opensees(ops, name, hist):
    if name == "pinching-slack":
        pytest.skip("flat plateau: see test_flat_pinched_plateau_differs_from_opensees")
    law = LAWS[name]
    th = HIST[hist]
    m_ref, k_ref = _drive_ops(ops, law, th)
    m, k = _drive_py(law, th)
    tol = 1e-9 * SCALE[name]
    assert np.max(np.abs(m - m_ref)) <= tol
    # tangents identical, except exactly at a yield point (the moment on a bounding line at
    # the end of an elastic branch), where ElasticPP takes the plastic one-sided slope and
    # Steel01 (and seisrack) the elastic one
    differ = np.abs(k - k_ref) > 1e-9 * law.stiffness
    if law.kind in ("elastic-plastic", "bilinear"):
        b = law.hardening_ratio
        on_line = np.minimum(np.abs(m - (b * K_ROT * th + (1 - b) * MY)),
                             np.abs(m - (b * K_ROT * th - (1 - b) * MY))) <= 1e-9 * MY
        differ &= ~on_line
    assert not differ.any()


def test_epp_equals_steel01_with_zero_hardening(ops):
    law = LAWS["epp"]
    th = HIST["partial"]
    m_pp, _ = _drive_ops(ops, law, th)
    ops.wipe()
    ops.model("basic", "-ndm", 1, "-ndf", 1)
    ops.uniaxialMaterial("Steel01", 1, MY, K_ROT, 0.0)
    ops.testUniaxialMaterial(1)
    m_s1 = []
    for x in th:
        ops.setStrain(float(x))
        m_s1.append(ops.getStress())
    m, _ = _drive_py(law, th)
    assert np.max(np.abs(m - np.array(m_s1))) <= 1e-9 * MY
    assert np.max(np.abs(m - m_pp)) <= 1e-9 * MY


def test_pinching_random_parameters_match_opensees(ops):
    """Random envelopes (rising and softening segments, asymmetric), random pinching ratios
    including the bounds 0 and 1, random walks of rotation."""
    rng = np.random.default_rng(4)
    worst = 0.0
    for _ in range(60):
        rot = tuple(np.cumsum(rng.uniform(0.002, 0.03, 4)))
        mom = np.cumsum(np.r_[rng.uniform(5e3, 2e4), rng.uniform(-3e3, 1e4, 3)])
        mom = tuple(np.maximum(mom, 100.0))
        nrot = tuple(np.cumsum(rng.uniform(0.002, 0.03, 4)))
        nrot = (rot[0],) + nrot[1:] if nrot[1] > rot[0] else rot
        nmom = np.cumsum(np.r_[mom[0], rng.uniform(-3e3, 1e4, 3)])
        nmom = tuple(np.maximum(nmom, 100.0))
        ratios = [float(rng.choice([0.0, 1.0, rng.uniform()])) for _ in range(6)]
        # rForce in (0, 1): rForce = 1, or rForce = uForce = 0, make an exactly flat path
        # segment, the known difference (test_flat_pinched_plateau_differs_from_opensees)
        ratios[1] = float(rng.uniform(0.01, 0.99))
        ratios[4] = float(rng.uniform(0.01, 0.99))
        law = HingeLaw(
            "pinching", mom[0] / rot[0], envelope_rotation=rot, envelope_moment=mom,
            negative_envelope_rotation=nrot, negative_envelope_moment=nmom,
            reload_rotation_ratio=ratios[0], reload_moment_ratio=ratios[1],
            unload_moment_ratio=ratios[2], negative_reload_rotation_ratio=ratios[3],
            negative_reload_moment_ratio=ratios[4], negative_unload_moment_ratio=ratios[5])
        th = _ramp(list(np.cumsum(rng.normal(0, 0.02, 20))), n=int(rng.integers(3, 25)))
        m_ref, _ = _drive_ops(ops, law, th)
        m, _ = _drive_py(law, th)
        worst = max(worst, float(np.max(np.abs(m - m_ref))) / max(mom + nmom))
    assert worst <= 1e-9


# ---------------------------------------------------------------------------- numba twin

@pytest.mark.parametrize("name", sorted(LAWS))
def test_numba_build_equals_python(numba_build, name):
    K = numba_build
    law = LAWS[name]
    code, par = law.pack()
    th = np.concatenate([HIST["growing"], HIST["walk"]])
    m_py, k_py = _drive_py(law, th)
    m_nb = np.empty_like(th)
    k_nb = np.empty_like(th)
    K._hyst_drive(code, par, th, m_nb, k_nb)
    np.testing.assert_array_equal(m_nb, m_py)
    np.testing.assert_array_equal(k_nb, k_py)
    # and step by step through the public trial entry point
    st_c = np.empty(K.HYST_NSTATE)
    st_t = np.empty(K.HYST_NSTATE)
    K._hyst_init(code, par, st_c)
    for i in range(200):
        m, kt = K._hyst_trial(code, par, st_c, th[i], st_t)
        assert m == m_py[i] and kt == k_py[i]
        st_c[:] = st_t


def test_numba_constants(numba_build):
    K = numba_build
    assert (K.HYST_ELASTIC, K.HYST_EPP, K.HYST_BILINEAR, K.HYST_PINCHING) == (0, 1, 2, 3)
    assert (K.HYST_NPAR, K.HYST_NSTATE) == (H.HYST_NPAR, H.HYST_NSTATE)
    assert LAW_CODES == {"elastic": H.HYST_ELASTIC, "elastic-plastic": H.HYST_EPP,
                         "bilinear": H.HYST_BILINEAR, "pinching": H.HYST_PINCHING}


# ---------------------------------------------------------------------------- interface

@pytest.mark.parametrize("name", sorted(LAWS))
def test_trial_is_path_independent_and_leaves_committed_state(name):
    """Newton iterations: any sequence of trials from one committed state gives the same answer
    as a single trial, and the committed row is never written."""
    law = LAWS[name]
    code, par = law.pack()
    th = HIST["partial"]
    st_c = np.empty(H.HYST_NSTATE)
    st_t = np.empty(H.HYST_NSTATE)
    st_x = np.empty(H.HYST_NSTATE)
    H._hyst_init(code, par, st_c)
    rng = np.random.default_rng(1)
    for x in th:
        before = st_c.copy()
        for y in x + rng.normal(0, 0.01, 4):  # wild iterates first
            H._hyst_trial(code, par, st_c, y, st_x)
        m1, k1 = H._hyst_trial(code, par, st_c, x, st_t)
        np.testing.assert_array_equal(st_c, before)
        m2, k2 = H._hyst_trial(code, par, st_c, x, st_x)
        assert (m1, k1) == (m2, k2)
        np.testing.assert_array_equal(st_t, st_x)
        st_c[:] = st_t


@pytest.mark.parametrize("name", sorted(LAWS))
def test_init_and_k0(name):
    law = LAWS[name]
    code, par = law.pack()
    st = np.full(H.HYST_NSTATE, np.nan)
    H._hyst_init(code, par, st)
    assert st[H.HYST_S_THETA] == 0.0 and st[H.HYST_S_M] == 0.0
    assert np.all(np.isfinite(st))
    assert H._hyst_k0(code, par) == pytest.approx(law.stiffness, rel=1e-3)
    st_t = np.empty(H.HYST_NSTATE)
    m, kt = H._hyst_trial(code, par, st, 1e-3 * law.yield_rotation
                          if np.isfinite(law.yield_rotation) else 1e-5, st_t)
    assert kt == pytest.approx(law.stiffness, rel=1e-3)


def test_elastic_law():
    law = LAWS["elastic"]
    th = HIST["walk"]
    m, k = _drive_py(law, th)
    np.testing.assert_array_equal(m, K_ROT * th)
    assert np.all(k == K_ROT)


@pytest.mark.parametrize("name", sorted(LAWS))
def test_tangent_matches_finite_differences(name):
    """Away from kinks the returned tangent is the exact slope dM/dθ of the trial moment
    (from the same committed state) – a kink is recognised by unequal one-sided slopes."""
    law = LAWS[name]
    code, par = law.pack()
    st_c = np.empty(H.HYST_NSTATE)
    st_t = np.empty(H.HYST_NSTATE)
    H._hyst_init(code, par, st_c)
    h = 1e-7
    checked = 0
    for x in HIST["partial"][1:]:
        m, kt = H._hyst_trial(code, par, st_c, x, st_t)
        mp, _ = H._hyst_trial(code, par, st_c, x + h, np.empty(H.HYST_NSTATE))
        mm, _ = H._hyst_trial(code, par, st_c, x - h, np.empty(H.HYST_NSTATE))
        right, left = (mp - m) / h, (m - mm) / h
        if abs(x - st_c[0]) > 10 * h and abs(right - left) <= 1e-6 * law.stiffness:
            assert kt == pytest.approx(0.5 * (right + left), rel=1e-6, abs=1e-6 * law.stiffness)
            checked += 1
        H._hyst_trial(code, par, st_c, x, st_t)
        st_c[:] = st_t
    assert checked > 0.8 * (len(HIST["partial"]) - 1)


@pytest.mark.parametrize("theta_max", [0.03, 0.05, 0.1])
def test_epp_energy_per_cycle(theta_max):
    """Energy dissipated by one full cycle ±θmax of the elastic–perfectly plastic law:
    4·My·(θmax − My/k) (the parallelogram's area), from the law's own work counter."""
    law = LAWS["epp"]
    code, par = law.pack()
    thy = MY / K_ROT
    n = 4000  # samples per half cycle; yield points land on samples up to O(1/n)
    th = _ramp([theta_max, -theta_max, theta_max, -theta_max, theta_max], n=n)
    st_c = np.empty(H.HYST_NSTATE)
    st_t = np.empty(H.HYST_NSTATE)
    H._hyst_init(code, par, st_c)
    work = []
    for x in th:
        H._hyst_trial(code, par, st_c, x, st_t)
        st_c[:] = st_t
        work.append(st_c[H.HYST_S_WORK])
    w = np.array(work)
    ends = [2 * (n - 1) + i * 2 * (n - 1) for i in range(2)]  # θ = +θmax after cycles 1, 2
    per_cycle = w[ends[1]] - w[ends[0]]
    exact = 4.0 * MY * (theta_max - thy)
    assert per_cycle == pytest.approx(exact, rel=1e-5)


def test_bilinear_stays_between_bounding_lines():
    for name in ("bilinear-2%", "bilinear-30%"):
        law = LAWS[name]
        b = law.hardening_ratio
        for th in HIST.values():
            m, k = _drive_py(law, th)
            lim = b * K_ROT * th
            cap = (1 - b) * MY
            assert np.all(m <= lim + cap + 1e-9 * MY) and np.all(m >= lim - cap - 1e-9 * MY)
            assert set(np.unique(k)) <= {K_ROT, b * K_ROT}


def test_pinching_envelope_and_slack():
    """Monotonic loading follows the 4-point envelope; the slack law reloads at (about) zero
    moment until rDisp of the previous peak rotation."""
    law = LAWS["pinching"]
    th = np.linspace(0, 0.1, 1001)
    m, _ = _drive_py(law, th)
    np.testing.assert_allclose(m, np.interp(th, (0,) + law.envelope_rotation,
                                            (0,) + law.envelope_moment), rtol=0, atol=1e-9)
    slack = LAWS["pinching-slack"]
    th = _ramp([0.06, -0.06, 0.03], n=200)
    m, k = _drive_py(slack, th)
    last, mm, kk = th[-199:], m[-199:], k[-199:]
    # reloading from -0.06 rad: elastic unloading to M = 0 at θ = -0.06 + M(-0.06)/k, then a
    # slack plateau at M = uForce·... = 0 up to where the reload line (rForce = 0 at
    # rDisp·0.06, limited to the elastic slope) starts
    m_start = float(np.interp(0.06, (0,) + slack.envelope_rotation,
                              (0,) + slack.envelope_moment))
    th_free = -0.06 + m_start / slack.stiffness
    th_grip = 0.06 - m_start / slack.stiffness
    inside = (last > th_free + 1e-9) & (last < min(0.03, th_grip) - 1e-9)
    assert inside.sum() > 100
    assert np.all(mm[inside] == 0.0) and np.all(kk[inside] == 0.0)
    assert np.all(np.abs(np.diff(m)) < 1.01 * slack.stiffness * np.max(np.abs(np.diff(th))))


def test_flat_pinched_plateau_differs_from_opensees(ops):
    """The one deliberate difference: OpenSees' Pinching4 evaluates an unload–reload segment
    of exactly zero slope (rForceP = uForceP = 0; or rForce = 1, whose reload point has the
    envelope's moment) as the first or last segment extrapolated, so its moment jumps by
    several times the strength; seisrack keeps the plateau flat. Elsewhere (before the plateau
    is reached) both agree."""
    slack = LAWS["pinching-slack"]
    th = _ramp([0.06, -0.06, 0.03], n=200)
    m_ref, _ = _drive_ops(ops, slack, th)
    m, _ = _drive_py(slack, th)
    jump_ref = np.max(np.abs(np.diff(m_ref)))
    assert jump_ref > 2.0 * max(slack.envelope_moment)  # OpenSees' discontinuity
    first = int(np.argmax(np.abs(m - m_ref) > 1e-9 * SCALE["pinching-slack"]))
    assert first > 400 and m[first] == 0.0  # agreement up to the plateau
