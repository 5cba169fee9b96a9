"""P-Δ on 3D racks (issue 21, item 3): the space frame's geometric stiffness in both bending
planes, the bars' string stiffness, the critical load factor and the periods under gravity.

References:
- Euler load of a cantilever (fixed base, free top) under an axial end load,
  P_cr = π² E I / (4 L²) (Timoshenko & Gere, *Theory of Elastic Stability*, 2nd ed., 1961,
  §2.1), in each principal plane of a space member (I = Iz for bending in the local x–y plane,
  Iy in the x–z plane): the consistent form converges as h⁴, the chord form (OpenSees'
  PDelta) as h², as in 2D (``tests/test_fe_pdelta.py``).
- A pin-ended compressed bar whose top is held sideways by a spring of stiffness k: it
  buckles sideways at P_cr = k L (the leaning column; Timoshenko & Gere §2.2 for the rigid
  bar on an elastic support, here the bar's length L is the lever arm): exact, with no mesh.
- OpenSeesPy with ``geomTransf PDelta`` (PDeltaCrdTransf3d: N/L on both local transverse
  translations, the chord form): the 3D paper rack exported by
  :func:`seisrack.export.opensees_script` with ``GEOM_TRANSF = "PDelta"``, seisrack's gravity
  load applied first (one linear static step, ``loadConst -time 0``), then ``eigen``. OpenSees'
  ``Truss`` bars have no geometric stiffness, so the like-for-like comparison leaves out the
  bars' in seisrack; with them the difference is that of the bars, measured.
"""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg
import scipy.optimize

from seisrack.errors import InputError
from seisrack.fe import geometric
from seisrack.fe.assembly import assemble_sparse
from seisrack.fe.mesh import FrameMesh, number_dofs
from seisrack.fe.modal import modal_analysis, modal_from_matrices
from seisrack.model import compile_rack, rack_from_dict

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
PAPER_3D = EXAMPLES / "paper_rack_3d.toml"
L = 1.0


def _cantilever(n_el: int, Iz: float, Iy: float, axis=(0.0, 1.0, 0.0), vecxz=(0.0, 0.0, 1.0)
                ) -> FrameMesh:
    """A space cantilever of ``n_el`` elements along ``axis`` from the origin (fixed there);
    E = G = 1, J = 10 and EA = 1e4 keep twist and axial modes out of the way."""
    s = np.linspace(0.0, L, n_el + 1)
    nodes = np.outer(s, np.asarray(axis) / np.linalg.norm(axis))
    free = np.ones((n_el + 1, 6), dtype=bool)
    free[0] = False
    node_dofs, n_dof = number_dofs(free)
    one = np.ones(n_el)
    return FrameMesh(nodes=nodes, elements=np.column_stack([np.arange(n_el),
                                                            np.arange(1, n_el + 1)]),
                     node_dofs=node_dofs, E=one, G=one, A=1e4 * one, I=Iz * one, Iy=Iy * one,
                     J=10 * one, Ip=one, density=1e-4 * one, vecxz=np.tile(vecxz, (n_el, 1)),
                     springs=np.zeros((0, 2), dtype=np.int64), spring_k=np.zeros(0),
                     n_dof=n_dof)


def _critical(mesh: FrameMesh, form: str) -> tuple[float, np.ndarray]:
    """(λ_cr for a unit compressive tip load along the member, the tip translation of the
    buckling mode)."""
    K, _ = assemble_sparse(mesh)
    axis = mesh.nodes[-1] / np.linalg.norm(mesh.nodes[-1])
    F = np.zeros(mesh.n_dof)
    F[mesh.node_dofs[-1, :3]] = -axis
    N, _ = geometric.static_axial_forces(mesh, K, F)
    np.testing.assert_allclose(N, -1.0, rtol=1e-9)  # uniform compression
    KG = geometric.geometric_stiffness(mesh, N, form)  # type: ignore[arg-type]
    lam = geometric.critical_load_factor(K, KG)
    A, B = K.toarray(), -KG.toarray()
    _, v = scipy.linalg.eigh(B, A)
    return lam, v[mesh.node_dofs[-1, :3], -1]


