"""Linear geometric stiffness (P-Δ) of 2D beam-column elements, vectorised over elements.

Sign convention: ``N`` is the element axial force, **tension positive** (as in
:mod:`seisrack.fe.recovery`: ``N = N_j = -N_i``). A compressed member (N < 0) softens the frame:
the second-order stiffness is ``K = K_E + K_G(N)``.

Two forms, local DOFs ``[u_i, v_i, θ_i, u_j, v_j, θ_j]``:

- ``"consistent"``: the geometric stiffness of the cubic-Hermite element,
  k_G = ∫ N v'ᵀ v' dx (Przemieniecki, *Theory of Matrix Structural Analysis*, 1968, ch. 15;
  McGuire, Gallagher & Ziemian, *Matrix Structural Analysis*, 2nd ed., 2000, ch. 9, the
  framework element's geometric stiffness without its axial N/L terms, which play no part in a
  linear buckling or P-Δ analysis of frames; H. Gavin, *Geometric Stiffness Effects in 2D and
  3D Frames*, Duke CEE 421L notes, 2012; equation numbers not checked here)::

      N/L · [ 6/5   L/10    -6/5   L/10  ]   on (v_i, θ_i, v_j, θ_j)
            [ L/10  2L²/15  -L/10  -L²/30 ]
            [ -6/5  -L/10   6/5    -L/10 ]
            [ L/10  -L²/30  -L/10  2L²/15 ]

  It captures P-δ within the element: a cantilever's Euler load converges as h⁴.
- ``"p_delta_only"``: the chord-rotation term alone, N/L·[[1, -1], [-1, 1]] on (v_i, v_j), the
  form of OpenSees' ``geomTransf PDelta`` (PDeltaCrdTransf2d). It converges as h² with the number
  of elements per member.

The axial forces come from a linear static solve under gravity (:func:`gravity_axial_forces`)
and the lowest buckling load factor from a sparse generalised eigenproblem
(:func:`critical_load_factor`).
"""

from __future__ import annotations

from typing import Literal

import numpy as np
import scipy.linalg
import scipy.sparse as sp
import scipy.sparse.linalg as sla

from seisrack.fe.assembly import scatter, symmetric_csr
from seisrack.fe.elements import rotation, to_global
from seisrack.fe.mesh import FloatArray, FrameMesh
from seisrack.fe.recovery import element_end_forces
from seisrack.fe.stability import symmetric_lu

GeometricForm = Literal["consistent", "p_delta_only"]
FORMS: tuple[str, ...] = ("consistent", "p_delta_only")
#: problems up to this many DOFs get the buckling factor from a dense LAPACK solve
DENSE_MAX_DOF = 500
#: 1/λ below which the load is taken as unable to buckle the frame (λ > 1e12)
MU_NONE = 1e-12


def local_geometric_stiffness(N: FloatArray, L: FloatArray,
                              form: GeometricForm = "consistent") -> FloatArray:
    """(n_el, 6, 6) local geometric stiffness [N/m, N, N·m] for axial forces ``N`` (n_el,) [N],
    tension positive, and lengths ``L`` (n_el,) [m]."""
    n = L.shape[0]
    k = np.zeros((n, 6, 6))
    a = N / L
    if form == "p_delta_only":
        k[:, 1, 1] = k[:, 4, 4] = a
        k[:, 1, 4] = k[:, 4, 1] = -a
        return k
    if form != "consistent":
        raise ValueError(f"form must be one of {FORMS}, not {form!r}")
    # the matrix of the module docstring (bending part of the consistent form)
    bend = np.array([[6 / 5, 1 / 10, -6 / 5, 1 / 10],
                     [1 / 10, 2 / 15, -1 / 10, -1 / 30],
                     [-6 / 5, -1 / 10, 6 / 5, -1 / 10],
                     [1 / 10, -1 / 30, -1 / 10, 2 / 15]])
    p = np.array([0, 1, 0, 1])  # powers of L carried by each entry (v: L^0, θ: L^1)
    powers = p[:, None] + p[None, :]
    idx = np.array([1, 2, 4, 5])
    k[:, idx[:, None], idx[None, :]] = a[:, None, None] * bend * L[:, None, None] ** powers
    return k


def geometric_stiffness(mesh: FrameMesh, N: FloatArray,
                        form: GeometricForm = "consistent") -> sp.csr_matrix:
    """Global geometric stiffness K_G (n_dof, n_dof) CSR, symmetric and canonical, for element
    axial forces ``N`` (n_el,) [N], tension positive."""
    c, s = mesh.direction_cosines
    kg = to_global(local_geometric_stiffness(np.asarray(N, float), mesh.lengths, form),
                   rotation(c, s))
    return symmetric_csr(scatter(kg, mesh.element_dofs, mesh.n_dof))


def gravity_axial_forces(mesh: FrameMesh, K: sp.spmatrix, F: FloatArray) -> FloatArray:
    """(n_el,) [N] axial force of each element (tension positive) from the linear static solution
    K u = F (``F`` (n_dof,) [N, N·m], e.g. -g·M·r_y for gravity).

    The force is the element's mean axial force EA (u_j − u_i)/L, which is what a uniform-N
    geometric stiffness needs (a member's own weight makes N vary linearly along it).
    """
    u = symmetric_lu(K).solve(np.asarray(F, float))
    return element_end_forces(mesh, u)[:, 3]


def critical_load_factor(K_E: sp.spmatrix, K_G: sp.spmatrix) -> float:
    """Lowest λ > 0 with det(K_E + λ K_G) = 0 (``inf`` if none below 1e12: no compression).

    With μ = 1/λ the problem is (−K_G) φ = μ K_E φ, whose largest μ gives the lowest λ; K_E is
    positive definite (checked by the caller) and −K_G indefinite, so K_E is the "mass" of the
    pencil (ARPACK regular generalised mode, K_E factored once; LAPACK ``eigh`` when small).
    """
    n = K_E.shape[0]
    if n == 0 or K_G.nnz == 0:
        return float("inf")
    A = -sp.csr_matrix(K_G)
    if n <= DENSE_MAX_DOF:
        mu = float(scipy.linalg.eigh(A.toarray(), sp.csr_matrix(K_E).toarray(),
                                     eigvals_only=True, subset_by_index=[n - 1, n - 1])[0])
    else:
        lu = symmetric_lu(K_E)
        Minv = sla.LinearOperator((n, n), matvec=lu.solve, dtype=float)
        mu = float(sla.eigsh(A, k=1, M=sp.csr_matrix(K_E), Minv=Minv, which="LA",
                             return_eigenvectors=False)[0])
    # μ = 1/λ is dimensionless: without compression it is round-off (≈ 1e-17), not a load
    # factor of 1e17; below MU_NONE the frame does not buckle under any multiple of the load.
    if mu <= MU_NONE:
        return float("inf")
    return 1.0 / mu
