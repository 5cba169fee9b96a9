"""Sparse compiled model: CSR matrices equal to the dense assembly, the stability check by the
pivots of a symmetric sparse factorisation (Sylvester's law of inertia: Golub & Van Loan,
*Matrix Computations*, 4th ed., §4.1–4.2), and the shift-invert Lanczos modal solver against
LAPACK's dense ``eigh`` (same periods, shapes and participation; Chopra, *Dynamics of
Structures*, 4th ed., §13.2) on the paper's rack, the three-level example and a warehouse rack
of 10 levels x 20 bays (3,481 DOFs).
"""

from __future__ import annotations

import json
import pickle

import numpy as np
import pytest
import scipy.linalg
import scipy.sparse as sp

from rack_inputs import EXAMPLES, PAPER_RACK, paper_dict, portal_dict, to_toml
from seisrack.cli import main
from seisrack.errors import InputError
from seisrack.fe import (
    assemble,
    assemble_sparse,
    is_positive_definite,
    line_mesh,
    modal_analysis,
    modal_from_matrices,
)
from seisrack.fe.modal import choose_method
from seisrack.model import compile_rack, load_rack, rack_from_dict
from seisrack.model.rack_mesh import build_rack_mesh

THREE_LEVEL = EXAMPLES / "three_level_rack.toml"


def warehouse_dict(n_levels: int = 10, n_bays: int = 20) -> dict:
    """A warehouse rack: 1.5 m levels, 2.7 m bays, two 800 kg pallets per bay and level."""
    d = paper_dict()
    d["title"] = f"Warehouse rack {n_levels} levels x {n_bays} bays"
    d["sections"] = {"beam": {"A": 1.0e-3, "I": 2.5e-6}, "upright": {"A": 1.2e-3, "I": 1.6e-6}}
    d["geometry"].update(bays=[2.7] * n_bays, levels=[1.5] * n_levels, subdivisions=2)
    d["pallets"] = [{"mass": 800.0, "bay": b + 1, "level": lv + 1, "position": x,
                     "mu_static": 0.4, "mu_dynamic": 0.35}
                    for lv in range(n_levels) for b in range(n_bays) for x in (0.675, 2.025)]
    return d


@pytest.fixture(scope="module", params=["paper", "three_level"])
def model(request):
    return compile_rack(load_rack(PAPER_RACK if request.param == "paper" else THREE_LEVEL))


@pytest.fixture(scope="module")
def warehouse():
    return compile_rack(rack_from_dict(warehouse_dict()))


# --- the compiled matrices -------------------------------------------------------------------

def test_sparse_matrices_are_canonical_symmetric_csr(model):
    for A in (model.K_sparse, model.M_sparse, model.C_sparse, model.total_mass_sparse()):
        assert sp.isspmatrix_csr(A) and A.shape == (model.n_dof, model.n_dof)
        assert A.has_canonical_format
        assert abs(A - A.T).max() == 0.0


def test_dense_views_equal_the_sparse_matrices(model):
    assert np.array_equal(model.K, model.K_sparse.toarray())
    assert np.array_equal(model.M, model.M_sparse.toarray())
    assert np.array_equal(model.C, model.C_sparse.toarray())
    assert np.array_equal(model.total_mass_matrix(), model.total_mass_sparse().toarray())
    a0, a1 = model.damping_coefficients
    assert abs(model.C_sparse - (a0 * model.M_sparse + a1 * model.K_sparse)).max() <= (
        1e-15 * abs(model.C_sparse).max())


def test_member_matrices_equal_the_dense_assembly():
    mesh = build_rack_mesh(load_rack(THREE_LEVEL)).mesh
    K, M = assemble_sparse(mesh)
    Kd, Md = assemble(mesh)
    assert np.array_equal(K.toarray(), Kd) and np.array_equal(M.toarray(), Md)
    # one spring per semi-rigid joint and base: K has the spring couplings, M does not
    assert K.nnz > M.nnz


def test_sparse_matrices_are_read_only(model):
    for A in (model.K_sparse, model.M_sparse, model.C_sparse):
        for part in (A.data, A.indices, A.indptr):
            with pytest.raises(ValueError):
                part[0] = part[0]
    Mt = model.total_mass_sparse()
    Mt.data[0] += 1.0  # a fresh, writable matrix
    assert Mt[0, 0] != model.M_sparse[0, 0] or model.pallet_dofs.size == 0