@pytest.mark.parametrize(("form", "order"), [("consistent", 4.0), ("p_delta_only", 2.0)])
@pytest.mark.parametrize(("Iz", "Iy", "sway"), [(1.0, 4.0, 0), (4.0, 1.0, 2)])
def test_cantilever_euler_load_in_both_planes(form, order, Iz, Iy, sway):
    """The weaker principal plane governs: Iz (sway along x) or Iy (sway along z)."""
    p_cr = np.pi**2 * min(Iz, Iy) / (4 * L**2)
    errs = []
    for n in (2, 4, 8):
        lam, tip = _critical(_cantilever(n, Iz, Iy), form)
        errs.append(lam / p_cr - 1.0)
        assert np.argmax(np.abs(tip)) == sway  # the mode sways in the weaker plane
    errs = np.array(errs)
    # measured as in 2D: consistent 5.1e-4, 3.3e-5, 2.1e-6; chord 5.2e-2, 1.3e-2, 3.2e-3
    assert np.all(errs > 0)
    np.testing.assert_allclose(np.log2(errs[:-1] / errs[1:]), order, atol=0.1)


@pytest.mark.parametrize("form", ["consistent", "p_delta_only"])
def test_orientation_does_not_change_the_euler_load(form):
    """An inclined member with a skew vecxz: the same λ as the vertical one with the same
    principal stiffnesses (the transformation of the geometric stiffness)."""
    ref, _ = _critical(_cantilever(4, 1.0, 4.0), form)
    axis = np.array([0.3, 0.8, -0.5])
    vec = np.cross(axis, [1.0, 0.0, 0.0])  # normal to the axis: it is the local z
    lam, _ = _critical(_cantilever(4, 1.0, 4.0, axis=tuple(axis), vecxz=tuple(vec)), form)
    assert lam == pytest.approx(ref, rel=1e-10)


def _leaning_bar(k_x: float, k_z: float) -> FrameMesh:
    """A vertical bar (node 0 pinned at the ground, node 1 on top) held at its top by two
    horizontal bars along x and z (stiffness k_x, k_z, their far ends fixed); bars only."""
    nodes = np.array([[0, 0, 0], [0, L, 0], [1.0, L, 0], [0, L, 1.0]], dtype=float)
    free = np.zeros((4, 6), dtype=bool)
    free[1, :3] = True
    node_dofs, n_dof = number_dofs(free)
    none = np.zeros(0)
    return FrameMesh(nodes=nodes, elements=np.zeros((0, 2), dtype=np.int64),
                     node_dofs=node_dofs, E=none, A=none, I=none, density=none, G=none,
                     Iy=none, J=none, Ip=none, vecxz=np.zeros((0, 3)),
                     springs=np.zeros((0, 2), dtype=np.int64), spring_k=np.zeros(0),
                     n_dof=n_dof, trusses=np.array([[0, 1], [1, 2], [1, 3]]),
                     truss_E=np.ones(3), truss_A=np.array([1e6, k_x, k_z]),
                     truss_density=np.ones(3))


@pytest.mark.parametrize(("k_x", "k_z"), [(3.0, 5.0), (7.0, 2.0)])
def test_compressed_bar_is_a_leaning_column(k_x, k_z):
    mesh = _leaning_bar(k_x, k_z)
    K, _ = assemble_sparse(mesh)
    F = np.zeros(mesh.n_dof)
    F[mesh.node_dofs[1, 1]] = -1.0
    N, N_bar = geometric.static_axial_forces(mesh, K, F)
    assert N.size == 0
    np.testing.assert_allclose(N_bar, [-1.0, 0.0, 0.0], atol=1e-9)
    KG = geometric.geometric_stiffness(mesh, N, "consistent", N_bar)
    assert geometric.critical_load_factor(K, KG) == pytest.approx(min(k_x, k_z) * L, rel=1e-9)
    # without the bars' forces nothing buckles
    assert geometric.critical_load_factor(K, geometric.geometric_stiffness(mesh, N)) == np.inf


# --- the 3D rack --------------------------------------------------------------------------------

def _paper3d(second_order: dict | None = None) -> dict:
    d = tomllib.loads(PAPER_3D.read_text())
    if second_order is not None:
        d["second_order"] = second_order
    return d


def test_p_delta_is_built_for_3d_racks():
    base = compile_rack(rack_from_dict(_paper3d()))
    on = compile_rack(rack_from_dict(_paper3d({"p_delta": True})))
    lam = on.critical_load_factor
    assert lam is not None and 1 < lam < np.inf  # measured 34.84
    T0, T = modal_analysis(base, 3).periods, modal_analysis(on, 3).periods
    assert np.all(T > T0)
    # first sway mode ≈ the buckling mode: T ≈ T0 / sqrt(1 - 1/λ) (measured ratio 0.99993)
    assert abs(T[0] / (T0[0] / np.sqrt(1 - 1 / lam)) - 1) < 2e-3


