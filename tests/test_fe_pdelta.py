"""P-Δ: linear geometric stiffness, buckling load factor and compressed-frame periods.

References:
- Euler load of a cantilever (fixed base, free top) under an axial end load:
  P_cr = π² EI / (4 L²) (Timoshenko & Gere, *Theory of Elastic Stability*, 2nd ed., 1961, §2.1).
- Free vibration of an axially compressed beam, EI w'''' + P w'' + m ẅ = 0, clamped at x = 0
  and free at x = L under a conservative (gravity) end load: w = w'= 0 at 0, EI w'' = 0 and
  EI w''' + P w' = 0 at L. With w = A cosh αx + B sinh αx + C cos βx + D sin βx,
  α², β² = (∓P + √(P² + 4 EI m ω²)) / (2 EI), the frequency equation is the 4 x 4 determinant
  solved below (Timoshenko & Gere §2.1 for the boundary conditions; Bokaian, J. Sound Vib.
  126(1), 1988, for the compressed-beam frequencies). The approximate relation
  ω² ≈ ω0² (1 − P/P_cr) (Galef, J. Acoust. Soc. Am. 44(2), 1968, 643) is checked against it
  within the 0.02 (in ω²/ω0²) it is off by for a cantilever.
- OpenSeesPy with ``geomTransf PDelta``: the same mesh exported by
  :func:`seisrack.export.opensees_script`, gravity applied first (linear static step,
  ``loadConst -time 0``), then ``eigen``. OpenSees' PDelta transformation is the chord term N/L
  only, so seisrack's ``form = "p_delta_only"`` is its like-for-like peer.
"""

from __future__ import annotations

import json
import tomllib
from pathlib import Path

import numpy as np
import pytest
import scipy.optimize

from seisrack.cli import main
from seisrack.errors import InputError
from seisrack.fe import geometric
from seisrack.fe.assembly import assemble_sparse
from seisrack.fe.mesh import line_mesh
from seisrack.fe.modal import modal_analysis, modal_from_matrices
from seisrack.model import compile_rack, rack_from_dict

PAPER_RACK = Path(__file__).resolve().parents[1] / "examples" / "paper_rack.toml"

# Nondimensional cantilever: L = EI = m = 1; EA = 1e4 keeps the axial modes far above bending.
L, EI, RHO_A = 1.0, 1.0, 1.0
P_CR = np.pi**2 * EI / (4 * L**2)


def _column(n_el: int):
    mesh = line_mesh(L, n_el, E=1.0, A=1e4, I=EI, density=RHO_A / 1e4,
                     restraints={0: (True, True, True)}, angle=np.pi / 2)
    K, M = assemble_sparse(mesh)
    return mesh, K, M


def _column_kg(n_el: int, P: float, form: str):
    """Cantilever of n_el elements with a compressive tip load P: (mesh, K_E, M, K_G)."""
    mesh, K, M = _column(n_el)
    F = np.zeros(mesh.n_dof)
    F[mesh.node_dofs[-1, 1]] = -P
    N = geometric.gravity_axial_forces(mesh, K, F)
    np.testing.assert_allclose(N, -P, rtol=1e-10)  # compression negative, uniform
    return mesh, K, M, geometric.geometric_stiffness(mesh, N, form)  # type: ignore[arg-type]


def _buckling_error(n_el: int, form: str) -> float:
    _, K, _, KG = _column_kg(n_el, 1.0, form)
    return geometric.critical_load_factor(K, KG) / P_CR - 1.0


@pytest.mark.parametrize(("form", "order"), [("consistent", 4.0), ("p_delta_only", 2.0)])
def test_cantilever_euler_load_converges(form, order):
    errs = np.array([_buckling_error(n, form) for n in (2, 4, 8)])
    # measured: consistent 5.1e-4, 3.3e-5, 2.1e-6 (order 3.97, 3.99);
    #           p_delta_only 5.2e-2, 1.3e-2, 3.2e-3 (order 2.02, 2.01)
    assert np.all(errs > 0)  # both forms are upper bounds (stiffer than the continuum)
    rates = np.log2(errs[:-1] / errs[1:])
    np.testing.assert_allclose(rates, order, atol=0.1)
    if form == "consistent":
        assert errs[0] < 5e-3  # within 0.5 % already with 2 elements


