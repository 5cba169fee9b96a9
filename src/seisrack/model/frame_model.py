"""The compiled rack: a frozen bundle of arrays built by :func:`seisrack.model.compile_rack`.

One type for a plane (2D) and a space (3D) rack: the dimension is data, in the shapes of the
arrays (the mesh's nodes and DOFs per node, one influence vector per horizontal ground
direction, each pallet's supports and sliding directions). Field meanings are the contract in
``docs/dev/interfaces.md``. Only free DOFs appear in the matrices (supports removed). Nothing
here is mutated after compilation; results live elsewhere. The matrices are stored sparse
(CSR), so a warehouse rack of thousands of DOFs costs O(nnz) memory; dense views exist for small
racks.

Axes: x down-aisle (along the beams), y up and, in 3D, z cross-aisle (front frame z = 0, rear
frame z = ``depth``). Horizontal *directions* are numbered 0 (down-aisle, x) and 1 (cross-aisle,
z, 3D racks only).
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from functools import cached_property
from typing import Any

import numpy as np
import scipy.sparse as sp

from seisrack.dynamics.axial import AxialPDelta
from seisrack.fe.mesh import FloatArray, FrameMesh, IntArray
from seisrack.model.pallet_layout import PalletLayout
from seisrack.model.rack_mesh import BEAM, UPRIGHT  # noqa: F401  (re-exported)

_DENSE_CACHE = ("K", "M", "C")

CONNECTOR = 0  # hinge_kind: beam-to-upright connector
BASE_PLATE = 1  # hinge_kind: base plate

#: the names of the horizontal directions, by index
DIRECTIONS = ("down-aisle", "cross-aisle")


@dataclass(frozen=True, eq=False)
class FrameModel:
    """Compiled frame model of a rack, 2D or 3D.

    Matrices (free DOFs only):
        K_sparse, M_sparse, C_sparse: (n_dof, n_dof) ``scipy.sparse.csr_matrix``, symmetric,
            canonical (sorted indices, no duplicates), read-only [N/m, kg, N·s/m]. ``M_sparse``
            is the structure mass: members (consistent) plus each pallet's *vertical* mass on
            its support nodes' uy DOFs. The pallets' horizontal masses are not in it (they are
            the sliders); :meth:`total_mass_sparse` / :meth:`total_mass_matrix` add them back as
            if rigidly attached.
        K, M, C: dense read-only views, built on first access and cached (dropped when
            pickled): small racks and tests only.
        damping_coefficients: (a0, a1) with C = a0·M + a1·K_C, K_C the elastic stiffness
            K_E, or K_E + K_G (with P-Δ) when ``damping_stiffness_term`` is "with_p_delta"
            (``[damping] stiffness_term``; the same matrix without P-Δ).
        r_x, r_y: (n_dof,) influence vectors of down-aisle and vertical ground motion;
        r_z: (n_dof,) cross-aisle influence vector (None for a 2D rack).
        r_theta: (n_dof,) rigid rotation of the plan about the vertical through
            ``plan_centre`` (x_c, z_c) [m], the mass centre of the plan (3D only, else None).

    Pallets (in input order; ``k`` supports each: 1 in 2D, the front and the rear beam node in
    3D, the pallet's mass shared equally):
        pallet_node: (m, k) int support nodes; pallet_dofs: (m, k, n_dir) int their horizontal
            DOFs in each direction; pallet_vdof: (m, k) int their vertical DOFs.
        pallet_mass [kg], pallet_mu_static, pallet_mu_dynamic [-], pallet_friction_rate [s/m]
            (velocity dependence, 0: Coulomb): (m,).
        pallet_level, pallet_bay, pallet_slot, pallet_row: (m,) int, 0-based (slot: position
            within its bay and level, left to right; row: 0, or 1 on the rear row of a
            back-to-back rack); pallet_x: (m,) [m] position of its centre along the rack;
            pallet_depth, pallet_overhang: (m,) [m] (nan when not given).
        layout: free distances down-aisle, fall distances cross-aisle and down-aisle contacts
            (:class:`~seisrack.model.pallet_layout.PalletLayout`).

    Layout:
        mesh: the :class:`~seisrack.fe.mesh.FrameMesh` (nodes, members, bars, DOF map,
            springs).
        level_dofs: per direction, per beam level (bottom to top), the sorted horizontal DOFs
            of its nodes in that direction.
        level_y: (n_level,) [m]; upright_x: (n_line,) [m]; depth [m] (0 for a 2D rack).
        element_kind (UPRIGHT 0, BEAM 1), element_storey, element_line, element_side: (n_el,)
            int; truss_kind, truss_line: (n_tr,) int (see :class:`~seisrack.model.rack_mesh.
            RackMesh`).
        column_line, column_side: (n_col,) int upright columns (one per line in 2D, front and
            rear in 3D); base_nodes: (n_col,); level_nodes: (n_col, n_level);
            upright_base_elements: (n_col,); upright_below_elements, upright_above_elements:
            (n_col, n_level) (-1 above the top level).
        member_mass: [kg] all members and bars; g: [m/s²].
        n_rows: rows of upright frames (1, or 2 back to back); frame_z: (n_side,) [m] z of
            each upright side (column_side indexes it; (0.0,) in 2D).

    Hinges (every connection spring, connectors then base plates in mesh order; see
    :mod:`seisrack.dynamics.hinges`): hinge_dofs (n_h, 2) rotation DOFs (a, b), rotation
    u[a] − u[b] (beam end minus upright; b = -1, the ground, for a base plate); hinge_k
    [N·m/rad]; hinge_kind CONNECTOR / BASE_PLATE; hinge_node; hinge_law, hinge_par;
    hinge_yield_rotation [rad] (inf: elastic); hinge_rotation_gravity [rad].

    Second order: critical_load_factor, with ``[second_order] p_delta = true``, the lowest λ
    with det(K_E + λ K_G) = 0 for the gravity load (``K_sparse`` is then K_E + K_G); None when
    P-Δ is off.
    """

    mesh: FrameMesh
    K_sparse: sp.csr_matrix
    M_sparse: sp.csr_matrix
    C_sparse: sp.csr_matrix
    damping_coefficients: tuple[float, float]
    r_x: FloatArray
    r_y: FloatArray
    r_z: FloatArray | None
    r_theta: FloatArray | None
    plan_centre: tuple[float, float] | None
    pallet_node: IntArray
    pallet_dofs: IntArray
    pallet_vdof: IntArray
    pallet_mass: FloatArray
    pallet_mu_static: FloatArray
    pallet_mu_dynamic: FloatArray
    pallet_friction_rate: FloatArray
    pallet_level: IntArray
    pallet_bay: IntArray
    pallet_slot: IntArray
    pallet_row: IntArray
    pallet_x: FloatArray
    pallet_depth: FloatArray
    pallet_overhang: FloatArray
    layout: PalletLayout
    level_dofs: tuple[tuple[IntArray, ...], ...]
    level_y: FloatArray
    upright_x: FloatArray
    depth: float
    element_kind: IntArray
    element_storey: IntArray
    element_line: IntArray
    element_side: IntArray
    truss_kind: IntArray
    truss_line: IntArray
    column_line: IntArray
    column_side: IntArray
    base_nodes: IntArray
    level_nodes: IntArray
    upright_base_elements: IntArray
    upright_below_elements: IntArray
    upright_above_elements: IntArray
    member_mass: float
    g: float
    hinge_dofs: IntArray
    hinge_k: FloatArray
    hinge_kind: IntArray
    hinge_node: IntArray
    hinge_law: IntArray
    hinge_par: FloatArray
    hinge_yield_rotation: FloatArray
    hinge_rotation_gravity: FloatArray
    title: str = ""
    critical_load_factor: float | None = None
    damping_stiffness_term: str = "elastic"
    n_rows: int = 1
    frame_z: FloatArray | None = None
    #: ``[second_order] axial = "current"``: the P-Δ of the axial forces' change during the
    #: motion (:mod:`seisrack.dynamics.axial`), else None
    axial_p_delta: AxialPDelta | None = None

    # ------------------------------------------------------------------ dimension
    @property
    def ndm(self) -> int:
        """2 for a plane rack, 3 for a space rack."""
        return self.mesh.ndm

    @property
    def n_dir(self) -> int:
        """Number of horizontal ground directions: 1 (down-aisle) or 2 (and cross-aisle)."""
        return int(self.pallet_dofs.shape[2])

    @property
    def directions(self) -> tuple[str, ...]:
        """Names of the horizontal directions ("down-aisle"[, "cross-aisle"])."""
        return DIRECTIONS[:self.n_dir]

    @property
    def influence(self) -> tuple[FloatArray, ...]:
        """One horizontal influence vector per direction (r_x[, r_z])."""
        return (self.r_x,) if self.r_z is None else (self.r_x, self.r_z)

    # ------------------------------------------------------------------ sizes
    @property
    def nonlinear_hinges(self) -> bool:
        """True when some connection follows a nonlinear moment–rotation law."""
        return bool((self.hinge_law != 0).any())

    @property
    def n_dof(self) -> int:
        return int(self.K_sparse.shape[0])

    @property
    def n_pallets(self) -> int:
        return int(self.pallet_mass.shape[0])

    @property
    def n_level(self) -> int:
        return int(self.level_y.shape[0])

    @property
    def n_column(self) -> int:
        return int(self.base_nodes.shape[0])

    @property
    def nodes(self) -> FloatArray:
        """(n_node, ndm) [m]."""
        return self.mesh.nodes

    @property
    def elements(self) -> IntArray:
        """(n_el, 2) int."""
        return self.mesh.elements

    @property
    def node_dofs(self) -> IntArray:
        """(n_node, ndf) int, -1 = restrained."""
        return self.mesh.node_dofs

    def pallet_labels(self) -> list[str]:
        """``"L{level}-B{bay}-S{slot}"`` of each pallet (1-based), as every output names them;
        ``"R{row}-L…"`` on a back-to-back rack."""
        rows = self.pallet_row.tolist() if self.n_rows > 1 else [None] * self.n_pallets
        return [("" if r is None else f"R{r + 1}-") + f"L{lv + 1}-B{b + 1}-S{s + 1}"
                for r, lv, b, s in zip(rows, self.pallet_level.tolist(),
                                       self.pallet_bay.tolist(), self.pallet_slot.tolist(),
                                       strict=True)]

    # ------------------------------------------------------------------ matrices
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
        """(n_dof, n_dof) [kg] CSR: ``M_sparse`` plus the pallets' horizontal masses, shared
        by their supports, in every horizontal direction, rigidly attached (a fresh matrix)."""
        n, (_, k, nd) = self.n_dof, self.pallet_dofs.shape
        share = np.repeat(self.pallet_mass / k, k * nd)
        dofs = self.pallet_dofs.reshape(-1)
        on = dofs >= 0
        P = sp.csr_matrix((share[on], (dofs[on], dofs[on])), shape=(n, n))
        Mt = (self.M_sparse + P).tocsr()
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
    """Lock every array of a compiled model (it is shared, never mutated).

    Sparse matrices are locked through their ``data``, ``indices`` and ``indptr`` arrays; they
    are canonical, so SciPy never needs to sort or merge them in place.
    """

    def lock(value: Any) -> None:
        if isinstance(value, tuple):
            for v in value:
                lock(v)
        elif sp.issparse(value):
            for part in (value.data, value.indices, value.indptr):
                part.flags.writeable = False
        elif isinstance(value, np.ndarray):
            value.flags.writeable = False

    for obj in (model, model.mesh, model.layout):
        for f in fields(obj):
            lock(getattr(obj, f.name))
    return model
