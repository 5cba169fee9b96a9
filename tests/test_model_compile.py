"""Compiled rack model: mesh and DOF layout, pallet bookkeeping, mass conservation, damping.

Mass conservation: a rigid translation r of an unrestrained frame has rᵀ M r equal to the total
member mass Σ ρ A L (consistent mass reproduces rigid-body inertia; Cook et al., *Concepts and
Applications of FEA*, 4th ed., §11.3). Damping: ξ(ω) = a0 / 2ω + a1 ω / 2 (Chopra, *Dynamics of
Structures*, 4th ed., Eq. 11.4.9).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from rack_inputs import PAPER_RACK, paper_dict
from seisrack.fe import assemble, modal_analysis
from seisrack.fe.damping import modal_ratio
from seisrack.model import BEAM, UPRIGHT, compile_rack, load_rack, rack_from_dict
from seisrack.model.rack_mesh import build_rack_mesh


@pytest.fixture(scope="module")
def spec():
    return load_rack(PAPER_RACK)


@pytest.fixture(scope="module")
def model(spec):
    return compile_rack(spec)


def _free_supports(mesh):
    """The same mesh with every restrained component released (for mass bookkeeping)."""
    nd = mesh.node_dofs.copy()
    fixed = nd < 0
    nd[fixed] = mesh.n_dof + np.arange(fixed.sum())
    return dataclasses.replace(mesh, node_dofs=nd, n_dof=int(mesh.n_dof + fixed.sum()))


def test_unrestrained_member_mass_is_conserved(spec):
    mesh = _free_supports(build_rack_mesh(spec).mesh)
    _, M = assemble(mesh)
    for comp in (0, 1):
        r = np.zeros(mesh.n_dof)
        r[np.unique(mesh.node_dofs[:, comp])] = 1.0
        assert r @ M @ r == pytest.approx(np.sum(mesh.density * mesh.A * mesh.lengths),
                                          rel=1e-12)


def test_pallet_masses_vertical_in_M_horizontal_only_in_total(model):
    member = 7850 * (3 * 2.0 * 488.9e-6 + 2 * 1.8 * 605.8e-6)
    assert model.member_mass == pytest.approx(member, rel=1e-12)
    Mt = model.total_mass_matrix()
    rx, ry = model.r_x, model.r_y
    assert rx @ Mt @ rx - rx @ model.M @ rx == pytest.approx(1600.0, rel=1e-12)
    assert np.allclose(Mt - model.M, np.diag(np.diag(Mt - model.M)))
    # the vertical mass is in M: compare with the same rack without pallets
    bare = compile_rack(rack_from_dict({**paper_dict(), "pallets": []}))
    assert ry @ model.M @ ry - bare.r_y @ bare.M @ bare.r_y == pytest.approx(1600.0, rel=1e-9)
    assert rx @ model.M @ rx == pytest.approx(bare.r_x @ bare.M @ bare.r_x, rel=1e-9)
    # only the small share of the uprights' mass lumped on the fixed base DOFs is not in M
    assert 0 < model.member_mass + 1600 - rx @ Mt @ rx < 0.2 * model.member_mass


def test_layout_and_pallet_nodes(model):
    assert model.nodes.shape[1] == 2 and model.elements.shape[1] == 2
    assert model.upright_x == pytest.approx([0.0, 1.8, 3.6])
    assert model.level_y == pytest.approx([2.0])
    assert np.sum(model.element_kind == UPRIGHT) == 3 * 4
    assert np.sum(model.element_kind == BEAM) == 2 * 4
    assert model.nodes[model.pallet_node[:, 0]] == pytest.approx(
        np.array([[0.45, 2.0], [1.35, 2.0], [2.25, 2.0], [3.15, 2.0]]))
    assert model.pallet_mass == pytest.approx([400.0] * 4)
    assert model.pallet_mu_static == pytest.approx([0.6] * 4)
    assert set(model.pallet_dofs[:, 0, 0]) <= set(model.level_dofs[0][0])
    assert model.r_x[model.pallet_dofs[:, 0, 0]] == pytest.approx(1.0)
    assert model.r_y[model.pallet_vdof[:, 0]] == pytest.approx(1.0)
    assert model.r_x @ model.r_y == 0.0
    # base nodes: translations fixed, rotation free (spring to ground)
    assert np.all(model.node_dofs[model.base_nodes, :2] == -1)
    assert np.all(model.node_dofs[model.base_nodes, 2] >= 0)
    assert model.g == 9.81


def test_pallet_nodes_inserted_off_the_subdivision_grid(spec):
    d = paper_dict()
    d["pallets"][0]["position"] = 0.5
    d["geometry"]["subdivisions"] = 2
    m = compile_rack(rack_from_dict(d))
    assert m.nodes[m.pallet_node[0, 0]] == pytest.approx([0.5, 2.0])
    assert m.nodes[m.pallet_node[1, 0]] == pytest.approx([1.35, 2.0])


def test_default_sliding_limits_are_free_distances(model):
    # bay 1: pallets span [0.05, 0.85] and [0.95, 1.75]; the uprights at 0 and 1.8
    assert model.layout.limit_neg == pytest.approx([0.05, 0.10, 0.05, 0.10])
    assert model.layout.limit_pos == pytest.approx([0.10, 0.05, 0.10, 0.05])


def test_explicit_sliding_limit_and_width():
    d = paper_dict()
    d["pallets"][0]["sliding_limit"] = 0.02
    d["pallets"][1]["width"] = 0.9  # spans [0.9, 1.8]: touches the upright
    m = compile_rack(rack_from_dict(d))
    assert (m.layout.limit_neg[0], m.layout.limit_pos[0]) == (0.02, 0.02)
    assert m.layout.limit_neg[1] == pytest.approx(0.9 - 0.85)  # to the neighbour's edge
    assert m.layout.limit_pos[1] == pytest.approx(0.0, abs=1e-12)


def test_stiffness_proportional_damping_at_first_period(model):
    res = modal_analysis(model, 1)
    a0, a1 = model.damping_coefficients
    assert a0 == 0.0
    assert modal_ratio(a0, a1, res.periods[0]) == pytest.approx(0.02, rel=1e-12)
    assert np.allclose(model.C, a1 * model.K)


def test_rayleigh_damping_matches_both_pairs():
    d = paper_dict()
    d["damping"] = {"kind": "rayleigh", "pairs": [[0.65, 0.02], [0.1, 0.05]]}
    m = compile_rack(rack_from_dict(d))
    a0, a1 = m.damping_coefficients
    assert modal_ratio(a0, a1, np.array([0.65, 0.1])) == pytest.approx([0.02, 0.05])
    assert np.allclose(m.C, a0 * m.M + a1 * m.K)


def test_stiffness_damping_at_given_period():
    d = paper_dict()
    d["damping"] = {"kind": "stiffness", "ratio": 0.05, "period": 0.3}
    m = compile_rack(rack_from_dict(d))
    assert modal_ratio(*m.damping_coefficients, 0.3) == pytest.approx(0.05)


def test_rigid_joint_shares_rotation():
    d = paper_dict()
    d["connections"] = {"beam_to_upright": "rigid", "base": "rigid"}
    m = compile_rack(rack_from_dict(d))
    assert m.mesh.springs.shape == (0, 2)
    assert np.all(m.node_dofs[m.base_nodes] == -1)
    semi = compile_rack(rack_from_dict(paper_dict()))
    assert semi.mesh.springs.shape == (3 + 4, 2)  # 3 base springs, 4 beam-end springs
    assert m.n_dof == semi.n_dof - 3 - 4
    assert np.allclose(m.K, m.K.T) and np.all(np.linalg.eigvalsh(m.K) > 0)


def test_compiled_arrays_are_read_only(model):
    for arr in (model.K, model.M, model.C, model.r_x, model.pallet_dofs, model.mesh.nodes,
                model.level_dofs[0][0]):
        with pytest.raises(ValueError):
            arr[0] = arr[0]
    Mt = model.total_mass_matrix()
    Mt[0, 0] += 1.0  # a fresh, writable copy
