"""Static deflections of beams vs closed forms (Timoshenko & Gere, *Mechanics of Materials*,
Appendix G: cantilever tip δ = PL³/3EI, θ = PL²/2EI; simply supported midspan δ = PL³/48EI;
axial bar δ = PL/EA). Hermite beam elements are exact at the nodes for nodal loads, so the
tolerance is round-off.
"""

from __future__ import annotations

import numpy as np
import pytest

from seisrack.fe import assemble, element_end_forces, line_mesh, support_reactions

E, A, I, L, P = 210e9, 605.8e-6, 93.8e-8, 1.8, 1.0e3


def _solve(mesh, load: dict[tuple[int, int], float]) -> np.ndarray:
    K, _ = assemble(mesh)
    f = np.zeros(mesh.n_dof)
    for (node, comp), value in load.items():
        f[mesh.node_dofs[node, comp]] += value
    return np.linalg.solve(K, f)


@pytest.mark.parametrize("n_el", [1, 3, 8])
def test_cantilever_tip(n_el):
    mesh = line_mesh(L, n_el, E=E, A=A, I=I, density=7850, restraints={0: (True, True, True)})
    u = _solve(mesh, {(n_el, 1): -P, (n_el, 0): P})
    tip = mesh.node_dofs[n_el]
    assert u[tip[1]] == pytest.approx(-P * L**3 / (3 * E * I), rel=1e-10)
    assert u[tip[2]] == pytest.approx(-P * L**2 / (2 * E * I), rel=1e-10)
    assert u[tip[0]] == pytest.approx(P * L / (E * A), rel=1e-10)


def test_cantilever_fixed_end_reactions_and_moment_diagram():
    n = 4
    mesh = line_mesh(L, n, E=E, A=A, I=I, density=7850, restraints={0: (True, True, True)})
    u = _solve(mesh, {(n, 1): -P})
    r = support_reactions(mesh, u, np.array([0]))[0]
    assert r == pytest.approx([0.0, P, P * L], abs=1e-6 * P * L)
    f = element_end_forces(mesh, u)
    # internal moment at end i of each element: -M_i = -P (L - x_i) (hogging)
    x_i = mesh.nodes[mesh.elements[:, 0], 0]
    assert -f[:, 2] == pytest.approx(-P * (L - x_i), abs=1e-6)
    assert f[:, 1] == pytest.approx(P * np.ones(n), rel=1e-9)  # shear carried by every element


@pytest.mark.parametrize("n_el", [2, 4, 10])
def test_simply_supported_midspan(n_el):
    mesh = line_mesh(L, n_el, E=E, A=A, I=I, density=7850,
                     restraints={0: (True, True, False), -1: (False, True, False)})
    mid = n_el // 2
    u = _solve(mesh, {(mid, 1): -P})
    assert u[mesh.node_dofs[mid, 1]] == pytest.approx(-P * L**3 / (48 * E * I), rel=1e-10)
    r = support_reactions(mesh, u, np.array([0, n_el]))
    assert r[:, 1] == pytest.approx([P / 2, P / 2], rel=1e-9)
    assert r[:, 2] == pytest.approx([0.0, 0.0], abs=1e-9)
