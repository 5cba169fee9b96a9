"""The design analysis (seisrack.design) against hand calculations and the standard's formulas.

Sources:
- EN 1998-1:2004 §3.2.2.5(4)P, Eqs (3.13)-(3.16): the design spectrum with q and the lower
  bound β·a_g; Tables 3.2/3.3 for S, T_B, T_C, T_D (typed here from the standard);
- EN 1998-1 §4.3.3.3.2: SRSS (Eq 4.16) for independent modes (T_j <= 0.9 T_i), CQC otherwise;
  §4.3.3.5.1: SRSS of the directions or Eqs (4.18)-(4.19); §4.3.4 d_s = q·d_e; §4.4.2.2 θ;
- A. K. Chopra, *Dynamics of Structures*, 4th ed.: the two-storey shear frame with equal masses
  and stiffnesses (Example 10.4: ω² = (k/m)(3 ∓ √5)/2, shapes [1, (1 ± √5)/2]),
  modal response spectrum analysis §13.8, CQC correlation Eq 13.7.10 (Der Kiureghian 1981).
"""

from __future__ import annotations

import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import scipy.sparse as sp

from seisrack.design import (
    DesignFactors,
    der_kiureghian_rho,
    design_analysis,
    design_spectrum,
    parse_factor_overrides,
)
from seisrack.design.combination import choose_rule, combine_directions
from seisrack.design.operators import storey_operators
from seisrack.errors import InputError
from seisrack.motion import G

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
#: E_D1 = E_D2 = E_D3 = 1: the hand cases have no unit loads and no spectrum reduction
NO_UNIT_LOAD = DesignFactors().without_unit_load_factors()


# ---- the design spectrum, Eqs (3.13)-(3.16) ---------------------------------------------

@pytest.mark.parametrize("q", [1.0, 1.5, 4.0])
def test_design_spectrum_formulas(q: float) -> None:
    S, TB, TC, TD = 1.15, 0.20, 0.60, 2.0  # Table 3.2, type 1, ground C
    ag = 0.25 * G * 1.2  # a_gR = 0.25 g, γ_I = 1.2: a_g = γ_I a_gR (§3.2.1(3))
    sp_ = design_spectrum(1, "C", 0.25, q, importance=1.2, beta=0.2)
    T = np.array([0.0, TB / 2, TB, 0.4, TC, 1.0, TD, 3.0, 4.0])
    plateau = ag * S * 2.5 / q
    exp = [
        ag * S * 2 / 3,  # Eq 3.13 at T = 0
        ag * S * (2 / 3 + 0.5 * (2.5 / q - 2 / 3)),  # Eq 3.13 at T_B/2
        plateau,  # Eq 3.14
        plateau,
        plateau,
        max(plateau * TC / 1.0, 0.2 * ag),  # Eq 3.15
        max(plateau * TC / TD, 0.2 * ag),
        max(plateau * TC * TD / 9.0, 0.2 * ag),  # Eq 3.16
        max(plateau * TC * TD / 16.0, 0.2 * ag),
    ]
    np.testing.assert_allclose(sp_.psa(T), exp, rtol=1e-12)


def test_design_spectrum_lower_bound_governs() -> None:
    # q = 4, type 1 ground A: at T = 4 s the branch gives a_g·2.5/4·0.4·2/16 = 0.03125 a_g,
    # below β·a_g = 0.2 a_g, so S_d = 0.2 a_g (Eq 3.16)
    sp_ = design_spectrum(1, "A", 0.2, 4.0)
    assert sp_.psa(4.0)[0] == pytest.approx(0.2 * 0.2 * G, rel=1e-12)
    assert design_spectrum(1, "A", 0.2, 4.0, beta=0.0).psa(4.0)[0] == pytest.approx(
        0.2 * G * 2.5 / 4 * 0.4 * 2.0 / 16.0, rel=1e-12)