def test_compile_forms_no_dense_matrix_and_pickles_without_one(warehouse):
    assert not {"K", "M", "C"} & set(vars(warehouse))  # dense views not built by compile
    small = compile_rack(load_rack(PAPER_RACK))
    _ = small.K  # build and cache a dense view ...
    assert "K" in vars(small)
    clone = pickle.loads(pickle.dumps(small))  # ... which is not pickled
    assert "K" not in vars(clone) and np.array_equal(clone.K, small.K)


def test_warehouse_rack_layout_and_mass(warehouse):
    assert warehouse.n_dof == 3481 and warehouse.n_pallets == 400
    assert warehouse.K_sparse.nnz < 20 * warehouse.n_dof  # O(n) storage, banded frame
    rx = warehouse.r_x
    assert rx @ (warehouse.total_mass_sparse() @ rx) - rx @ (warehouse.M_sparse @ rx) == (
        pytest.approx(400 * 800.0, rel=1e-12))


# --- stability ---------------------------------------------------------------------------------

def test_positive_definite_matches_eigenvalues_on_small_matrices():
    rng = np.random.default_rng(3)
    for _ in range(20):
        Q = np.linalg.qr(rng.standard_normal((8, 8)))[0]
        lam = rng.uniform(0.5, 2.0, 8)
        n_neg = rng.integers(0, 3)
        lam[:n_neg] *= -1
        A = sp.csr_matrix((Q * lam) @ Q.T)
        assert is_positive_definite(A) == (n_neg == 0)
    singular = sp.csr_matrix(np.array([[1.0, -1.0], [-1.0, 1.0]]))
    assert not is_positive_definite(singular)
    assert not is_positive_definite(sp.csr_matrix(np.diag([1.0, 0.0, 2.0])))
    assert not is_positive_definite(sp.csr_matrix(np.array([[0.0, 1.0], [1.0, 1.0]])))


@pytest.mark.parametrize(("joint", "base", "stable"), [
    ("pinned", "pinned", False), ("rigid", "pinned", True), ("pinned", "rigid", True),
    (1.0, "pinned", True)])
def test_stability_of_rack_connections(joint, base, stable):
    """A 10 x 20 rack with every joint pinned: 10 sway mechanisms whose round-off pivots are
    positive (about 1e-13 of the diagonal), still refused; a 1 N·m/rad joint is accepted."""
    d = warehouse_dict()
    d["connections"] = {"beam_to_upright": joint, "base": base}
    mesh = build_rack_mesh(rack_from_dict(d)).mesh
    K, _ = assemble_sparse(mesh)
    assert is_positive_definite(K) is stable
    if not stable:
        with pytest.raises(InputError, match="mechanism"):
            compile_rack(rack_from_dict(d))


def test_small_pinned_portal_refused():
    with pytest.raises(InputError, match="connections"):
        compile_rack(rack_from_dict(portal_dict(joint="pinned", base="pinned")))


# --- modal analysis: sparse == dense -----------------------------------------------------------

def _assert_same_modes(a, b, rtol=1e-8):
    assert a.n_modes == b.n_modes
    assert a.periods == pytest.approx(b.periods, rel=rtol)
    scale = np.abs(a.shapes).max()
    assert np.abs(a.shapes - b.shapes).max() <= rtol * scale
    # participation is compared on the scale of the total mass: a sway mode's vertical
    # participation is round-off (1e-15 kg^0.5) in both solvers
    for axis, total in (("x", b.total_mass_x), ("y", b.total_mass_y)):
        ga, gb = getattr(a, f"gamma_{axis}"), getattr(b, f"gamma_{axis}")
        assert np.abs(ga - gb).max() <= rtol * np.sqrt(total), axis
        ma, mb = getattr(a, f"effective_mass_{axis}"), getattr(b, f"effective_mass_{axis}")
        assert np.abs(ma - mb).max() <= rtol * total, axis
    assert a.mass_participation == pytest.approx(b.mass_participation, abs=rtol)
    assert a.total_mass_x == pytest.approx(b.total_mass_x, rel=1e-14)
    assert a.total_mass_y == pytest.approx(b.total_mass_y, rel=1e-14)


