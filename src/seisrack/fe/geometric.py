"""Linear geometric stiffness (P-Δ) of beam-columns and bars, 2D or 3D, vectorised over
elements.

Sign convention: ``N`` is the element axial force, **tension positive** (as in
:mod:`seisrack.fe.recovery`: ``N = N_j = -N_i``). A compressed member (N < 0) softens the frame:
the second-order stiffness is ``K = K_E + K_G(N)``.

Two forms for a beam-column, in each bending plane (the plane member's one; a space member's
x–y plane on (v, θz) and x–z plane on (w, θy), where θy = −dw/dx flips the signs of the
rotation rows, as in :mod:`seisrack.fe.elements3d`):

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
- ``"p_delta_only"``: the chord-rotation term alone, N/L·[[1, -1], [-1, 1]] on (v_i, v_j) (and
  on (w_i, w_j) in 3D), the form of OpenSees' ``geomTransf PDelta`` (PDeltaCrdTransf2d/3d).
  It converges as h² with the number of elements per member.

A space member's geometric stiffness here is that of bending in its two principal planes: the
terms coupling N with the twist (Wagner's N·Ip/(A L) on θx, McGuire et al. §9.3) and the end
moments are left out, as in OpenSees' PDelta transformation. They govern the flexural-torsional
buckling of one member, which the member checks of the rack's design standard cover (EN 15512
§9), not the sway of the frame that P-Δ is for.

A pin-ended bar (3D bracing) has the exact string stiffness k_G = N/L [[P, −P], [−P, P]] on its
end translations, P = I − n nᵀ with n the unit axis (McGuire et al. §9.2): a compressed bar
softens the transverse motion of its ends, as a compressed beam-column's chord term does.

The axial forces come from a linear static solve under gravity (:func:`gravity_axial_forces`,
:func:`static_axial_forces`) and the lowest buckling load factor from a sparse generalised
eigenproblem (:func:`critical_load_factor`).
"""

from __future__ import annotations

from typing import Literal

import numpy as np
import scipy.linalg
import scipy.sparse as sp
import scipy.sparse.linalg as sla

from seisrack.fe.assembly import scatter, symmetric_csr
from seisrack.fe.elements import to_global
from seisrack.fe.frame_elements import end_force_maps, local_frames
from seisrack.fe.mesh import FloatArray, FrameMesh, IntArray
from seisrack.fe.recovery import element_end_forces
from seisrack.fe.stability import symmetric_lu

GeometricForm = Literal["consistent", "p_delta_only"]
FORMS: tuple[str, ...] = ("consistent", "p_delta_only")
#: problems up to this many DOFs get the buckling factor from a dense LAPACK solve
DENSE_MAX_DOF = 500
#: 1/λ below which the load is taken as unable to buckle the frame (λ > 1e12)
MU_NONE = 1e-12


#: the consistent form's bending block on (v_i, θ_i, v_j, θ_j), times N/L · L^power
_BEND = np.array([[6 / 5, 1 / 10, -6 / 5, 1 / 10],
                  [1 / 10, 2 / 15, -1 / 10, -1 / 30],
                  [-6 / 5, -1 / 10, 6 / 5, -1 / 10],
                  [1 / 10, -1 / 30, -1 / 10, 2 / 15]])
_P = np.array([0, 1, 0, 1])  # powers of L carried by each entry (v: L^0, θ: L^1)
_POW = _P[:, None] + _P[None, :]
#: per element size (6: plane, 12: space), each bending plane's local (v_i, θ_i, v_j, θ_j)
#: and the sign of its rotation rows (θy = −dw/dx in the x–z plane)
_PLANES = {6: ((np.array([1, 2, 4, 5]), np.ones(4)),),
           12: ((np.array([1, 5, 7, 11]), np.ones(4)),
                (np.array([2, 4, 8, 10]), np.array([1.0, -1.0, 1.0, -1.0])))}
#: the axial end force N_j in the local end forces, by element size
_AXIAL_J = {6: 3, 12: 6}