@pytest.mark.parametrize("q", [0.9, 0.0, -1.0, math.nan, math.inf, 10.5, 1e300])
def test_q_below_one_is_refused(q: float) -> None:
    with pytest.raises(InputError, match="q >= 1"):  # 1e300 made the design drifts overflow
        design_spectrum(1, "C", 0.3, q)


@pytest.mark.parametrize(("kw", "field"), [
    (dict(ag=1e300), "ag"), (dict(ag=3.01), "ag"), (dict(ag=30.0, ag_units="m/s2"), "ag"),
    (dict(importance=1e300), "importance"), (dict(importance=3.5), "importance")])
def test_absurd_ground_accelerations_are_refused(kw: dict, field: str) -> None:
    """ag = 1e300 g gave inf forces and NaN drifts reported "ok": at most 3 g, gamma_I 3."""
    with pytest.raises(InputError) as exc:
        design_spectrum(**dict(dict(type=1, ground="C", ag=0.3, q=1.5), **kw))
    assert exc.value.field == field
    assert design_spectrum(1, "C", 3.0, 1.5, importance=3.0).psa(0.5) > 0.0  # the bounds run


def test_factor_table_validation() -> None:
    with pytest.raises(InputError, match=r"factors\.e_d1.*\(0, 1\]"):
        DesignFactors(e_d1=1.2)
    with pytest.raises(InputError, match=r"factors\.e_d2_down_aisle"):
        DesignFactors(e_d2_down_aisle=0.0)
    with pytest.raises(InputError, match=r"factors\.damping"):
        DesignFactors(damping=1.5)
    with pytest.raises(InputError, match="theta_ignore <= theta_amplify"):
        DesignFactors(theta_ignore=0.25)
    with pytest.raises(InputError, match="e_d1"):
        DesignFactors().with_(e_d9=0.5)
    f = parse_factor_overrides(["e_d1=0.9", "e_d3 = 0.5"])
    assert (f.e_d1, f.e_d3, f.mass_factor) == (0.9, 0.5, 0.45)
    with pytest.raises(InputError, match="KEY=VALUE"):
        parse_factor_overrides(["e_d1"])
    with pytest.raises(InputError, match="a number"):
        parse_factor_overrides(["e_d1=abc"])
    with pytest.raises(InputError, match=r"\(0, 1\]"):
        parse_factor_overrides(["e_d2_down_aisle=2"])


# ---- modal combination by hand -----------------------------------------------------------

def test_der_kiureghian_rho_by_hand() -> None:
    # Chopra Eq 13.7.10 (equal damping): ρ = 8ζ²(1 + r) r^1.5 / ((1 − r²)² + 4ζ² r (1 + r)²)
    z, r = 0.05, 0.8
    rho = 8 * z**2 * (1 + r) * r**1.5 / ((1 - r**2) ** 2 + 4 * z**2 * r * (1 + r) ** 2)
    got = der_kiureghian_rho(np.array([8.0, 10.0]), 0.05)
    assert got[0, 1] == pytest.approx(rho, rel=1e-12)
    assert got[1, 0] == pytest.approx(rho, rel=1e-12)  # symmetric for equal damping
    np.testing.assert_allclose(np.diag(got), 1.0)


def test_rule_choice_follows_en1998_4_3_3_3_2() -> None:
    assert choose_rule(np.array([1.0, 0.9]), np.array([True, True]))[0] == "srss"
    assert choose_rule(np.array([1.0, 0.91]), np.array([True, True]))[0] == "cqc"
    # a close pair that is not relevant does not force CQC
    assert choose_rule(np.array([1.0, 0.5, 0.49]), np.array([True, True, False]))[0] == "srss"
    rule, why = choose_rule(np.array([1.0, 0.95]), np.array([True, True]), rule="srss")
    assert rule == "srss" and "as asked" in why


