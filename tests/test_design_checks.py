"""Design checks (seisrack.checks): hand-computed cases with the arithmetic shown.

No published worked example of the FEM 10.2.08 / EN 16681 sliding check or of an EN 1998-1
§4.4.2.2 θ calculation for a rack was available here, so the cases below are computed by hand
from the rules as published: the sliding condition a_i/g > γ_μS·μ_S (Castiglioni, *Seismic
behaviour of steel storage pallet racking systems*, Politecnico di Milano 2008, quoting prFEM
10.2.08) and θ = P_tot·d_r/(V_tot·h) with the limits 0.1 / 0.2 / 0.3 (EN 1998-1 §4.4.2.2).
Independent checks: storey shears recovered from element end forces equal the applied static
storey forces (equilibrium), and storey gravity loads add up to the rack's masses.
"""

from __future__ import annotations

import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from seisrack.checks import (
    CheckFactors,
    compare_sliding,
    level_accelerations,
    pallet_sliding_check,
    sensitivity_theta,
    theta_verdict,
)
from seisrack.checks.drift import storey_gravity_loads, storey_shear_history
from seisrack.errors import InputError

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _toy(mu_s: float = 0.3, mu_d: float = 0.25) -> tuple[SimpleNamespace, SimpleNamespace]:
    """One level (DOFs 0 and 1), two modes, one pallet on DOF 0."""
    model = SimpleNamespace(level_dofs=((np.array([0, 1]),),), pallet_level=np.array([0]),
                            n_pallets=1, g=9.81, pallet_mu_static=np.array([mu_s]),
                            pallet_mu_dynamic=np.array([mu_d]))
    # mean level shapes: mode 1 (0.3 + 0.3)/2 = 0.3, mode 2 (-0.1 - 0.3)/2 = -0.2
    modal = SimpleNamespace(shapes=np.array([[0.3, -0.1], [0.3, -0.3]]),
                            gamma_x=np.array([2.0, 1.0]), periods=np.array([0.8, 0.2]))
    return model, modal


class _Flat:
    """A design spectrum with S_a = 4 m/s² at 0.8 s and 10 m/s² at 0.2 s."""

    name = "test spectrum"

    def psa(self, periods):  # noqa: ANN001, ANN201
        return np.where(np.asarray(periods) > 0.5, 4.0, 10.0)


def test_level_acceleration_srss_by_hand():
    # contributions Γ φ̄ S_a: 2 * 0.3 * 4 = 2.4 and 1 * (-0.2) * 10 = -2.0
    # SRSS: sqrt(2.4² + 2.0²) = sqrt(5.76 + 4.00) = sqrt(9.76) = 3.12410 m/s²
    model, modal = _toy()
    a = level_accelerations(model, modal, np.array([4.0, 10.0]))
    assert a[0] == pytest.approx(math.sqrt(9.76), rel=1e-12)


def test_sliding_check_uls_and_sls_by_hand():
    # ULS: a/g = 3.12410 / 9.81 = 0.31846 > γ_μ μ_upper = 1.0 * 0.30 -> slides
    # SLS: ν a/g = 0.5 * 0.31846 = 0.15923 <= μ_lower = 0.25 -> does not slide
    model, modal = _toy()
    res = pallet_sliding_check(model, modal, spectrum=_Flat())
    p = res["pallets"][0]
    assert p["id"] == 1 and p["level"] == 1
    assert p["alpha_uls"] == pytest.approx(math.sqrt(9.76) / 9.81, rel=1e-12)
    assert p["slides_uls"] is True
    assert p["alpha_sls"] == pytest.approx(0.5 * math.sqrt(9.76) / 9.81, rel=1e-12)
    assert p["slides_sls"] is False
    assert res["ok"] is False and "FEM 10.2.08" in res["source"]
    # with γ_μ = 1.1: 1.1 * 0.30 = 0.33 > 0.31846 -> no sliding at ULS
    res = pallet_sliding_check(model, modal, spectrum=_Flat(),
                               factors=CheckFactors(gamma_mu=1.1))
    assert res["pallets"][0]["slides_uls"] is False and res["ok"] is True
    # user bounds override the rack file: μ_upper = 0.35 -> no ULS sliding; μ_lower = 0.15 <
    # 0.15923 -> SLS sliding
    res = pallet_sliding_check(model, modal, spectrum=_Flat(),
                               factors=CheckFactors(mu_uls=0.35, mu_sls=0.15))
    p = res["pallets"][0]
    assert (p["slides_uls"], p["slides_sls"]) == (False, True)
    assert (p["mu_uls"], p["mu_sls"]) == (0.35, 0.15)


