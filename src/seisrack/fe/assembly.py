"""Assembly: one COO scatter of all element (and spring) matrices into a global matrix.

As in scikit-fem, the loop (implicit, via broadcasting) runs over local entries, never over
elements: the (n_el, k, k) blocks and their (n_el, k) DOF tables are flattened into COO triplets,
restrained entries (DOF ``-1``) are dropped, and duplicates are summed by the COO → CSR
conversion.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from seisrack.fe.elements import element_matrices
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


def assemble(mesh: FrameMesh) -> tuple[FloatArray, FloatArray]:
    """Dense global stiffness K [N/m …] and consistent mass M [kg …], each (n_dof, n_dof)."""
    ke, me = element_matrices(mesh)
    blocks_k = np.concatenate([ke.reshape(-1, 36), _pad_springs(mesh)], axis=0)
    dofs = np.concatenate([mesh.element_dofs, _spring_dofs6(mesh)], axis=0)
    K = scatter(blocks_k.reshape(-1, 6, 6), dofs, mesh.n_dof).toarray()
    M = scatter(me, mesh.element_dofs, mesh.n_dof).toarray()
    return 0.5 * (K + K.T), 0.5 * (M + M.T)


def _pad_springs(mesh: FrameMesh) -> FloatArray:
    """Springs as 6x6 blocks (2x2 in the corner) so one scatter handles everything."""
    out = np.zeros((mesh.springs.shape[0], 6, 6))
    out[:, :2, :2] = spring_blocks(mesh.spring_k)
    return out.reshape(-1, 36)


def _spring_dofs6(mesh: FrameMesh) -> IntArray:
    out = np.full((mesh.springs.shape[0], 6), -1, dtype=np.int64)
    out[:, :2] = mesh.springs
    return out