def test_direction_combination_rules() -> None:
    ex, ez = np.array([10.0, 1.0]), np.array([2.0, 3.0])
    np.testing.assert_allclose(combine_directions([ex, ez], "srss"), np.sqrt(ex**2 + ez**2))
    # Eqs (4.18)-(4.19): max(E_x + 0.3 E_z, 0.3 E_x + E_z)
    np.testing.assert_allclose(combine_directions([ex, ez], "0.30"), [10.6, 3.3])
    with pytest.raises(InputError):
        combine_directions([ex, ez], "abs")


def _shear_frame(m: float, k: float, h: float = 3.0) -> SimpleNamespace:
    """Two storeys, equal masses m [kg] and storey stiffnesses k [N/m] (Chopra Ex. 10.4):
    DOFs 0 (floor 1) and 1 (floor 2), nodes 0, 1 and a base node 2."""
    K = sp.csr_matrix(np.array([[2 * k, -k], [-k, k]]))
    M = sp.csr_matrix(np.diag([m, m]))
    mesh = SimpleNamespace(nodes=np.array([[0.0, h], [0.0, 2 * h], [0.0, 0.0]]),
                           node_dofs=np.array([[0, -1, -1], [1, -1, -1], [-1, -1, -1]]))
    return SimpleNamespace(
        n_dof=2, K_sparse=K, M_sparse=M, total_mass_sparse=lambda: M, r_x=np.ones(2),
        r_y=np.zeros(2), level_y=np.array([h, 2 * h]),
        level_dofs=((np.array([0]), np.array([1])),), influence=(np.ones(2),),
        directions=("down-aisle",), ndm=2, mesh=mesh, base_nodes=np.array([2]),
        damping_coefficients=(0.0, 0.0), g=9.81)


def test_two_mode_shear_frame_by_hand() -> None:
    m, k, zeta = 10_000.0, 4.0e6, 0.05
    frame = _shear_frame(m, k)
    spec = design_spectrum(1, "C", 0.3, 1.5)
    # Chopra Ex. 10.4: ω² = (k/m)(3 ∓ √5)/2, φ = [1, (1 ± √5)/2]
    s5 = math.sqrt(5.0)
    w = np.sqrt(k / m * np.array([(3 - s5) / 2, (3 + s5) / 2]))
    T = 2 * math.pi / w
    phi = np.array([[1.0, (1 + s5) / 2], [1.0, (1 - s5) / 2]])  # rows: modes
    Mn = m * np.sum(phi**2, axis=1)  # φᵀMφ
    L = m * np.sum(phi, axis=1)  # φᵀM1
    gamma = L / Mn  # for shapes with φ_1 = 1
    Sa = spec.psa(T)
    D = Sa / w**2  # spectral displacement
    # storey shears of each mode: V_1 = k u_1, V_2 = k (u_2 - u_1), u = Γ φ D
    u = gamma[:, None] * phi * D[:, None]  # (mode, floor)
    V1 = k * u[:, 0]
    V2 = k * (u[:, 1] - u[:, 0])
    # base shear of a mode is also M*_k S_a,k with M*_k = L²/Mn (Chopra Eq 13.2.13)
    np.testing.assert_allclose(V1, L**2 / Mn * Sa, rtol=1e-12)
    # EN 1998-1: T_2/T_1 = 0.382 <= 0.9, so SRSS
    srss_V1 = math.sqrt(V1[0] ** 2 + V1[1] ** 2)
    srss_top = math.sqrt(u[0, 1] ** 2 + u[1, 1] ** 2)
    res = design_analysis(frame, spec, operators=storey_operators(frame, "down-aisle"),
                          factors=NO_UNIT_LOAD.with_(damping=zeta))
    assert res.modal_rule["down-aisle"] == "srss"
    np.testing.assert_allclose(res.periods, T, rtol=1e-10)
    assert res.base_shear() == pytest.approx(srss_V1, rel=1e-10)
    q = res.quantities
    assert q["storey_shear_x"].seismic[1] == pytest.approx(math.hypot(*V2), rel=1e-10)
    assert q["level_displacement_x"].seismic[1] == pytest.approx(srss_top, rel=1e-10)
    # CQC written out: E² = E_1² + E_2² + 2 ρ_12 E_1 E_2, ρ from Chopra Eq 13.7.10
    r = w[0] / w[1]
    rho = 8 * zeta**2 * (1 + r) * r**1.5 / ((1 - r**2) ** 2 + 4 * zeta**2 * r * (1 + r) ** 2)
    cqc_V1 = math.sqrt(V1[0] ** 2 + V1[1] ** 2 + 2 * rho * V1[0] * V1[1])
    cqc_top = math.sqrt(u[0, 1] ** 2 + u[1, 1] ** 2 + 2 * rho * u[0, 1] * u[1, 1])
    res_c = design_analysis(frame, spec, operators=storey_operators(frame, "down-aisle"),
                            factors=NO_UNIT_LOAD.with_(damping=zeta), modal_rule="cqc")
    assert res_c.base_shear() == pytest.approx(cqc_V1, rel=1e-10)
    assert res_c.quantities["level_displacement_x"].seismic[1] == pytest.approx(cqc_top,
                                                                                 rel=1e-10)
    assert rho > 0 and cqc_V1 != pytest.approx(srss_V1, rel=1e-6)
    # §4.3.4: d_s = q·d_e for the drifts of the θ check
    st = res.storeys["down-aisle"]
    np.testing.assert_allclose(st.drift_s, 1.5 * st.drift_e)
    assert st.drift_e[0] == pytest.approx(math.hypot(*u[:, 0]), rel=1e-10)


