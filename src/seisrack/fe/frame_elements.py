"""The element matrices of a mesh, whatever its dimension: the one place that picks the plane
(:mod:`seisrack.fe.elements`) or the space (:mod:`seisrack.fe.elements3d`) beam-column from the
mesh's data (``mesh.ndm``), as scikit-fem's element types do.

Every function returns one block per beam-column, ``(n_el, 2·ndf, 2·ndf)``, on the element's
DOFs ``mesh.element_dofs`` (node i's slots, then node j's).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from seisrack.fe import elements as e2
from seisrack.fe import elements3d as e3
from seisrack.fe.elements import to_global
from seisrack.fe.mesh import FloatArray


def local_frames(mesh: Any) -> FloatArray:
    """(n_el, 2·ndf, 2·ndf) transformation T of each beam-column, u_local = T u_global."""
    if mesh.ndm == 2:
        c, s = mesh.direction_cosines
        return e2.rotation(c, s)
    X = mesh.nodes
    return e3.transformation_3d(e3.local_axes(X[mesh.elements[:, 0]], X[mesh.elements[:, 1]],
                                              mesh.vecxz))


def local_stiffness(mesh: Any) -> FloatArray:
    """(n_el, 2·ndf, 2·ndf) stiffness in the members' local axes [N/m, N, N·m]."""
    L = mesh.lengths
    if mesh.ndm == 2:
        return e2.local_stiffness(mesh.E, mesh.A, mesh.I, L)
    return e3.local_stiffness_3d(mesh.E, mesh.G, mesh.A, mesh.Iy, mesh.I, mesh.J, L)


def local_mass(mesh: Any) -> FloatArray:
    """(n_el, 2·ndf, 2·ndf) consistent mass in the members' local axes [kg, kg·m, kg·m²]."""
    L = mesh.lengths
    if mesh.ndm == 2:
        return e2.local_consistent_mass(mesh.density * mesh.A, L)
    return e3.local_consistent_mass_3d(mesh.density, mesh.A, mesh.Ip, L)


def element_matrices(mesh: Any) -> tuple[FloatArray, FloatArray]:
    """Global-axis stiffness and consistent mass of every beam-column, each
    (n_el, 2·ndf, 2·ndf)."""
    T = local_frames(mesh)
    return to_global(local_stiffness(mesh), T), to_global(local_mass(mesh), T)


def truss_matrices(mesh: Any) -> tuple[FloatArray, FloatArray]:
    """Global stiffness and consistent mass of the pin-ended bars, (n_tr, 2·ndm, 2·ndm) each
    (none in a plane rack: the 2D model has no bracing bars)."""
    X = mesh.nodes
    return e3.truss_matrices_3d(X[mesh.trusses[:, 0]], X[mesh.trusses[:, 1]], E=mesh.truss_E,
                                A=mesh.truss_A, rho=mesh.truss_density)


@dataclass(frozen=True)
class EndForceMaps:
    """What force recovery needs of every member, computed in one pass per dimension.

    T: (n_el, 2·ndf, 2·ndf) transformation, u_local = T u_global; kt: (n_el, 2·ndf, 2·ndf)
    ``k_local · T``, local end forces from global end displacements; bars: (n_tr, 2·ndm,
    2·ndm) global stiffness of the pin-ended bars (none in a plane rack).
    """

    T: FloatArray
    kt: FloatArray
    bars: FloatArray


def end_force_maps(mesh: Any) -> EndForceMaps:
    """:class:`EndForceMaps` of ``mesh`` (the plane or the space beam-column, by ``mesh.ndm``)."""
    T = local_frames(mesh)
    bars = np.zeros((0, 4, 4)) if mesh.ndm == 2 else truss_matrices(mesh)[0]
    return EndForceMaps(T=T, kt=np.einsum("eij,ejk->eik", local_stiffness(mesh), T), bars=bars)
