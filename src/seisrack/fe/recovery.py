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


@dataclass(frozen=True)
class DesignOperators:
    """Sparse maps from free-DOF displacements to the member forces a rack designer checks.

    Each is ``(n_dof, k)`` CSR applied as ``U @ op`` (elastic forces only, conventions of the
    module docstring), with one label per column:

    Attributes:
        beam_moment, beam_shear: (n_dof, n_level·n_bay·2) bending moment [N·m] (member
            convention: ``-M_i`` at the left end, ``+M_j`` at the right end) and shear force [N]
            (``V_i`` at the left end, ``-V_j`` at the right end, the same internal shear sign
            on both ends) at the two ends of every beam; column ``(l·n_bay + b)·2 + e``,
            e = 0 left, 1 right. ``beam_labels``: ``"L{l}-B{b}-left"`` (1-based).
        connector_rotation, connector_moment: (n_dof, n_conn) relative rotation [rad] of each
            beam-to-upright spring and its moment ``k·rotation`` [N·m], signed like the beam
            end moment it carries (left end: beam minus upright rotation, right end: upright
            minus beam), so that in equilibrium the connector moment equals the beam end
            moment; ``connector_labels`` name that beam end (same labels as the beams).
        axial: (n_dof, n_upright·(n_level + 1)) upright axial force [N], tension positive, at
            the base (section 0) and at the top of the segment below each level (section l,
            l = 1..n_level); column ``u·(n_level + 1) + s``. ``axial_labels``: ``"U{u}-base"``,
            ``"U{u}-L{l}"``. The bending moment at the same sections is
            ``RecoveryOperators.base_moment`` / ``below``.
    """

    beam_moment: sp.csr_matrix
    beam_shear: sp.csr_matrix
    beam_labels: tuple[str, ...]
    connector_rotation: sp.csr_matrix
    connector_moment: sp.csr_matrix
    connector_labels: tuple[str, ...]
    axial: sp.csr_matrix
    axial_labels: tuple[str, ...]


def design_operators(model: Any) -> DesignOperators:
    """Build the :class:`DesignOperators` of a FrameModel (beam ends, connectors, upright N)."""
    mesh = _mesh(model)
    n = mesh.n_dof
    edofs = mesh.element_dofs
    c, s = mesh.direction_cosines
    kt = np.einsum("eij,ejk->eik", local_stiffness(mesh.E, mesh.A, mesh.I, mesh.lengths),
                   rotation(c, s))
    kind = np.asarray(model.element_kind)
    storey = np.asarray(model.element_storey)
    line = np.asarray(model.element_line)
    ux = np.asarray(model.upright_x, dtype=float)
    n_lev, n_bay = len(model.level_dofs), ux.size - 1
    xi = mesh.nodes[mesh.elements[:, 0], 0]
    xj = mesh.nodes[mesh.elements[:, 1], 0]
    tol = 1e-9 * max(1.0, float(np.ptp(ux)))
    beam = kind == 1
    # the end element of each beam: its i node on the left upright / its j node on the right
    left = np.full((n_lev, n_bay), -1, dtype=np.int64)
    right = np.full((n_lev, n_bay), -1, dtype=np.int64)
    for e in np.flatnonzero(beam & (np.abs(xi - ux[np.clip(line, 0, n_bay)]) < tol)):
        left[storey[e], line[e]] = e
    for e in np.flatnonzero(beam & (np.abs(xj - ux[np.clip(line + 1, 0, n_bay)]) < tol)):
        right[storey[e], line[e]] = e
    ends = np.stack([left, right], axis=-1).ravel()  # (l, b, e) order
    comp_m = np.tile([2, 5], n_lev * n_bay)
    comp_v = np.tile([1, 4], n_lev * n_bay)
    sign = np.tile([-1.0, 1.0], n_lev * n_bay)
    beam_m = _end_rows(kt, edofs, ends, comp_m, sign, n)
    beam_v = _end_rows(kt, edofs, ends, comp_v, -sign, n)
    beam_labels = tuple(f"L{lv + 1}-B{b + 1}-{side}" for lv in range(n_lev)
                        for b in range(n_bay) for side in ("left", "right"))

    # connectors: springs between two free rotation DOFs, the second on a beam end node
    node_of_rot = np.full(n + 1, -1, dtype=np.int64)
    rot = mesh.node_dofs[:, 2]
    node_of_rot[rot[rot >= 0]] = np.flatnonzero(rot >= 0)
    end_of_node: dict[int, int] = {}
    for k, e in enumerate(ends):
        if e >= 0:
            end_of_node[int(mesh.elements[e, k % 2])] = k
    springs = np.asarray(mesh.springs)
    cols, labels, ks = [], [], []
    for si, (a, b) in enumerate(springs):
        if a < 0 or b < 0:
            continue
        for up, bm in ((a, b), (b, a)):
            k = end_of_node.get(int(node_of_rot[bm]), -1)
            if k >= 0:
                cols.append((up, bm))
                labels.append(beam_labels[k])
                ks.append(float(mesh.spring_k[si]))
                break
    order = np.argsort([beam_labels.index(lab) for lab in labels], kind="stable")
    cols = [cols[i] for i in order]
    labels = [labels[i] for i in order]
    ks = np.asarray([ks[i] for i in order])
    nc = len(cols)
    r_rows = np.array([[bm, up] for up, bm in cols], dtype=np.int64).reshape(-1)
    r_cols = np.repeat(np.arange(nc), 2)
    # sign of the beam's member convention: the connector moment equals the beam end moment
    # (equilibrium of the beam end node, no external moment there) and the rotation follows it
    side = np.array([1.0 if lab.endswith("left") else -1.0 for lab in labels])
    r_vals = np.repeat(side, 2) * np.tile([1.0, -1.0], nc)
    conn_rot = _columns(r_rows, r_cols, r_vals, n, nc)
    conn_m = _columns(r_rows, r_cols, r_vals * np.repeat(ks, 2), n, nc)

    n_up = ux.size
    sec = np.empty((n_up, n_lev + 1), dtype=np.int64)
    sec[:, 0] = np.asarray(model.upright_base_elements)
    sec[:, 1:] = np.asarray(model.upright_below_elements)
    comp_n = np.tile(np.r_[0, np.full(n_lev, 3)], n_up)
    sign_n = np.tile(np.r_[-1.0, np.ones(n_lev)], n_up)  # tension positive: -N_i, +N_j
    axial = _end_rows(kt, edofs, sec.ravel(), comp_n, sign_n, n)
    axial_labels = tuple(f"U{u + 1}-" + ("base" if s_ == 0 else f"L{s_}")
                         for u in range(n_up) for s_ in range(n_lev + 1))
    return DesignOperators(beam_moment=beam_m, beam_shear=beam_v, beam_labels=beam_labels,
                           connector_rotation=conn_rot, connector_moment=conn_m,
                           connector_labels=tuple(labels), axial=axial,
                           axial_labels=axial_labels)


def _end_rows(kt: FloatArray, edofs: IntArray, elems: IntArray, comp: IntArray,
              factor: FloatArray, n_dof: int) -> sp.csr_matrix:
    """Like :func:`_element_rows` with a component and a factor per column."""
    ok = elems >= 0
    cols = np.repeat(np.flatnonzero(ok), 6)
    e = elems[ok]
    vals = factor[ok, None] * kt[e, comp[ok], :]
    return _columns(edofs[e].ravel(), cols, vals.ravel(), n_dof, elems.size)