def test_close_modes_switch_to_cqc() -> None:
    """Two uncoupled oscillators with T_2/T_1 = 0.95 > 0.9: the rule is CQC (§4.3.3.3.2(3))."""
    m = 1000.0
    k1 = m * (2 * math.pi / 0.5) ** 2
    k2 = m * (2 * math.pi / 0.475) ** 2
    K = sp.csr_matrix(np.diag([k1, k2]))
    M = sp.csr_matrix(np.diag([m, m]))
    mesh = SimpleNamespace(nodes=np.array([[0.0, 1.0], [1.0, 1.0], [0.0, 0.0]]),
                           node_dofs=np.array([[0, -1, -1], [1, -1, -1], [-1, -1, -1]]))
    model = SimpleNamespace(n_dof=2, K_sparse=K, M_sparse=M, total_mass_sparse=lambda: M,
                            r_x=np.ones(2), r_y=np.zeros(2), level_y=np.array([1.0]),
                            level_dofs=((np.array([0, 1]),),), influence=(np.ones(2),),
                            directions=("down-aisle",), ndm=2, mesh=mesh,
                            base_nodes=np.array([2]), damping_coefficients=(0.0, 0.0), g=9.81)
    spec = design_spectrum(1, "C", 0.3, 2.0)
    res = design_analysis(model, spec, operators=storey_operators(model, "down-aisle"),
                          factors=NO_UNIT_LOAD)
    assert res.modal_rule["down-aisle"] == "cqc"
    assert "0.950" in res.modal_rule_reason["down-aisle"]
    V = m * spec.psa(np.array([0.5, 0.475]))  # each oscillator: base shear m S_a
    rho = der_kiureghian_rho(2 * math.pi / np.array([0.5, 0.475]), 0.05)[0, 1]
    assert res.base_shear() == pytest.approx(math.sqrt(V @ V + 2 * rho * V[0] * V[1]),
                                             rel=1e-10)


# ---- a real rack --------------------------------------------------------------------------

@pytest.fixture(scope="module")
def paper_model():  # noqa: ANN201
    from seisrack.model import compile_rack, load_rack

    return compile_rack(load_rack(EXAMPLES / "paper_rack.toml"))


