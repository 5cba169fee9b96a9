"""The compiled 3D rack: a frozen bundle of arrays built by :func:`compile_rack_3d`.

Global axes: x down-aisle, y up, z cross-aisle (front frame z = 0, rear frame z = depth).
Only free DOFs appear in the matrices. Nothing here is mutated after compilation.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Any

import numpy as np
import scipy.sparse as sp

from seisrack.fe.mesh import FloatArray, IntArray
from seisrack.model.frame_model import FrameModel
from seisrack.model.pallet_layout3d import PalletLayout3D
from seisrack.model.rack_mesh3d import Mesh3D


@dataclass(frozen=True, eq=False)
class FrameModel3D:
    """Compiled 3D model of a rack (6 DOFs per node: ux, uy, uz, rx, ry, rz).

    Matrices (free DOFs only, CSR, symmetric, canonical, read-only):
        K_sparse [N/m …], M_sparse [kg …], C_sparse [N·s/m …]; ``M_sparse`` holds the members
        (consistent mass) and the pallets' *vertical* mass; the pallets' horizontal masses are
        added by :meth:`total_mass_sparse` as if rigidly attached.
        damping_coefficients: (a0, a1) with C = a0·M + a1·K.
        r_x, r_y, r_z: (n_dof,) influence vectors of ground motion down-aisle, vertical and
        cross-aisle (1 on the translations of every free node in that direction).
        r_theta: (n_dof,) rigid rotation of the plan about the vertical axis through
        ``plan_centre`` (ux = z − z_c, uz = −(x − x_c), ry = 1: a unit rotation about +y).
        plan_centre: (x_c, z_c) [m], centre of the horizontal mass (pallets attached).

    Pallets (input order), each resting on the front and the rear beam of its bay and level at
    the beam node nearest its centre, half its mass on each (point masses; the pallet's own
    rotary inertia is not modelled yet):
        pallet_node, pallet_dof_x, pallet_dof_z, pallet_vdof: (n_pallet, 2) int, [front, rear].
        pallet_mass [kg], pallet_mu_static, pallet_mu_dynamic [-]: (n_pallet,).
        pallet_depth, pallet_overhang: (n_pallet,) [m], nan when not given.
        layout: fall distances cross-aisle and down-aisle contact gaps
        (:class:`~seisrack.model.pallet_layout3d.PalletLayout3D`).
        pallet_level, pallet_bay: (n_pallet,) 1-based, as in the TOML.

    Layout:
        mesh: the :class:`~seisrack.model.rack_mesh3d.Mesh3D`.
        element_kind (UPRIGHT 0, BEAM 1), element_storey, element_line, element_side
        (0 front, 1 rear): (n_el,) int. truss_kind (BRACING 2, SPINE 3), truss_line: (n_tr,).
        base_nodes: (n_line, 2) int; level_nodes: (n_line, 2, n_level) int.
        level_dofs_x, level_dofs_z: per level, the sorted ux / uz DOFs of its nodes.
        level_y: (n_level,) [m]; upright_x: (n_line,) [m]; depth [m].
        member_mass [kg] (all members, bracing included); g [m/s²].
    """

    mesh: Mesh3D
    K_sparse: sp.csr_matrix
    M_sparse: sp.csr_matrix
    C_sparse: sp.csr_matrix
    damping_coefficients: tuple[float, float]
    r_x: FloatArray
    r_y: FloatArray
    r_z: FloatArray
    r_theta: FloatArray
    plan_centre: tuple[float, float]
    pallet_node: IntArray
    pallet_dof_x: IntArray
    pallet_dof_z: IntArray
    pallet_vdof: IntArray
    pallet_mass: FloatArray
    pallet_mu_static: FloatArray
    pallet_mu_dynamic: FloatArray
    pallet_depth: FloatArray
    pallet_overhang: FloatArray
    pallet_level: IntArray
    pallet_bay: IntArray
    element_kind: IntArray
    element_storey: IntArray
    element_line: IntArray
    element_side: IntArray
    truss_kind: IntArray
    truss_line: IntArray
    base_nodes: IntArray
    level_nodes: IntArray
    level_dofs_x: tuple[IntArray, ...]
    level_dofs_z: tuple[IntArray, ...]
    level_y: FloatArray
    upright_x: FloatArray
    depth: float
    member_mass: float
    g: float
    title: str = ""
    critical_load_factor: float | None = None
    layout: PalletLayout3D | None = None

    is_3d = True

    def __getattr__(self, name: str) -> Any:
        # Only reached when normal lookup fails: a 2D-only attribute (pallet_dof, level_dofs,
        # hinge_dofs, ...) asked by the 2D time history, report or export stops with a clear
        # InputError instead of a traceback (see seisrack.model.dimension.require_2d).
        if name in _2D_ONLY:
            from seisrack.model.dimension import require_2d

            require_2d(self)
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    @property
    def n_dof(self) -> int:
        return int(self.K_sparse.shape[0])

    @property
    def n_pallets(self) -> int:
        return int(self.pallet_mass.shape[0])

    @property
    def nodes(self) -> FloatArray:
        """(n_node, 3) [m]."""
        return self.mesh.nodes

    @property
    def node_dofs(self) -> IntArray:
        """(n_node, 6) int, -1 = restrained."""
        return self.mesh.node_dofs

    def total_mass_sparse(self) -> sp.csr_matrix:
        """(n_dof, n_dof) [kg] CSR: ``M_sparse`` plus the pallets' horizontal masses (half on
        the front and half on the rear beam node, in x and z), rigidly attached."""
        n = self.n_dof
        half = np.repeat(0.5 * self.pallet_mass, 2)
        dofs = np.concatenate([self.pallet_dof_x.ravel(), self.pallet_dof_z.ravel()])
        P = sp.csr_matrix((np.concatenate([half, half]), (dofs, dofs)), shape=(n, n))
        Mt = (self.M_sparse + P).tocsr()
        Mt.sum_duplicates()
        Mt.sort_indices()
        return Mt


_2D_ONLY = frozenset(f.name for f in fields(FrameModel)) - frozenset(
    f.name for f in fields(FrameModel3D)) | {"total_mass_matrix", "K", "M", "C",
                                             "nonlinear_hinges", "elements"}
