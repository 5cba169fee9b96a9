"""Assembly: one COO scatter of all element, bar and spring matrices into a global matrix.

As in scikit-fem, the loop (implicit, via broadcasting) runs over local entries, never over
elements: the (n_el, k, k) blocks and their (n_el, k) DOF tables are flattened into COO triplets,
restrained entries (DOF ``-1``) are dropped, and duplicates are summed by the COO → CSR
conversion. :func:`assemble_sparse` is the primary form (memory O(nnz)); :func:`assemble` densifies
it for small problems and tests.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from seisrack.fe.frame_elements import element_matrices, truss_matrices
from seisrack.fe.mesh import FloatArray, FrameMesh, IntArray


def scatter(blocks: FloatArray, dofs: IntArray, n_dof: int) -> sp.csr_matrix:
    """Sum ``blocks`` (n, k, k) into an (n_dof, n_dof) CSR matrix at ``dofs`` (n, k)."""
    k = dofs.shape[1]
    rows = np.broadcast_to(dofs[:, :, None], (dofs.shape[0], k, k)).ravel()
    cols = np.broadcast_to(dofs[:, None, :], (dofs.shape[0], k, k)).ravel()
    vals = blocks.ravel()
    keep = (rows >= 0) & (cols >= 0)
    return sp.coo_matrix((vals[keep], (rows[keep], cols[keep])), shape=(n_dof, n_dof)).tocsr()


def spring_blocks(k: FloatArray) -> FloatArray:
    """(n, 2, 2) stiffness of two-DOF springs: k·[[1, -1], [-1, 1]]."""
    return k[:, None, None] * np.array([[1.0, -1.0], [-1.0, 1.0]])


def symmetric_csr(A: sp.spmatrix) -> sp.csr_matrix:
    """(A + Aᵀ)/2 as a CSR matrix in canonical form (sorted indices, no duplicates)."""
    S = (0.5 * (A + A.T)).tocsr()
    S.sum_duplicates()
    S.sort_indices()
    return S


def assemble_sparse(mesh: FrameMesh) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """Global stiffness K [N/m …] and consistent mass M [kg …], each (n_dof, n_dof) CSR, of the
    beam-columns, bars and springs of a 2D or 3D mesh.

    Both are exactly symmetric (averaged with their transpose) and in canonical CSR form.
    """
    n = mesh.n_dof
    ke, me = element_matrices(mesh)
    K = scatter(ke, mesh.element_dofs, n)
    M = scatter(me, mesh.element_dofs, n)
    if mesh.trusses.shape[0]:
        kt, mt = truss_matrices(mesh)
        K = K + scatter(kt, mesh.truss_dofs, n)
        M = M + scatter(mt, mesh.truss_dofs, n)
    if mesh.springs.shape[0]:
        K = K + scatter(spring_blocks(mesh.spring_k), mesh.springs, n)
    return symmetric_csr(K), symmetric_csr(M)


def assemble(mesh: FrameMesh) -> tuple[FloatArray, FloatArray]:
    """Dense global stiffness K and consistent mass M, each (n_dof, n_dof): for small meshes."""
    K, M = assemble_sparse(mesh)
    return K.toarray(), M.toarray()
