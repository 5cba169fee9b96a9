"""Natural frequencies of uniform Euler–Bernoulli beams vs closed forms, and their convergence.

Sources: Blevins, *Formulas for Natural Frequency and Mode Shape* (1979), Table 8-1: a beam of
length L, bending stiffness EI and mass per length m has ω_n = (β_n L)² √(EI / (m L⁴)), with
β_n L the roots of cos x cosh x + 1 = 0 (cantilever: 1.87510, 4.69409, 7.85476, 10.99554) and
β_n L = nπ (simply supported). Consistent-mass cubic Hermite elements converge in eigenvalue as
O(h⁴) (Strang & Fix, *An Analysis of the Finite Element Method*, 1973, §6.3: error h^{2(k+1-m)}
with k = 3, m = 2); the test measures the order by log–log regression.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from seisrack.fe import assemble, line_mesh, modal_from_matrices

E, A, I, RHO, L = 210e9, 488.9e-6, 41.3e-8, 7850.0, 2.0
OMEGA0 = np.sqrt(E * I / (RHO * A * L**4))


def cantilever_roots(n: int) -> np.ndarray:
    f = lambda x: np.cos(x) * np.cosh(x) + 1.0  # noqa: E731
    return np.array([brentq(f, (k + 0.5) * np.pi - 1.0, (k + 0.5) * np.pi + 1.0)
                     for k in range(n)])


def bending_omegas(mesh) -> np.ndarray:
    """Circular frequencies of the bending (transverse) modes, ascending."""
    K, M = assemble(mesh)
    n = mesh.n_dof
    res = modal_from_matrices(K, M, np.zeros(n), np.zeros(n))
    ux = mesh.node_dofs[:, 0][mesh.node_dofs[:, 0] >= 0]
    axial_share = np.abs(res.shapes[ux]).max(axis=0) / np.abs(res.shapes).max(axis=0)
    return res.omega[axial_share < 1e-8]


def cantilever(n_el: int, angle: float = 0.0):
    return line_mesh(L, n_el, E=E, A=A, I=I, density=RHO, angle=angle,
                     restraints={0: (True, True, True)})


def simply_supported(n_el: int):
    # pin at x=0, roller at x=L (axial motion free at one end only)
    return line_mesh(L, n_el, E=E, A=A, I=I, density=RHO,
                     restraints={0: (True, True, False), -1: (False, True, False)})


def test_cantilever_roots_match_published_values():
    assert cantilever_roots(4) == pytest.approx([1.87510, 4.69409, 7.85476, 10.99554], abs=2e-5)


def test_cantilever_first_four_within_0p1_percent():
    exact = cantilever_roots(4) ** 2 * OMEGA0
    fe = bending_omegas(cantilever(16))[:4]
    assert np.abs(fe / exact - 1).max() < 1e-3


def test_simply_supported_first_four_within_0p1_percent():
    exact = (np.arange(1, 5) * np.pi) ** 2 * OMEGA0
    fe = bending_omegas(simply_supported(16))[:4]
    assert np.abs(fe / exact - 1).max() < 1e-3


def test_inclined_cantilever_is_frame_invariant():
    """Rotating the member (here vertical, like an upright) must not change its frequencies."""
    K, M = assemble(cantilever(8, angle=np.pi / 2))
    K0, M0 = assemble(cantilever(8))
    import scipy.linalg
    w = scipy.linalg.eigh(K, M, eigvals_only=True)
    w0 = scipy.linalg.eigh(K0, M0, eigvals_only=True)
    assert w == pytest.approx(w0, rel=1e-9)


@pytest.mark.parametrize(("builder", "exact_root"), [
    (cantilever, lambda: cantilever_roots(2)[1]),
    (simply_supported, lambda: 2 * np.pi),
], ids=["cantilever-mode2", "simply-supported-mode2"])
def test_frequency_convergence_order_is_four(builder, exact_root):
    exact = exact_root() ** 2 * OMEGA0
    ns = np.array([4, 8, 16, 32])
    err = np.array([bending_omegas(builder(n))[1] / exact - 1 for n in ns])
    assert np.all(err > 0)  # consistent mass: upper bounds (Rayleigh–Ritz)
    order = np.polyfit(np.log(L / ns), np.log(err), 1)[0]  # err ~ C h^p
    assert 3.7 < order < 4.3, order
    assert err[-1] < 1e-3