def _exact_compressed_omega(P: float) -> float:
    """Lowest ω [rad/s] of the clamped-free beam under compression P (module docstring)."""

    def det(w: float) -> float:
        D = np.sqrt(P**2 + 4 * EI * RHO_A * w**2)
        a, b = np.sqrt((D - P) / (2 * EI)), np.sqrt((D + P) / (2 * EI))
        ch, sh, c, s = np.cosh(a * L), np.sinh(a * L), np.cos(b * L), np.sin(b * L)
        rows = [
            [1, 0, 1, 0],                                                      # w(0)
            [0, a, 0, b],                                                      # w'(0)
            [a**2 * ch, a**2 * sh, -b**2 * c, -b**2 * s],                      # w''(L)
            [EI * a**3 * sh + P * a * sh, EI * a**3 * ch + P * a * ch,         # shear(L)
             EI * b**3 * s - P * b * s, -EI * b**3 * c + P * b * c],
        ]
        return float(np.linalg.det(np.array(rows)))

    w0 = 1.8751040687**2 * np.sqrt(EI / (RHO_A * L**4))  # P = 0 root
    return scipy.optimize.brentq(det, 1e-3, 1.2 * w0, xtol=1e-14)


def test_exact_frequency_reduces_to_euler_bernoulli():
    np.testing.assert_allclose(_exact_compressed_omega(0.0), 1.8751040687**2, rtol=1e-9)


@pytest.mark.parametrize("ratio", [0.25, 0.5, 0.9])
def test_compressed_cantilever_frequency(ratio):
    P = ratio * P_CR
    exact = _exact_compressed_omega(P)
    _, K, M, KG = _column_kg(8, P, "consistent")
    omega = modal_from_matrices(K + KG, M, np.zeros(K.shape[0]), np.zeros(K.shape[0]),
                                n_modes=1).omega[0]
    assert abs(omega / exact - 1) < 1e-4  # FE (8 elements) vs the exact frequency equation
    # Galef's linear relation ω²/ω0² ≈ 1 − P/P_cr is exact at both ends (P = 0, P = P_cr);
    # for a cantilever the exact curve lies above it by at most 0.02 (measured: 0.014, 0.020,
    # 0.008 at P/P_cr = 0.25, 0.5, 0.9), and the FE frequencies follow the exact curve.
    gap = (omega / 1.8751040687**2) ** 2 - (1 - ratio)
    assert 0 < gap < 0.021


def _paper(second_order: dict | None = None, **changes) -> dict:
    d = tomllib.loads(PAPER_RACK.read_text())
    d.update(changes)
    if second_order is not None:
        d["second_order"] = second_order
    return d


def test_p_delta_off_gives_todays_matrices():
    base = compile_rack(rack_from_dict(_paper()))
    off = compile_rack(rack_from_dict(_paper({"p_delta": False})))
    K_E, _ = assemble_sparse(base.mesh)
    assert base.critical_load_factor is None and off.critical_load_factor is None
    assert (base.K_sparse != K_E).nnz == 0
    for name in ("K_sparse", "M_sparse", "C_sparse"):
        assert (getattr(base, name) != getattr(off, name)).nnz == 0
    assert base.damping_coefficients == off.damping_coefficients


def test_p_delta_on_softens_the_paper_rack():
    base = compile_rack(rack_from_dict(_paper()))
    on = compile_rack(rack_from_dict(_paper({"p_delta": True})))
    lam = on.critical_load_factor
    assert lam is not None and 1 < lam < np.inf
    T0 = modal_analysis(base, 1).periods[0]
    T = modal_analysis(on, 1).periods[0]
    # single-mode estimate T ≈ T0 / sqrt(1 - 1/λ): the sway mode is nearly the buckling mode
    assert abs(T / (T0 / np.sqrt(1 - 1 / lam)) - 1) < 2e-3


def test_rack_too_heavy_for_its_uprights_is_refused():
    d = _paper({"p_delta": True})
    for p in d["pallets"]:
        p["mass"] = 8000.0
    spec = rack_from_dict(d)
    with pytest.raises(InputError) as err:
        compile_rack(spec)
    assert err.value.field == "second_order.p_delta"
    assert "critical load factor" in str(err.value)
    d["second_order"]["p_delta"] = False
    assert compile_rack(rack_from_dict(d)).critical_load_factor is None  # linear: no check


@pytest.mark.parametrize(("table", "field"), [
    ({"p_delta": "yes"}, "second_order.p_delta"),
    ({"p_delta": True, "form": "exact"}, "second_order.form"),
    ({"pdelta": True}, "second_order.pdelta"),
])
def test_bad_second_order_table(table, field):
    with pytest.raises(InputError) as err:
        rack_from_dict(_paper(table))
    assert err.value.field == field


# --- OpenSeesPy cross-check on the paper rack ------------------------------------------------

def _opensees_namespace(model) -> dict:
    from seisrack.export import opensees_script

    script = opensees_script(model, pallets="rigid")
    ns: dict = {"__name__": "paper_rack_ops"}
    exec(compile(script, "rack_ops.py", "exec"), ns)
    assert ns["GEOM_TRANSF"] == "Linear"
    ns["GEOM_TRANSF"] = "PDelta"  # the script's switch: OpenSees' chord term
    return ns