def test_base_shear_operator_equals_support_reactions(paper_model) -> None:  # noqa: ANN001
    """V = rᵀ K u (the storey operator) equals −Σ F_x of the support reactions
    (seisrack.fe.recovery) for any displacement field (equilibrium of the free body)."""
    from seisrack.fe.recovery import recovery_operators

    u = np.random.default_rng(1).standard_normal((3, paper_model.n_dof))
    ops = {o.name: o for o in storey_operators(paper_model, "down-aisle")}
    np.testing.assert_allclose(u @ ops["base_shear_x"].op.toarray(),
                               u @ recovery_operators(paper_model).base_shear.toarray(),
                               rtol=1e-9, atol=1e-9 * np.abs(u).max() * 1e6)


def test_paper_rack_single_mode_by_hand(paper_model) -> None:  # noqa: ANN001
    """One dominant mode: V ≈ M*_1 S_d(T_1), θ = P d_s/(V h), unit-load mass E_D1·E_D3."""
    from seisrack.fe.modal import modal_analysis

    f = NO_UNIT_LOAD
    spec = design_spectrum(1, "C", 0.3, 2.0)
    res = design_analysis(paper_model, spec, factors=f)
    modal = modal_analysis(paper_model, 6)
    assert res.periods[0] == pytest.approx(modal.periods[0], rel=1e-10)
    v1 = modal.effective_mass_x[0] * spec.psa(modal.periods[0])[0]
    # the higher modes add < 1 % (99.6 % of the mass in mode 1)
    assert res.base_shear() == pytest.approx(v1, rel=0.01)
    st = res.storeys["down-aisle"].as_dict()["storeys"][0]
    assert st["theta"] == pytest.approx(st["P_tot_N"] * st["drift_s_m"]
                                        / (st["V_tot_N"] * st["height_m"]), rel=1e-12)
    # E_D1 = 0.5 halves the pallets' horizontal mass: T_1 shorter, the same structure
    half = design_analysis(paper_model, spec, factors=f.with_(e_d1=0.5))
    m_pal = float(paper_model.pallet_mass.sum())
    assert half.total_mass["down-aisle"] == pytest.approx(
        res.total_mass["down-aisle"] - 0.5 * m_pal, rel=1e-12)
    assert half.periods[0] < res.periods[0]
    # E_D2 scales every spectral ordinate: forces scale by it exactly
    red = design_analysis(paper_model, spec, factors=f.with_(e_d2_down_aisle=0.7))
    assert red.base_shear() == pytest.approx(0.7 * res.base_shear(), rel=1e-12)
    cm, cm_red = res.quantities["connector_moment"], red.quantities["connector_moment"]
    np.testing.assert_allclose(cm_red.seismic, 0.7 * cm.seismic, rtol=1e-12)
    np.testing.assert_allclose(cm_red.gravity, cm.gravity, rtol=1e-12)
    np.testing.assert_allclose(cm.design, np.abs(cm.gravity) + cm.seismic)


def test_design_analysis_bad_input(paper_model) -> None:  # noqa: ANN001
    spec = design_spectrum(1, "C", 0.3, 2.0)
    with pytest.raises(InputError, match="2D rack has no cross-aisle"):
        design_analysis(paper_model, spec, directions="cross-aisle")
    with pytest.raises(InputError, match="n_modes"):
        design_analysis(paper_model, spec, n_modes=0)
    with pytest.raises(InputError, match="combination"):
        design_analysis(paper_model, spec, modal_rule="abs")
    with pytest.raises(InputError, match="damping"):
        design_analysis(paper_model, spec, damping=2.0)


def test_model_damping_is_the_modal_damping_of_c(paper_model) -> None:  # noqa: ANN001
    """damping="model": ζ_k = φ_kᵀ C φ_k / (2 ω_k); for the paper rack's stiffness-proportional
    C = a1 K (a0 = 0) that is a1 ω_k / 2 exactly (Chopra Eq 11.4.9)."""
    res = design_analysis(paper_model, design_spectrum(1, "C", 0.3, 1.0), damping="model",
                          factors=NO_UNIT_LOAD)
    a0, a1 = paper_model.damping_coefficients
    assert a0 == 0.0
    np.testing.assert_allclose(res.damping, a1 * res.omega / 2, rtol=1e-9)
