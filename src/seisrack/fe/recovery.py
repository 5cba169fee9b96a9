"""Force recovery from nodal displacements: element end forces, support reactions, upright moments.

Sign conventions
----------------
- Element end forces are the forces *acting on the element* at its ends, in the element's local
  axes, ordered ``[N_i, V_i, M_i, N_j, V_j, M_j]`` (f = k_local · T · u_e). An upright runs bottom
  (i) to top (j), a beam left (i) to right (j). Axial tension is ``-N_i = N_j > 0``.
- Bending moments (:func:`upright_moments`) use the member convention M(x) with the internal
  moment at end i equal to ``-M_i`` and at end j equal to ``+M_j``, so a column in single
  curvature has one sign over its length.
- Reactions are the forces the supports exert *on the structure*, global axes ``(Fx, Fy, M)``.
  Under a static load P, ``Σ Fx + Px = 0``; base shear is ``-Σ Fx``.

Only the elastic (stiffness) forces are recovered: for a dynamic history ``U`` of displacements
relative to the ground these are the internal forces of the frame. Damping forces (C·v) and the
inertia coupled onto restrained DOFs by the consistent mass are not included.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.sparse as sp

from seisrack.fe.elements import local_stiffness, rotation
from seisrack.fe.mesh import FloatArray, FrameMesh, IntArray


def _mesh(model: Any) -> FrameMesh:
    return model if isinstance(model, FrameMesh) else model.mesh


def _as_2d(U: FloatArray) -> tuple[FloatArray, bool]:
    U = np.asarray(U, dtype=float)
    return (U[None, :], True) if U.ndim == 1 else (U, False)


def element_end_forces(model: Any, U: FloatArray) -> FloatArray:
    """Local end forces of every element.

    Args:
        model: a FrameModel (or FrameMesh).
        U: (n_t, n_dof) or (n_dof,) [m, rad] displacements of the free DOFs.

    Returns:
        (n_t, n_el, 6) [N, N, N·m] (or (n_el, 6) for 1-D ``U``), see the module conventions.
    """
    mesh = _mesh(model)
    U2, squeeze = _as_2d(U)
    # Append a zero column so restrained DOFs (-1) read 0.
    padded = np.concatenate([U2, np.zeros((U2.shape[0], 1))], axis=1)
    ue = padded[:, mesh.element_dofs]  # (n_t, n_el, 6), -1 -> last column
    c, s = mesh.direction_cosines
    T = rotation(c, s)
    k = local_stiffness(mesh.E, mesh.A, mesh.I, mesh.lengths)
    kt = np.einsum("eij,ejk->eik", k, T)
    f = np.einsum("eik,tek->tei", kt, ue)
    return f[0] if squeeze else f


def _global_end_forces(mesh: FrameMesh, f_local: FloatArray) -> FloatArray:
    """(n_t, n_el, 6) end forces in global axes: Tᵀ f."""
    c, s = mesh.direction_cosines
    T = rotation(c, s)
    return np.einsum("eji,tej->tei", T, f_local)


def nodal_element_forces(model: Any, U: FloatArray) -> FloatArray:
    """(n_t, n_node, 3) sum over elements of the global end forces acting on them at each node."""
    mesh = _mesh(model)
    U2, _ = _as_2d(U)
    fg = _global_end_forces(mesh, element_end_forces(mesh, U2))
    out = np.zeros((U2.shape[0], mesh.nodes.shape[0], 3))
    np.add.at(out, (slice(None), mesh.elements[:, 0]), fg[:, :, :3])
    np.add.at(out, (slice(None), mesh.elements[:, 1]), fg[:, :, 3:])
    return out


def support_reactions(model: Any, U: FloatArray, nodes: IntArray) -> FloatArray:
    """Reactions (Fx, Fy, M) at support ``nodes``: (n_t, n_support, 3).

    A restrained component's reaction is the sum of the element end forces at the node (nodal
    equilibrium). A free component tied to the ground by a spring (a semi-rigid base) reacts with
    the spring force ``-k·u``; a free component without a spring reacts with 0.
    """
    mesh = _mesh(model)
    U2, squeeze = _as_2d(U)
    nodes = np.asarray(nodes, dtype=np.int64)
    r = nodal_element_forces(mesh, U2)[:, nodes, :]
    dofs = mesh.node_dofs[nodes]  # (n_sup, 3)
    free = dofs >= 0
    kg = mesh.ground_spring_k
    spring = -kg[np.where(free, dofs, 0)] * U2[:, np.where(free, dofs, 0)]
    r = np.where(free[None], spring, r)
    return r[0] if squeeze else r


def base_reactions(model: Any, U: FloatArray) -> FloatArray:
    """Reactions (Fx [N], Fy [N], M [N·m]) at each rack base, left to right: (n_t, n_base, 3).

    Includes the base-spring moment for semi-rigid bases.
    Base shear is ``-reactions[..., 0].sum(-1)``.
    """
    return support_reactions(model, U, model.base_nodes)


@dataclass(frozen=True)
class UprightMoments:
    """Upright bending moments [N·m] (member convention, see module docstring).

    Attributes:
        base: (n_t, n_upright) at the foot of each upright.
        below: (n_t, n_upright, n_level) at the top of the upright segment just below each level.
        above: (n_t, n_upright, n_level) at the bottom of the segment just above (0 at the top).
    """

    base: FloatArray
    below: FloatArray
    above: FloatArray

    def peak_abs(self) -> FloatArray:
        """(n_t, n_upright) largest |moment| at the base and connections of each upright."""
        return np.maximum(np.abs(self.base), np.abs(np.concatenate(
            [self.below, self.above], axis=2)).max(axis=2))


def upright_moments(model: Any, U: FloatArray) -> UprightMoments:
    """Upright end moments at the base and at the beam connections, for (n_t, n_dof) ``U``."""
    U2, _ = _as_2d(U)
    f = element_end_forces(model, U2)
    base = -f[:, model.upright_base_elements, 2]
    below = f[:, model.upright_below_elements, 5]
    above_idx = model.upright_above_elements
    above = np.where(above_idx >= 0, -f[:, np.maximum(above_idx, 0), 2], 0.0)
    return UprightMoments(base=base, below=below, above=above)


@dataclass(frozen=True)
class RecoveryOperators:
    """Sparse linear maps from free-DOF displacements to rack forces: ``U @ op``.

    For ``U: (n_t, n_dof)`` [m, rad] each product is exactly the corresponding function of this
    module evaluated on ``U`` (elastic forces only, same sign conventions):

    Attributes:
        base_shear: (n_dof, 1) CSR; ``U @ base_shear`` (n_t, 1) [N] is the base shear
            ``-base_reactions(model, U)[..., 0].sum(-1)``.
        base_moment: (n_dof, n_upright) CSR; ``U @ base_moment`` [N·m] is
            ``upright_moments(model, U).base``.
        below, above: (n_dof, n_upright·n_level) CSR; ``U @ below`` [N·m] is
            ``upright_moments(model, U).below`` flattened over (upright, level), upright-major
            (column ``u·n_level + l``); likewise ``above`` (columns above the top level are 0).
        n_upright, n_level: the shapes to unflatten with.

    Each column has at most a dozen non-zeros (one element's stiffness row), so the operators
    cost O(n_upright·n_level) memory, unlike evaluating the functions on ``np.eye(n_dof)``.
    """

    base_shear: sp.csr_matrix
    base_moment: sp.csr_matrix
    below: sp.csr_matrix
    above: sp.csr_matrix
    n_upright: int
    n_level: int

    def upright_moments(self, U: FloatArray) -> UprightMoments:
        """:class:`UprightMoments` of ``U: (n_t, n_dof)`` through the operators."""
        U2, _ = _as_2d(U)
        shape = (U2.shape[0], self.n_upright, self.n_level)
        return UprightMoments(base=np.asarray(U2 @ self.base_moment),
                              below=np.asarray(U2 @ self.below).reshape(shape),
                              above=np.asarray(U2 @ self.above).reshape(shape))


def recovery_operators(model: Any) -> RecoveryOperators:
    """Build the :class:`RecoveryOperators` of a FrameModel from its element stiffness rows."""
    mesh = _mesh(model)
    n = mesh.n_dof
    edofs = mesh.element_dofs  # (n_el, 6)
    c, s = mesh.direction_cosines
    T = rotation(c, s)
    kt = np.einsum("eij,ejk->eik", local_stiffness(mesh.E, mesh.A, mesh.I, mesh.lengths), T)
    kg = np.einsum("eji,ejk->eik", T, kt)  # Tᵀ k T: global end forces from u_e

    # Base shear: -Σ Fx over the base nodes. A restrained ux reacts with the sum of the global
    # x end forces of the elements meeting there; a free ux with its ground spring, -k·u.
    base = np.asarray(model.base_nodes, dtype=np.int64)
    is_base = np.zeros(mesh.nodes.shape[0], dtype=bool)
    is_base[base] = True
    fixed_x = mesh.node_dofs[:, 0] < 0
    rows, vals = [], []
    for end in (0, 1):  # the two ends of every element, not a loop over elements
        hit = is_base[mesh.elements[:, end]] & fixed_x[mesh.elements[:, end]]
        rows.append(edofs[hit])
        vals.append(-kg[hit, 3 * end, :])  # minus: base shear = -Σ Fx
    free_x = mesh.node_dofs[base, 0][mesh.node_dofs[base, 0] >= 0]
    rows.append(free_x[:, None])
    vals.append(mesh.ground_spring_k[free_x][:, None])  # -(-k·u)
    shear = _columns(np.concatenate([r.ravel() for r in rows]),
                     np.zeros(sum(r.size for r in rows), dtype=np.int64),
                     np.concatenate([v.ravel() for v in vals]), n, 1)

    n_up, n_lev = np.asarray(model.upright_below_elements).shape
    base_m = _element_rows(kt, edofs, np.asarray(model.upright_base_elements), 2, -1.0, n)
    below = _element_rows(kt, edofs, np.asarray(model.upright_below_elements).ravel(), 5, 1.0, n)
    above = _element_rows(kt, edofs, np.asarray(model.upright_above_elements).ravel(), 2, -1.0, n)
    return RecoveryOperators(base_shear=shear, base_moment=base_m, below=below, above=above,
                             n_upright=int(n_up), n_level=int(n_lev))


def _element_rows(kt: FloatArray, edofs: IntArray, elems: IntArray, comp: int, factor: float,
                  n_dof: int) -> sp.csr_matrix:
    """(n_dof, len(elems)) CSR: column j = factor · row ``comp`` of k·T of element ``elems[j]``
    (a zero column where ``elems[j] < 0``)."""
    ok = elems >= 0
    cols = np.repeat(np.flatnonzero(ok), 6)
    e = elems[ok]
    return _columns(edofs[e].ravel(), cols, factor * kt[e, comp, :].ravel(), n_dof, elems.size)


def _columns(rows: IntArray, cols: IntArray, vals: FloatArray, n_dof: int, n_col: int
             ) -> sp.csr_matrix:
    """Sum COO triplets into an (n_dof, n_col) CSR, dropping restrained rows (-1)."""
    keep = rows >= 0
    out = sp.coo_matrix((vals[keep], (rows[keep], cols[keep])), shape=(n_dof, n_col)).tocsr()
    out.sum_duplicates()
    out.eliminate_zeros()
    out.sort_indices()
    return out
