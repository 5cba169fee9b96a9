"""The compiled rack: a frozen bundle of arrays built by :func:`seisrack.model.compile_rack`.

Field meanings are the contract in ``docs/dev/interfaces.md``. Only free DOFs appear in the
matrices (supports removed). Nothing here is mutated after compilation; results live elsewhere.
The matrices are stored sparse (CSR), so a warehouse rack of thousands of DOFs costs O(nnz)
memory; dense views exist for small racks and for code that has not moved to sparse yet.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from functools import cached_property
from typing import Any

import numpy as np
import scipy.sparse as sp

from seisrack.fe.mesh import FloatArray, FrameMesh, IntArray

_DENSE_CACHE = ("K", "M", "C")

UPRIGHT = 0
BEAM = 1

CONNECTOR = 0  # hinge_kind: beam-to-upright connector
BASE_PLATE = 1  # hinge_kind: base plate


@dataclass(frozen=True, eq=False)
class FrameModel:
    """Compiled 2D frame model of a rack.

    Matrices (free DOFs only):
        K_sparse, M_sparse, C_sparse: (n_dof, n_dof) ``scipy.sparse.csr_matrix``, symmetric,
            canonical (sorted indices, no duplicates), read-only [N/m, kg, N·s/m]. ``M_sparse``
            is the structure mass: members (consistent) plus each pallet's *vertical* mass on its
            node's uy DOF. The pallets' horizontal masses are not in it (they are the sliders);
            :meth:`total_mass_sparse` / :meth:`total_mass_matrix` add them back as if rigidly
            attached.
        K, M, C: (n_dof, n_dof) dense read-only ``ndarray`` views of the same matrices, built on
            first access and cached (dropped when pickled). For small racks, tests and callers
            not yet on sparse: at 5,000 DOFs each is 200 MB, so large-rack code must use the
            ``*_sparse`` fields.
        damping_coefficients: (a0, a1) with C = a0·M + a1·K.
        r_x, r_y: (n_dof,) influence vectors of horizontal / vertical ground motion.

    Pallets (in input order):
        pallet_dof: (n_pallet,) int horizontal DOF of the node each pallet rests on.
        pallet_vdof: (n_pallet,) int vertical DOF of that node.
        pallet_node: (n_pallet,) int node index.
        pallet_mass [kg], pallet_mu_static, pallet_mu_dynamic [-]: (n_pallet,).
        pallet_limit_neg, pallet_limit_pos: (n_pallet,) [m] allowed sliding distance towards -x
            and towards +x, both given as non-negative distances.

    Layout:
        mesh: nodes, elements, DOF map, section properties, springs (see FrameMesh).
        level_dofs: per beam level (bottom to top), the sorted horizontal DOFs of its nodes.
        level_y: (n_level,) [m]; upright_x: (n_upright,) [m].
        element_kind: (n_el,) int, UPRIGHT (0) or BEAM (1).
        element_storey: (n_el,) int 0-based storey (uprights) or level (beams).
        element_line: (n_el,) int 0-based upright column (uprights) or bay (beams).
        base_nodes: (n_upright,) int support nodes, left to right.
        level_nodes: (n_upright, n_level) int upright node at each level.
        upright_base_elements: (n_upright,) int lowest upright element of each column.
        upright_below_elements, upright_above_elements: (n_upright, n_level) int upright element
            ending at / starting from each level node (-1 above the top level).
        member_mass: [kg] total mass of all members (including mass on restrained DOFs).
        g: [m/s²].

    Hinges (every connection spring of ``mesh.springs``, connectors then base plates in mesh
    order; see :mod:`seisrack.dynamics.hinges`):
        hinge_dofs: (n_h, 2) int, rotation DOFs (a, b): the hinge rotation is u[a] − u[b]
            (beam end minus upright for a connector; b = -1, the ground, for a base plate).
        hinge_k: (n_h,) [N·m/rad] elastic stiffness (in K). hinge_kind: (n_h,) CONNECTOR or
            BASE_PLATE. hinge_node: (n_h,) int node of the hinge (the upright's node).
        hinge_law, hinge_par: (n_h,) int law code and (n_h, HYST_NPAR) parameters (elastic
            where ``[hysteresis]`` gives no law).
        hinge_yield_rotation: (n_h,) [rad] end of the elastic branch (``inf``: elastic).
        hinge_rotation_gravity: (n_h,) [rad] rotation under gravity (the static state a time
            history starts from; zeros when every connection is linear).
        pallet_friction_rate: (n_pallet,) [s/m] velocity dependence of friction (0: Coulomb).

    Second order:
        critical_load_factor: with ``[second_order] p_delta = true``, the lowest λ with
            det(K_E + λ K_G) = 0 for the gravity load (``K_sparse`` is then K_E + K_G, see
            :mod:`seisrack.fe.geometric`); ``inf`` if nothing is compressed; None when P-Δ
            is off (``K_sparse`` = K_E).
    """

    mesh: FrameMesh
    K_sparse: sp.csr_matrix
    M_sparse: sp.csr_matrix
    C_sparse: sp.csr_matrix
    damping_coefficients: tuple[float, float]
    r_x: FloatArray
    r_y: FloatArray
    pallet_dof: IntArray
    pallet_vdof: IntArray
    pallet_node: IntArray
    pallet_mass: FloatArray
    pallet_mu_static: FloatArray
    pallet_mu_dynamic: FloatArray
    pallet_limit_neg: FloatArray
    pallet_limit_pos: FloatArray
    level_dofs: tuple[IntArray, ...]
    level_y: FloatArray
    upright_x: FloatArray
    element_kind: IntArray
    element_storey: IntArray
    element_line: IntArray
    base_nodes: IntArray
    level_nodes: IntArray
    upright_base_elements: IntArray
    upright_below_elements: IntArray
    upright_above_elements: IntArray
    member_mass: float
    g: float
    title: str = ""
    critical_load_factor: float | None = None
    hinge_dofs: IntArray | None = None
    hinge_k: FloatArray | None = None
    hinge_kind: IntArray | None = None
    hinge_node: IntArray | None = None
    hinge_law: IntArray | None = None
    hinge_par: FloatArray | None = None
    hinge_yield_rotation: FloatArray | None = None
    hinge_rotation_gravity: FloatArray | None = None
    pallet_friction_rate: FloatArray | None = None

    @property
    def nonlinear_hinges(self) -> bool:
        """True when some connection follows a nonlinear moment–rotation law."""
        return self.hinge_law is not None and bool((self.hinge_law != 0).any())

    @property
    def n_dof(self) -> int:
        return int(self.K_sparse.shape[0])

    @property
    def n_pallets(self) -> int:
        return int(self.pallet_dof.shape[0])

    @property
    def nodes(self) -> FloatArray:
        """(n_node, 2) [m]."""
        return self.mesh.nodes

    @property
    def elements(self) -> IntArray:
        """(n_el, 2) int."""
        return self.mesh.elements

    @property
    def node_dofs(self) -> IntArray:
        """(n_node, 3) int, -1 = restrained."""
        return self.mesh.node_dofs

    @cached_property
    def K(self) -> FloatArray:  # noqa: N802
        """(n_dof, n_dof) [N/m] dense, read-only copy of ``K_sparse`` (small racks only)."""
        return _dense(self.K_sparse)

    @cached_property
    def M(self) -> FloatArray:  # noqa: N802
        """(n_dof, n_dof) [kg] dense, read-only copy of ``M_sparse`` (small racks only)."""
        return _dense(self.M_sparse)

    @cached_property
    def C(self) -> FloatArray:  # noqa: N802
        """(n_dof, n_dof) [N·s/m] dense, read-only copy of ``C_sparse`` (small racks only)."""
        return _dense(self.C_sparse)

    def total_mass_sparse(self) -> sp.csr_matrix:
        """(n_dof, n_dof) [kg] CSR: ``M_sparse`` plus the pallets' horizontal masses, rigidly
        attached (a fresh matrix)."""
        n = self.n_dof
        pallets = sp.csr_matrix((self.pallet_mass, (self.pallet_dof, self.pallet_dof)),
                                shape=(n, n))
        Mt = (self.M_sparse + pallets).tocsr()
        Mt.sum_duplicates()
        Mt.sort_indices()
        return Mt

    def total_mass_matrix(self) -> FloatArray:
        """(n_dof, n_dof) [kg] dense, writable: ``M`` plus the pallets' horizontal masses,
        rigidly attached (small racks; see :meth:`total_mass_sparse`)."""
        return self.total_mass_sparse().toarray()

    def __getstate__(self) -> dict[str, Any]:
        # The dense views are caches: do not ship them to worker processes.
        return {k: v for k, v in self.__dict__.items() if k not in _DENSE_CACHE}


def _dense(A: sp.spmatrix) -> FloatArray:
    out = A.toarray()
    out.flags.writeable = False
    return out


def read_only(model: Any) -> Any:
    """Lock every array of a compiled model, 2D or 3D (it is shared, never mutated).

    Sparse matrices are locked through their ``data``, ``indices`` and ``indptr`` arrays; they
    are canonical, so SciPy never needs to sort or merge them in place.
    """
    for obj in (model, model.mesh):
        for f in fields(obj):
            value = getattr(obj, f.name)
            for arr in value if isinstance(value, tuple) else (value,):
                if sp.issparse(arr):
                    for part in (arr.data, arr.indices, arr.indptr):
                        part.flags.writeable = False
                elif isinstance(arr, np.ndarray):
                    arr.flags.writeable = False
    return model
