"""The compiled rack: a frozen bundle of arrays built by :func:`seisrack.model.compile_rack`.

Field meanings are the contract in ``docs/dev/interfaces.md``. Only free DOFs appear in the
matrices (supports removed). Nothing here is mutated after compilation; results live elsewhere.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from seisrack.fe.mesh import FloatArray, FrameMesh, IntArray

UPRIGHT = 0
BEAM = 1


@dataclass(frozen=True, eq=False)
class FrameModel:
    """Compiled 2D frame model of a rack.

    Matrices (free DOFs only):
        K, M, C: (n_dof, n_dof) [N/m, kg, N·s/m]. ``M`` is the structure mass: members
            (consistent) plus each pallet's *vertical* mass on its node's uy DOF. The pallets'
            horizontal masses are not in ``M`` (they are the sliders);
            :meth:`total_mass_matrix` adds them back as if rigidly attached.
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
    """

    mesh: FrameMesh
    K: FloatArray
    M: FloatArray
    C: FloatArray
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

    @property
    def n_dof(self) -> int:
        return int(self.K.shape[0])

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

    def total_mass_matrix(self) -> FloatArray:
        """(n_dof, n_dof) [kg]: ``M`` plus the pallets' horizontal masses, rigidly attached."""
        Mt = self.M.copy()
        np.add.at(Mt, (self.pallet_dof, self.pallet_dof), self.pallet_mass)
        return Mt