def test_theta_formula_and_verdicts_by_hand():
    # P = 100 kN, d_r = 30 mm, V = 50 kN, h = 3 m: θ = 100e3 * 0.03 / (50e3 * 3) = 0.02
    assert sensitivity_theta(100e3, 0.03, 50e3, 3.0) == pytest.approx(0.02, rel=1e-14)
    # d_r = 225 mm: θ = 100e3 * 0.225 / 150e3 = 0.15 -> amplify by 1/(1-0.15) = 1.1765
    theta = sensitivity_theta(100e3, 0.225, 50e3, 3.0)
    assert theta == pytest.approx(0.15, rel=1e-14)
    f = CheckFactors()
    text, ok = theta_verdict(theta, f)
    assert ok and "1.176" in text
    assert theta_verdict(0.1, f)[0].startswith("θ ≤ 0.1") and theta_verdict(0.1, f)[1]
    assert "second-order analysis" in theta_verdict(0.25, f)[0] and theta_verdict(0.3, f)[1]
    assert theta_verdict(0.3001, f) == ("θ > 0.3: not allowed", False)
    assert sensitivity_theta(1.0, 1.0, 0.0, 1.0) == 0.0


def test_factors_override_and_bad_values():
    f = CheckFactors().with_(gamma_mu=1.2, theta_max=0.25)
    assert f.gamma_mu == 1.2 and f.as_dict()["theta_max"] == 0.25
    with pytest.raises(InputError, match="gamma_mu"):
        CheckFactors(gamma_mu=-1.0)
    with pytest.raises(InputError, match="nu_sls"):
        CheckFactors(nu_sls=0.0)
    with pytest.raises(InputError, match="theta"):
        CheckFactors(theta_ignore=0.4)
    with pytest.raises(InputError, match="not_a_factor"):
        CheckFactors().with_(not_a_factor=1.0)


def test_compare_flags_unsafe_and_conservative():
    check = {"pallets": [{"slides_uls": False}, {"slides_uls": True}, {"slides_uls": False}]}
    cmp_ = compare_sliding(check, np.array([True, False, False]), "slides_uls")
    assert cmp_["unsafe_ids"] == [1] and cmp_["conservative_ids"] == [2]
    assert cmp_["agree"] is False and "no sliding but pallets 1 slid" in cmp_["disagreement"]
    ok = compare_sliding(check, np.array([False, True, False]), "slides_uls")
    assert ok["agree"] is True and ok["disagreement"] == ""


@pytest.fixture(scope="module")
def three_level():
    from seisrack.model import compile_rack, load_rack

    return compile_rack(load_rack(EXAMPLES / "three_level_rack.toml"))


def test_storey_gravity_loads_add_up(three_level):
    # Top storey: 6 pallets * 800 kg plus the members above level 2; bottom storey: every free
    # mass (r_yᵀ M r_y). Each storey carries at least its pallets: 18, 12, 6 x 800 kg.
    m = three_level
    P = storey_gravity_loads(m) / m.g
    total = float(m.r_y @ (m.M_sparse @ m.r_y))
    assert P[0] == pytest.approx(total, rel=1e-12)
    assert np.all(np.diff(P) < 0)
    pallets = np.array([18, 12, 6]) * 800.0
    members = P - pallets
    assert np.all(members > 0) and members[0] < m.member_mass


def test_storey_shear_equals_applied_storey_forces(three_level):
    # Static lateral forces F = (10, 20, 30) kN at levels 1..3, spread over each level's
    # horizontal DOFs. Equilibrium: storey shear V_s = Σ F above = (60, 50, 30) kN.
    import scipy.sparse.linalg as spla

    m = three_level
    F = np.zeros(m.n_dof)
    for lv, force in enumerate((10e3, 20e3, 30e3)):
        dofs = np.asarray(m.level_dofs[0][lv])
        F[dofs] += force / dofs.size
    u = spla.spsolve(m.K_sparse.tocsc(), F)
    V = np.abs(storey_shear_history(m, u[None, :])[0])
    np.testing.assert_allclose(V, [60e3, 50e3, 30e3], rtol=1e-8)