def _nodal_gravity(model) -> dict[int, list[float]]:
    """seisrack's gravity load -g·M·r_y on the OpenSees node owning each DOF (tag = index + 1)."""
    F = -model.g * (model.M_sparse @ model.r_y)
    loads: dict[int, list[float]] = {}
    seen: set[int] = set()
    for i, dofs in enumerate(model.mesh.node_dofs):
        for k, d in enumerate(dofs):
            if d >= 0 and d not in seen:  # the first node holding a DOF retains it
                seen.add(int(d))
                loads.setdefault(i + 1, [0.0, 0.0, 0.0])[k] = float(F[d])
    return loads


def _opensees_lowest_eigenvalue(ns: dict, loads: dict, lam: float) -> float:
    ops = ns["ops"]
    ns["build"]("rigid")
    ops.timeSeries("Constant", 1)
    ops.pattern("Plain", 1, 1)
    for node, f in loads.items():
        ops.load(node, *(lam * v for v in f))
    ops.constraints("Transformation")
    ops.numberer("RCM")
    ops.system("BandGeneral")
    ops.algorithm("Linear")  # one linear step from the unstressed state: linear gravity forces
    ops.integrator("LoadControl", 1.0)
    ops.analysis("Static")
    assert ops.analyze(1) == 0
    ops.loadConst("-time", 0.0)
    return float(ops.eigen(ns["EIGEN_SOLVER"], 1)[0])


def test_paper_rack_against_opensees_pdelta():
    pytest.importorskip("openseespy.opensees")
    model = compile_rack(rack_from_dict(_paper({"p_delta": True, "form": "p_delta_only"})))
    ns = _opensees_namespace(model)
    loads = _nodal_gravity(model)

    T = modal_analysis(model, 1).periods[0]
    T_ops = 2 * np.pi / np.sqrt(_opensees_lowest_eigenvalue(ns, loads, 1.0))
    lam = model.critical_load_factor
    lam_ops = scipy.optimize.brentq(lambda x: _opensees_lowest_eigenvalue(ns, loads, x),
                                    0.5 * lam, 1.5 * lam, xtol=1e-10 * lam)
    assert abs(T / T_ops - 1) < 5e-3
    assert abs(lam / lam_ops - 1) < 5e-3
    # same matrices on both sides: far closer than the 0.5 % asked for
    assert abs(T / T_ops - 1) < 1e-6
    assert abs(lam / lam_ops - 1) < 1e-6


def test_paper_rack_consistent_form_is_the_converged_value():
    """The consistent form at the file's 4 elements per member is within 0.1 % of the chord
    form on a 16-element mesh extrapolated (Richardson, order 2) to h → 0."""
    lam = compile_rack(rack_from_dict(_paper({"p_delta": True}))).critical_load_factor

    def chord(sub: int) -> float:
        d = _paper({"p_delta": True, "form": "p_delta_only"})
        d["geometry"]["subdivisions"] = sub
        return compile_rack(rack_from_dict(d)).critical_load_factor

    l8, l16 = chord(8), chord(16)
    extrapolated = l16 + (l16 - l8) / 3
    assert abs(lam / extrapolated - 1) < 1e-3


def test_cli_modal_shows_the_critical_load_factor(tmp_path, capsys):
    f = tmp_path / "rack.toml"
    f.write_text(PAPER_RACK.read_text() + "\n[second_order]\np_delta = true\n")
    lam = compile_rack(rack_from_dict(_paper({"p_delta": True}))).critical_load_factor
    assert main(["modal", str(f)]) == 0
    assert f"critical load factor {lam:.4g}" in capsys.readouterr().out
    assert main(["modal", str(f), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["critical_load_factor"] == pytest.approx(lam)
    assert main(["modal", str(PAPER_RACK), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["critical_load_factor"] is None


def test_sparse_and_dense_buckling_solvers_agree(monkeypatch):
    d = tomllib.loads((PAPER_RACK.parent / "three_level_rack.toml").read_text())
    d["second_order"] = {"p_delta": True}
    dense = compile_rack(rack_from_dict(d)).critical_load_factor
    monkeypatch.setattr(geometric, "DENSE_MAX_DOF", 0)  # ARPACK path of large racks
    sparse = compile_rack(rack_from_dict(d)).critical_load_factor
    assert dense is not None and sparse == pytest.approx(dense, rel=1e-8)


def test_tension_only_has_no_critical_load():
    _, K, _, KG = _column_kg(4, -1.0, "consistent")  # a pulled column
    assert geometric.critical_load_factor(K, KG) == np.inf