def local_geometric_stiffness(N: FloatArray, L: FloatArray,
                              form: GeometricForm = "consistent", ndm: int = 2) -> FloatArray:
    """(n_el, 2·ndf, 2·ndf) local geometric stiffness [N/m, N, N·m] of plane (``ndm`` 2:
    6 x 6) or space (3: 12 x 12) beam-columns, for axial forces ``N`` (n_el,) [N], tension
    positive, and lengths ``L`` (n_el,) [m]."""
    if form not in FORMS:
        raise ValueError(f"form must be one of {FORMS}, not {form!r}")
    size = 6 if ndm == 2 else 12
    k = np.zeros((L.shape[0], size, size))
    a = N / L
    for idx, sign in _PLANES[size]:
        if form == "p_delta_only":  # the chord term on the two transverse translations
            i, j = idx[0], idx[2]
            k[:, i, i] += a
            k[:, j, j] += a
            k[:, i, j] -= a
            k[:, j, i] -= a
            continue
        block = _BEND * np.outer(sign, sign)
        k[:, idx[:, None], idx[None, :]] += a[:, None, None] * block * L[:, None, None] ** _POW
    return k


def bar_geometric_stiffness(mesh: FrameMesh, N_bar: FloatArray) -> FloatArray:
    """(n_tr, 2·ndm, 2·ndm) global geometric stiffness of the pin-ended bars for axial forces
    ``N_bar`` (n_tr,) [N], tension positive (module docstring)."""
    X = mesh.nodes
    d = X[mesh.trusses[:, 1]] - X[mesh.trusses[:, 0]]
    L = np.linalg.norm(d, axis=1)
    n = d / L[:, None]
    P = np.eye(mesh.ndm)[None] - np.einsum("ei,ej->eij", n, n)
    two = np.array([[1.0, -1.0], [-1.0, 1.0]])
    k = np.einsum("ab,eij->eaibj", two, P).reshape(-1, 2 * mesh.ndm, 2 * mesh.ndm)
    return k * (np.asarray(N_bar, float) / L)[:, None, None]


def geometric_stiffness(mesh: FrameMesh, N: FloatArray, form: GeometricForm = "consistent",
                        N_bar: FloatArray | None = None) -> sp.csr_matrix:
    """Global geometric stiffness K_G (n_dof, n_dof) CSR, symmetric and canonical, for
    beam-column axial forces ``N`` (n_el,) [N] and, when given, bar axial forces ``N_bar``
    (n_tr,) [N], tension positive; a plane or a space mesh."""
    kl = local_geometric_stiffness(np.asarray(N, float), mesh.lengths, form, mesh.ndm)
    K = scatter(to_global(kl, local_frames(mesh)), mesh.element_dofs, mesh.n_dof)
    if N_bar is not None and mesh.trusses.shape[0]:
        K = K + scatter(bar_geometric_stiffness(mesh, N_bar), mesh.truss_dofs, mesh.n_dof)
    return symmetric_csr(K)


