"""Force recovery on compiled racks: equilibrium of the support reactions under static loads,
the base-spring moment, and upright moments at the joints (statics: Σ F = 0, Σ M = 0; the
spring laws M = k·Δθ of the semi-rigid connections, ``docs/theory/portal_stiffness.md``).
"""

from __future__ import annotations

import numpy as np
import pytest

from rack_inputs import PAPER_RACK, portal_dict
from seisrack.fe import base_reactions, element_end_forces, upright_moments
from seisrack.model import compile_rack, load_rack, rack_from_dict

H_LOAD = 2.5e3


@pytest.fixture(scope="module")
def paper():
    return compile_rack(load_rack(PAPER_RACK))


def _lateral(model, total: float = H_LOAD) -> tuple[np.ndarray, np.ndarray]:
    P = np.zeros(model.n_dof)
    P[model.pallet_dofs[:, 0, 0]] += total / model.n_pallets  # the pallets push the beam sideways
    np.add.at(P, model.pallet_vdof[:, 0], -model.pallet_mass * model.g)  # and load it vertically
    return P, np.linalg.solve(model.K, P)


def test_base_shear_and_vertical_equilibrium(paper):
    P, u = _lateral(paper)
    R = base_reactions(paper, u)
    assert R.shape == (3, 3)
    assert R[:, 0].sum() == pytest.approx(-H_LOAD, rel=1e-9)
    assert R[:, 1].sum() == pytest.approx(paper.pallet_mass.sum() * paper.g, rel=1e-9)


def test_moment_equilibrium_about_origin(paper):
    P, u = _lateral(paper)
    R = base_reactions(paper, u)
    xy = paper.nodes[paper.base_nodes]
    m_reac = np.sum(R[:, 2] + xy[:, 0] * R[:, 1] - xy[:, 1] * R[:, 0])
    # moment of the applied nodal loads about the origin
    m_load = 0.0
    for node, dofs in enumerate(paper.node_dofs):
        if node in set(paper.level_nodes.ravel()):
            continue  # beam-end nodes share these translation DOFs; count each DOF once
        x, y = paper.nodes[node]
        fx = P[dofs[0]] if dofs[0] >= 0 else 0.0
        fy = P[dofs[1]] if dofs[1] >= 0 else 0.0
        m_load += x * fy - y * fx
    assert m_reac + m_load == pytest.approx(0.0, abs=1e-9 * H_LOAD * 2.0)


def test_base_moment_is_the_spring_moment(paper):
    _, u = _lateral(paper)
    R = base_reactions(paper, u)
    theta = u[paper.node_dofs[paper.base_nodes, 2]]
    assert R[:, 2] == pytest.approx(-160e3 * theta, rel=1e-12)
    mom = upright_moments(paper, u)
    assert mom.base[0] == pytest.approx(-R[:, 2], rel=1e-9)


def test_upright_top_moment_equals_joint_spring_moment(paper):
    _, u = _lateral(paper)
    mom = upright_moments(paper, u)
    # rotation of each upright top node and of the beam-end nodes attached to it
    theta_up = u[paper.node_dofs[paper.level_nodes[:, 0], 2]]
    beam_ends = {}
    for e in np.flatnonzero(paper.element_kind == 1):
        for node in paper.elements[e]:
            x = paper.nodes[node, 0]
            col = int(np.argmin(np.abs(paper.upright_x - x)))
            if abs(paper.upright_x[col] - x) < 1e-12:
                beam_ends.setdefault(col, set()).add(int(node))
    for col, ends in beam_ends.items():
        spring = sum(160e3 * (theta_up[col] - u[paper.node_dofs[n, 2]]) for n in ends)
        # top-of-column joint equilibrium: member end moment + springs = 0
        assert mom.below[0, col, 0] == pytest.approx(-spring, rel=1e-9)
    assert np.all(mom.above == 0.0)
    assert mom.peak_abs().shape == (1, 3)


def test_vectorised_over_time_matches_single_steps(paper):
    rng = np.random.default_rng(1)
    U = rng.standard_normal((5, paper.n_dof)) * 1e-3
    f = element_end_forces(paper, U)
    assert f.shape == (5, paper.mesh.n_el, 6)
    assert f[3] == pytest.approx(element_end_forces(paper, U[3]))
    R = base_reactions(paper, U)
    assert R.shape == (5, 3, 3)
    assert R[2] == pytest.approx(base_reactions(paper, U[2]))
    assert upright_moments(paper, U).below.shape == (5, 3, 1)


def test_rigid_base_reaction_from_elements():
    model = compile_rack(rack_from_dict(portal_dict(base="rigid")))
    P = np.zeros(model.n_dof)
    P[model.node_dofs[model.level_nodes[0, 0], 0]] = H_LOAD
    u = np.linalg.solve(model.K, P)
    R = base_reactions(model, u)
    assert R[:, 0].sum() == pytest.approx(-H_LOAD, rel=1e-9)
    xy = model.nodes[model.base_nodes]
    h = model.level_y[0]
    assert np.sum(R[:, 2] + xy[:, 0] * R[:, 1]) - h * H_LOAD == pytest.approx(0.0, abs=1e-6)
    assert np.all(R[:, 2] > 0)  # counter-clockwise: both feet resist the clockwise overturning
