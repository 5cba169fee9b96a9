"""Sparse assembly of a 3D frame: beam-columns, trusses and rotational springs.

Same scheme as :mod:`seisrack.fe.assembly` (one COO scatter of all (n_el, k, k) blocks,
restrained DOFs ``-1`` dropped, duplicates summed by COO → CSR), for the 12-DOF beam-columns
and 6-DOF trusses of :mod:`seisrack.fe.elements3d`.
"""

from __future__ import annotations

from typing import Any

import scipy.sparse as sp

from seisrack.fe.assembly import scatter, spring_blocks, symmetric_csr
from seisrack.fe.elements3d import beam_matrices_3d, truss_matrices_3d


def assemble_sparse_3d(mesh: Any) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """Global stiffness K and consistent mass M of a :class:`~seisrack.model.rack_mesh3d.Mesh3D`
    (or any object with the same arrays), each (n_dof, n_dof) CSR, symmetric and canonical."""
    n = mesh.n_dof
    X = mesh.nodes
    kb, mb = beam_matrices_3d(X[mesh.elements[:, 0]], X[mesh.elements[:, 1]], mesh.vecxz,
                              E=mesh.E, G=mesh.G, A=mesh.A, Iy=mesh.Iy, Iz=mesh.Iz, J=mesh.J,
                              rho=mesh.density, Ip=mesh.Ip)
    K = scatter(kb, mesh.element_dofs, n)
    M = scatter(mb, mesh.element_dofs, n)
    if mesh.trusses.shape[0]:
        kt, mt = truss_matrices_3d(X[mesh.trusses[:, 0]], X[mesh.trusses[:, 1]], E=mesh.truss_E,
                                   A=mesh.truss_A, rho=mesh.truss_density)
        K = K + scatter(kt, mesh.truss_dofs, n)
        M = M + scatter(mt, mesh.truss_dofs, n)
    if mesh.springs.shape[0]:
        K = K + scatter(spring_blocks(mesh.spring_k), mesh.springs, n)
    return symmetric_csr(K), symmetric_csr(M)
