"""The frame mesh: nodes, two-node elements, their properties, the DOF map and springs.

This is the array-only description that assembly, recovery and plotting work on. Each node has
three DOF slots ``(ux, uy, rz)`` mapped to global DOF indices by ``node_dofs``; ``-1`` marks a
restrained (support) component. Two nodes may share DOF indices: a semi-rigid beam end is a
separate node sharing the translations of its upright node but owning its rotation.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


@dataclass(frozen=True)
class FrameMesh:
    """Array description of a plane frame.

    Attributes:
        nodes: (n_node, 2) [m] coordinates (x horizontal, y up).
        elements: (n_el, 2) int node indices (i, j).
        node_dofs: (n_node, 3) int global DOF of (ux, uy, rz); -1 = restrained.
        E: (n_el,) [Pa]; A: (n_el,) [m²]; I: (n_el,) [m⁴]; density: (n_el,) [kg/m³].
        springs: (n_spring, 2) int DOF pairs joined by a linear spring; -1 = ground.
        spring_k: (n_spring,) spring stiffness [N/m or N·m/rad].
        n_dof: number of free DOFs.
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

    @property
    def n_el(self) -> int:
        return int(self.elements.shape[0])

    @property
    def element_dofs(self) -> IntArray:
        """(n_el, 6) global DOFs of each element [ux_i, uy_i, rz_i, ux_j, uy_j, rz_j]; -1 fixed."""
        return self.node_dofs[self.elements].reshape(-1, 6)

    @property
    def lengths(self) -> FloatArray:
        d = self.nodes[self.elements[:, 1]] - self.nodes[self.elements[:, 0]]
        return np.hypot(d[:, 0], d[:, 1])

    @property
    def direction_cosines(self) -> tuple[FloatArray, FloatArray]:
        """(cos, sin) of each element axis, each (n_el,)."""
        d = self.nodes[self.elements[:, 1]] - self.nodes[self.elements[:, 0]]
        L = np.hypot(d[:, 0], d[:, 1])
        return d[:, 0] / L, d[:, 1] / L

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
    """Number the True entries of ``free`` (n_node, 3) consecutively, row-major; -1 elsewhere."""
    node_dofs = np.full(free.shape, -1, dtype=np.int64)
    n = int(free.sum())
    node_dofs[free] = np.arange(n)
    return node_dofs, n


def line_mesh(length: float, n_el: int, *, E: float, A: float, I: float, density: float,
              restraints: dict[int, tuple[bool, bool, bool]], angle: float = 0.0) -> FrameMesh:
    """A straight member of ``n_el`` equal elements from the origin at ``angle`` [rad].

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