def axial_forces(mesh: FrameMesh, u: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Axial forces [N], tension positive, for free-DOF displacements ``u`` (n_dof,): of the
    beam-columns (n_el,), their mean force EA (u_j − u_i)/L (which a uniform-N geometric
    stiffness needs: a member's own weight makes N vary linearly along it), and of the bars
    (n_tr,)."""
    N = element_end_forces(mesh, u)[:, _AXIAL_J[2 * mesh.ndf]]
    if not mesh.trusses.shape[0]:
        return N, np.zeros(0)
    ut = np.append(np.asarray(u, float), 0.0)[mesh.truss_dofs]  # -1 (fixed) reads 0
    nd = mesh.ndm
    X = mesh.nodes
    d = X[mesh.trusses[:, 1]] - X[mesh.trusses[:, 0]]
    L = np.linalg.norm(d, axis=1)
    stretch = np.einsum("ei,ei->e", d / L[:, None], ut[:, nd:] - ut[:, :nd])
    return N, mesh.truss_E * mesh.truss_A / L * stretch


def static_axial_forces(mesh: FrameMesh, K: sp.spmatrix, F: FloatArray
                        ) -> tuple[FloatArray, FloatArray]:
    """(:func:`axial_forces`) of the linear static solution K u = F (``F`` (n_dof,) [N, N·m],
    e.g. -g·M·r_y for gravity): beam-column (n_el,) and bar (n_tr,) axial forces [N]."""
    return axial_forces(mesh, symmetric_lu(K).solve(np.asarray(F, float)))


def gravity_axial_forces(mesh: FrameMesh, K: sp.spmatrix, F: FloatArray) -> FloatArray:
    """(n_el,) [N] the beam-columns' axial forces of :func:`static_axial_forces`."""
    return static_axial_forces(mesh, K, F)[0]


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


def axial_operator(mesh: FrameMesh) -> sp.csr_matrix:
    """(n_el + n_tr, n_dof) the axial forces of :func:`axial_forces` (beam-columns, then
    bars; tension positive) per unit free-DOF displacement: ``axial_operator(mesh) @ u``
    equals them, as the concatenation of the two arrays."""
    n_el, nt = mesh.n_el, mesh.trusses.shape[0]
    kt = end_force_maps(mesh).kt[:, _AXIAL_J[2 * mesh.ndf], :]  # (n_el, 2 ndf)
    rows = [np.repeat(np.arange(n_el), kt.shape[1])]
    cols = [mesh.element_dofs.ravel()]
    vals = [kt.ravel()]
    if nt:
        X = mesh.nodes
        d = X[mesh.trusses[:, 1]] - X[mesh.trusses[:, 0]]
        L = np.linalg.norm(d, axis=1)
        c = (mesh.truss_E * mesh.truss_A / L)[:, None] * d / L[:, None]  # EA/L n
        rows.append(n_el + np.repeat(np.arange(nt), 2 * mesh.ndm))
        cols.append(mesh.truss_dofs.ravel())
        vals.append(np.concatenate([-c, c], axis=1).ravel())
    r, c_, v = np.concatenate(rows), np.concatenate(cols), np.concatenate(vals)
    keep = c_ >= 0
    return sp.csr_matrix((v[keep], (r[keep], c_[keep])), shape=(n_el + nt, mesh.n_dof))


def unit_geometric_factors(mesh: FrameMesh, form: GeometricForm = "consistent"
                           ) -> tuple[sp.csr_matrix, IntArray, FloatArray]:
    """The members' geometric stiffness per unit axial force by its eigenpairs: (rows
    (n_g, n_dof), owner (n_g,), scale (n_g,)) with ``K_G(N, N_bar) = Σ_g n_{owner g} scale_g
    rows_gᵀ rows_g`` for ``n = [N, N_bar]`` (owner indexes the rows of
    :func:`axial_operator`); rank 2 per member in 3D with the chord form, 6 with the
    consistent one (each plane's block but its rigid translation), 2 per bar (``ndm − 1``)."""
    blocks = [(to_global(local_geometric_stiffness(np.ones(mesh.n_el), mesh.lengths, form,
                                                   mesh.ndm), local_frames(mesh)),
               mesh.element_dofs, 0)]
    if mesh.trusses.shape[0]:
        blocks.append((bar_geometric_stiffness(mesh, np.ones(mesh.trusses.shape[0])),
                       mesh.truss_dofs, mesh.n_el))
    rows, cols, vals, owner, scale = [], [], [], [], []
    n_g = 0
    for kb, dofs, first in blocks:
        w, v = np.linalg.eigh(kb)
        big = np.abs(w) > 1e-9 * np.max(np.abs(w), axis=1, keepdims=True)
        e, i = np.nonzero(big)
        vec = v[e, :, i]  # (k, size): the eigenvectors of the kept pairs
        rows.append(n_g + np.repeat(np.arange(e.size), vec.shape[1]))
        cols.append(dofs[e].ravel())
        vals.append(vec.ravel())
        owner.append(first + e)
        scale.append(w[e, i])
        n_g += e.size
    r, c, val = np.concatenate(rows), np.concatenate(cols), np.concatenate(vals)
    keep = c >= 0
    G = sp.csr_matrix((val[keep], (r[keep], c[keep])), shape=(n_g, mesh.n_dof))
    return G, np.concatenate(owner).astype(np.int64), np.concatenate(scale)
