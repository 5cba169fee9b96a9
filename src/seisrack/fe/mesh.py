"""The frame mesh: nodes, two-node members, their properties, the DOF map and springs.

This is the array-only description that assembly, recovery and plotting work on, for a plane
frame and a space frame alike: the dimension is data. A 2D mesh has nodes ``(n, 2)`` (x, y)
and three DOF slots per node ``(ux, uy, rz)``; a 3D mesh has nodes ``(n, 3)`` (x, y, z) and six
``(ux, uy, uz, rx, ry, rz)``. ``node_dofs`` maps each slot to a global DOF index, ``-1`` marking
a restrained component. Two nodes may share DOF indices: a semi-rigid beam end is a separate
node sharing the translations of its upright node but owning its rotation about the axis
normal to the down-aisle plane.

Only the element matrices (:mod:`seisrack.fe.elements`, :mod:`seisrack.fe.elements3d`, chosen by
:mod:`seisrack.fe.frame_elements`) know what the dimension changes.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


def _no_int(shape: tuple[int, ...] = (0, 2)) -> IntArray:
    return np.zeros(shape, dtype=np.int64)


def _no_float() -> FloatArray:
    return np.zeros(0)


@dataclass(frozen=True)
class FrameMesh:
    """Array description of a frame (beam-columns, pin-ended bars and linear springs).

    Attributes:
        nodes: (n_node, ndm) [m] coordinates (x down-aisle, y up and, in 3D, z cross-aisle).
        elements: (n_el, 2) int node indices (i, j) of the beam-columns.
        node_dofs: (n_node, ndf) int global DOF of each slot; -1 = restrained (ndf = 3 in 2D,
            6 in 3D).
        E: (n_el,) [Pa]; A: (n_el,) [m²]; I: (n_el,) [m⁴] second moment for bending in the
            down-aisle plane (``Iz`` of a 3D member: local z is the global z axis for every
            rack member); density: (n_el,) [kg/m³].
        springs: (n_spring, 2) int DOF pairs joined by a linear spring; -1 = ground.
        spring_k: (n_spring,) spring stiffness [N/m or N·m/rad].
        n_dof: number of free DOFs.
    3D members only (None or empty in 2D):
        G: (n_el,) [Pa] shear modulus; Iy: (n_el,) [m⁴] second moment for bending in the other
            principal plane; J: (n_el,) [m⁴] St Venant torsion constant; Ip: (n_el,) [m⁴] polar
            moment for the torsional inertia; vecxz: (n_el, 3) a vector in each member's local
            x–z plane (OpenSees' ``geomTransf`` convention, :mod:`seisrack.fe.elements3d`).
        trusses: (n_tr, 2) pin-ended bars (bracing) with truss_E [Pa], truss_A [m²],
            truss_density [kg/m³], each (n_tr,).
    """

    nodes: FloatArray
    elements: IntArray
    node_dofs: IntArray
    E: FloatArray
    A: FloatArray
    I: FloatArray
    density: FloatArray
    springs: IntArray
    spring_k: FloatArray
    n_dof: int
    G: FloatArray | None = None
    Iy: FloatArray | None = None
    J: FloatArray | None = None
    Ip: FloatArray | None = None
    vecxz: FloatArray | None = None
    trusses: IntArray = field(default_factory=_no_int)
    truss_E: FloatArray = field(default_factory=_no_float)
    truss_A: FloatArray = field(default_factory=_no_float)
    truss_density: FloatArray = field(default_factory=_no_float)

    @property
    def ndm(self) -> int:
        """Number of coordinates per node: 2 (plane frame) or 3 (space frame)."""
        return int(self.nodes.shape[1])

    @property
    def ndf(self) -> int:
        """DOF slots per node: 3 (ux, uy, rz) or 6 (ux, uy, uz, rx, ry, rz)."""
        return int(self.node_dofs.shape[1])

    @property
    def Iz(self) -> FloatArray:  # noqa: N802
        """(n_el,) [m⁴] the same as ``I`` (the 3D name)."""
        return self.I

    @property
    def n_el(self) -> int:
        return int(self.elements.shape[0])

    @property
    def element_dofs(self) -> IntArray:
        """(n_el, 2·ndf) global DOFs of each beam-column (node i's slots, then node j's)."""
        return self.node_dofs[self.elements].reshape(-1, 2 * self.ndf)

    @property
    def truss_dofs(self) -> IntArray:
        """(n_tr, 2·ndm) translation DOFs of each bar; -1 fixed."""
        return self.node_dofs[self.trusses][:, :, :self.ndm].reshape(-1, 2 * self.ndm)

    @property
    def lengths(self) -> FloatArray:
        d = self.nodes[self.elements[:, 1]] - self.nodes[self.elements[:, 0]]
        return np.linalg.norm(d, axis=1)

    @property
    def truss_lengths(self) -> FloatArray:
        d = self.nodes[self.trusses[:, 1]] - self.nodes[self.trusses[:, 0]]
        return np.linalg.norm(d, axis=1)

    @property
    def direction_cosines(self) -> tuple[FloatArray, FloatArray]:
        """(cos, sin) of each element axis in the x–y plane, each (n_el,)."""
        d = self.nodes[self.elements[:, 1]] - self.nodes[self.elements[:, 0]]
        L = np.linalg.norm(d, axis=1)
        return d[:, 0] / L, d[:, 1] / L

    @property
    def member_mass(self) -> float:
        """[kg] mass of every member and bar."""
        return float(np.sum(self.density * self.A * self.lengths)
                     + np.sum(self.truss_density * self.truss_A * self.truss_lengths))

    @property
    def ground_spring_k(self) -> FloatArray:
        """(n_dof,) summed stiffness of the springs tying each DOF to the ground."""
        out = np.zeros(self.n_dof)
        to_ground = self.springs[:, 1] < 0
        np.add.at(out, self.springs[to_ground, 0], self.spring_k[to_ground])
        to_ground = self.springs[:, 0] < 0
        np.add.at(out, self.springs[to_ground, 1], self.spring_k[to_ground])
        return out


def number_dofs(free: NDArray[np.bool_]) -> tuple[IntArray, int]:
    """Number the True entries of ``free`` (n_node, ndf) consecutively, row-major; -1 elsewhere."""
    node_dofs = np.full(free.shape, -1, dtype=np.int64)
    n = int(free.sum())
    node_dofs[free] = np.arange(n)
    return node_dofs, n


def line_mesh(length: float, n_el: int, *, E: float, A: float, I: float, density: float,
              restraints: dict[int, tuple[bool, bool, bool]], angle: float = 0.0) -> FrameMesh:
    """A straight plane member of ``n_el`` equal elements from the origin at ``angle`` [rad].

    ``restraints`` maps a node index (``-1`` for the last) to which of (ux, uy, rz) are fixed.
    Used for validation against closed-form beam solutions.
    """
    s = np.linspace(0.0, length, n_el + 1)
    nodes = np.column_stack([s * np.cos(angle), s * np.sin(angle)])
    elements = np.column_stack([np.arange(n_el), np.arange(1, n_el + 1)]).astype(np.int64)
    free = np.ones((n_el + 1, 3), dtype=bool)
    for node, fixed in restraints.items():
        free[node] = ~np.asarray(fixed, dtype=bool)
    node_dofs, n_dof = number_dofs(free)
    ones = np.ones(n_el)
    return FrameMesh(nodes=nodes, elements=elements, node_dofs=node_dofs, E=E * ones,
                     A=A * ones, I=I * ones, density=density * ones,
                     springs=np.zeros((0, 2), dtype=np.int64), spring_k=np.zeros(0),
                     n_dof=n_dof)