@pytest.mark.parametrize("n_modes", [1, 6, 10])
def test_sparse_modes_equal_dense_modes(model, n_modes):
    full = modal_analysis(model)
    # Shapes are only defined for distinct periods: the cut must not split a cluster (the paper
    # rack's modes 12 and 13 are the same beam mode in its two identical bays).
    assert np.all(full.periods[:n_modes] / full.periods[1:n_modes + 1] > 1 + 1e-4)
    dense = modal_analysis(model, n_modes, method="dense")
    sparse = modal_analysis(model, n_modes, method="sparse")
    _assert_same_modes(sparse, dense)
    assert full.periods[:n_modes] == pytest.approx(sparse.periods, rel=1e-8)


def test_sparse_shapes_are_mass_normalised(model):
    res = modal_analysis(model, 8, method="sparse")
    Mt = model.total_mass_sparse()
    assert res.shapes.T @ (Mt @ res.shapes) == pytest.approx(np.eye(8), abs=1e-10)
    K_modal = res.shapes.T @ (model.K_sparse @ res.shapes)
    assert np.diag(K_modal) == pytest.approx(res.omega**2, rel=1e-9)


def test_massless_dofs_are_tolerated():
    """A lumped-mass cantilever (no rotational inertia: M singular): the sparse solver finds the
    same finite-frequency modes as the dense one, which drops the massless ones."""
    mesh = line_mesh(2.0, 40, E=210e9, A=1e-3, I=1e-6, density=7850.0,
                     restraints={0: (True, True, True)})
    K, _ = assemble(mesh)
    m_node = 7850.0 * 1e-3 * 2.0 / 40
    lumped = np.zeros(mesh.n_dof)
    lumped[mesh.node_dofs[1:, :2].ravel()] = m_node
    M = sp.diags(lumped).tocsr()
    r = np.zeros(mesh.n_dof)
    r[mesh.node_dofs[1:, 0]] = 1.0
    dense = modal_from_matrices(K, M.toarray(), r, r, 5, method="dense")
    sparse = modal_from_matrices(sp.csr_matrix(K), M, r, r, 5, method="sparse")
    _assert_same_modes(sparse, dense)


def test_auto_method_and_bad_method():
    assert choose_method(60, 6) == "dense"  # small
    assert choose_method(3481, None) == "dense"  # all modes
    assert choose_method(3481, 10) == "sparse"
    assert choose_method(3481, 1000) == "dense"  # most of the spectrum
    with pytest.raises(InputError, match="method"):
        choose_method(60, 6, "lanczos")  # type: ignore[arg-type]
    with pytest.raises(InputError, match="n_modes"):
        modal_analysis(compile_rack(load_rack(PAPER_RACK)), 60, method="sparse")


def test_first_period_damping_uses_the_sparse_solver(warehouse):
    a0, a1 = warehouse.damping_coefficients
    t1 = modal_analysis(warehouse, 1).periods[0]
    assert a0 == 0.0 and a1 == pytest.approx(2 * 0.02 / (2 * np.pi / t1), rel=1e-12)


@pytest.mark.slow
def test_warehouse_periods_match_dense_eigh(warehouse):
    """First five periods of the 10 x 20 rack from the sparse solver against LAPACK on the same
    (densified) matrices."""
    res = modal_analysis(warehouse, 5)
    n = warehouse.n_dof
    lam = scipy.linalg.eigh(warehouse.K_sparse.toarray(), warehouse.total_mass_sparse().toarray(),
                            eigvals_only=True, subset_by_index=[0, 4])
    assert res.periods == pytest.approx(2 * np.pi / np.sqrt(lam), rel=1e-6)
    assert n > 3000 and res.mass_participation[0] > 0.7


def test_cli_modal_on_warehouse_rack(tmp_path, capsys):
    path = tmp_path / "warehouse.toml"
    path.write_text(to_toml(warehouse_dict()))
    assert main(["modal", str(path), "--json", "--modes", "4"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["n_dof"] == 3481 and len(out["periods_s"]) == 4
    assert out["periods_s"] == sorted(out["periods_s"], reverse=True)