def test_3d_rack_too_heavy_for_its_uprights_is_refused():
    d = _paper3d({"p_delta": True})
    for p in d["pallets"]:
        p["mass"] = 40000.0
    with pytest.raises(InputError) as err:
        compile_rack(rack_from_dict(d))
    assert err.value.field == "second_order.p_delta"
    assert "critical load factor" in str(err.value)


def test_sparse_and_dense_buckling_solvers_agree_3d(monkeypatch):
    dense = compile_rack(rack_from_dict(_paper3d({"p_delta": True}))).critical_load_factor
    monkeypatch.setattr(geometric, "DENSE_MAX_DOF", 0)
    sparse = compile_rack(rack_from_dict(_paper3d({"p_delta": True}))).critical_load_factor
    assert sparse == pytest.approx(dense, rel=1e-8)


def _opensees(model) -> tuple[dict, dict]:
    from seisrack.export import opensees_script

    ns: dict = {"__name__": "paper_rack_3d_ops"}
    exec(compile(opensees_script(model, pallets="rigid"), "rack_ops.py", "exec"), ns)
    ns["GEOM_TRANSF"] = "PDelta"
    # seisrack's gravity load -g M r_y on the node owning each DOF (tag = index + 1)
    F = -model.g * (model.M_sparse @ model.r_y)
    loads: dict[int, list[float]] = {}
    seen: set[int] = set()
    for i, dofs in enumerate(model.mesh.node_dofs):
        for k, d in enumerate(dofs):
            if d >= 0 and d not in seen:
                seen.add(int(d))
                loads.setdefault(i + 1, [0.0] * 6)[k] = float(F[d])
    return ns, loads


def _opensees_eigen(ns: dict, loads: dict, lam: float, n: int) -> np.ndarray:
    ops = ns["ops"]
    ns["build"]("rigid")
    ops.timeSeries("Constant", 1)
    ops.pattern("Plain", 1, 1)
    for node, f in loads.items():
        ops.load(node, *(lam * v for v in f))
    ops.constraints("Transformation")
    ops.numberer("RCM")
    ops.system("BandGeneral")
    ops.algorithm("Linear")  # one linear step from the unstressed state
    ops.integrator("LoadControl", 1.0)
    ops.analysis("Static")
    assert ops.analyze(1) == 0
    ops.loadConst("-time", 0.0)
    return np.array(ops.eigen(ns["EIGEN_SOLVER"], n))


def test_paper_rack_3d_against_opensees_pdelta():
    pytest.importorskip("openseespy.opensees")
    model = compile_rack(rack_from_dict(_paper3d({"p_delta": True, "form": "p_delta_only"})))
    ns, loads = _opensees(model)
    T_ops = 2 * np.pi / np.sqrt(_opensees_eigen(ns, loads, 1.0, 10))
    lam_ops = scipy.optimize.brentq(lambda x: _opensees_eigen(ns, loads, x, 1)[0],
                                    20.0, 50.0, xtol=1e-12)
    # like for like: seisrack without the bars' geometric stiffness (OpenSees' Truss has none)
    K_E, _ = assemble_sparse(model.mesh)
    N, N_bar = geometric.static_axial_forces(model.mesh, K_E, -model.g * (model.M_sparse
                                                                          @ model.r_y))
    KG = geometric.geometric_stiffness(model.mesh, N, "p_delta_only")
    T = modal_from_matrices(K_E + KG, model.total_mass_sparse(), model.r_x, model.r_y,
                            n_modes=10).periods
    assert np.abs(T / T_ops - 1).max() < 1e-8  # measured 2.1e-12
    assert abs(geometric.critical_load_factor(K_E, KG) / lam_ops - 1) < 1e-8  # 1.6e-11
    # the compiled model has the bars' too: a compressed bar softens the frame a little
    # (measured: periods 1.1e-6, λ 2.7e-5 below OpenSees)
    T_full = modal_analysis(model, 10).periods
    assert np.abs(T_full / T_ops - 1).max() < 1e-5
    assert -1e-4 < model.critical_load_factor / lam_ops - 1 < 0
    assert np.abs(N_bar).max() > 1.0  # the bars do carry gravity forces
