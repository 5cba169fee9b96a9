"""Force recovery from nodal displacements: element end forces, support reactions, upright
moments, and the sparse operators that give them, for a 2D or a 3D rack.

Sign conventions
----------------
- Element end forces are the forces *acting on the element* at its ends, in the element's local
  axes (f = k_local · T · u_e): ``[N_i, V_i, M_i, N_j, V_j, M_j]`` for a plane member,
  ``[N_i, Vy_i, Vz_i, T_i, My_i, Mz_i, N_j, …]`` for a space member. An upright runs bottom (i)
  to top (j), a beam left (i) to right (j). Axial tension is ``-N_i = N_j > 0``.
- A *bending plane* goes with each horizontal direction: the down-aisle plane x–y (the 2D
  frame's plane; moment about z, ``M`` in 2D, ``Mz`` of a space member, whose local z is the
  global z for every rack member) and, in 3D, the cross-aisle plane z–y (moment ``My`` of an
  upright). Bending moments use the member convention M(x) with the internal moment at end i
  equal to ``-M_i`` and at end j equal to ``+M_j``, so a column in single curvature has one sign
  over its length.
- Reactions are the forces the supports exert *on the structure*, global axes, one per DOF slot
  of the node (``(Fx, Fy, M)`` in 2D). Under a static load P, ``Σ Fx + Px = 0``; base shear in a
  direction is minus the sum of the reactions along it.

Only the elastic (stiffness) forces are recovered: for a dynamic history ``U`` of displacements
relative to the ground these are the internal forces of the frame. Damping forces (C·v) and the
inertia coupled onto restrained DOFs by the consistent mass are not included.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.sparse as sp

from seisrack.fe.frame_elements import EndForceMaps, end_force_maps
from seisrack.fe.mesh import FloatArray, FrameMesh, IntArray

#: local end-force components per mesh dimension: axial (i, j), and per bending plane
#: (direction 0 down-aisle, 1 cross-aisle) the shear and the moment (i, j)
_AXIAL = {2: (0, 3), 3: (0, 6)}
_SHEAR = {2: ((1, 4),), 3: ((1, 7), (2, 8))}
_MOMENT = {2: ((2, 5),), 3: ((5, 11), (4, 10))}
#: the node slot of the translation along each horizontal direction
_SLOT = {2: (0,), 3: (0, 2)}


def _mesh(model: Any) -> FrameMesh:
    return model if isinstance(model, FrameMesh) else model.mesh


def _as_2d(U: FloatArray) -> tuple[FloatArray, bool]:
    U = np.asarray(U, dtype=float)
    return (U[None, :], True) if U.ndim == 1 else (U, False)


def element_end_forces(model: Any, U: FloatArray) -> FloatArray:
    """Local end forces of every beam-column.

    Args:
        model: a FrameModel (or FrameMesh), 2D or 3D.
        U: (n_t, n_dof) or (n_dof,) [m, rad] displacements of the free DOFs.

    Returns:
        (n_t, n_el, 2·ndf) [N, N·m] (or (n_el, 2·ndf) for 1-D ``U``), see the module conventions.
    """
    mesh = _mesh(model)
    U2, squeeze = _as_2d(U)
    # Append a zero column so restrained DOFs (-1) read 0.
    padded = np.concatenate([U2, np.zeros((U2.shape[0], 1))], axis=1)
    ue = padded[:, mesh.element_dofs]  # (n_t, n_el, 2 ndf), -1 -> last column
    f = np.einsum("eik,tek->tei", end_force_maps(mesh).kt, ue)
    return f[0] if squeeze else f


def nodal_element_forces(model: Any, U: FloatArray) -> FloatArray:
    """(n_t, n_node, ndf) sum over members and bars of the global end forces acting on them at
    each node."""
    mesh = _mesh(model)
    U2, _ = _as_2d(U)
    nf = mesh.ndf
    maps = end_force_maps(mesh)
    padded = np.concatenate([U2, np.zeros((U2.shape[0], 1))], axis=1)
    f = np.einsum("eik,tek->tei", maps.kt, padded[:, mesh.element_dofs])
    fg = np.einsum("eji,tej->tei", maps.T, f)
    out = np.zeros((U2.shape[0], mesh.nodes.shape[0], nf))
    np.add.at(out, (slice(None), mesh.elements[:, 0]), fg[:, :, :nf])
    np.add.at(out, (slice(None), mesh.elements[:, 1]), fg[:, :, nf:])
    if mesh.trusses.shape[0]:
        ft = np.einsum("eik,tek->tei", maps.bars, padded[:, mesh.truss_dofs])
        nd = mesh.ndm
        np.add.at(out, (slice(None), mesh.trusses[:, 0], slice(0, nd)), ft[:, :, :nd])
        np.add.at(out, (slice(None), mesh.trusses[:, 1], slice(0, nd)), ft[:, :, nd:])
    return out


def support_reactions(model: Any, U: FloatArray, nodes: IntArray) -> FloatArray:
    """Reactions at support ``nodes``, one per DOF slot: (n_t, n_support, ndf).

    A restrained component's reaction is the sum of the member end forces at the node (nodal
    equilibrium). A free component tied to the ground by a spring (a semi-rigid base) reacts with
    the spring force ``-k·u``; a free component without a spring reacts with 0.
    """
    mesh = _mesh(model)
    U2, squeeze = _as_2d(U)
    nodes = np.asarray(nodes, dtype=np.int64)
    r = nodal_element_forces(mesh, U2)[:, nodes, :]
    dofs = mesh.node_dofs[nodes]  # (n_sup, ndf)
    free = dofs >= 0
    kg = mesh.ground_spring_k
    spring = -kg[np.where(free, dofs, 0)] * U2[:, np.where(free, dofs, 0)]
    r = np.where(free[None], spring, r)
    return r[0] if squeeze else r


def base_reactions(model: Any, U: FloatArray) -> FloatArray:
    """Reactions at each rack base (upright columns in order), one per DOF slot:
    (n_t, n_column, ndf); in 2D ``(Fx [N], Fy [N], M [N·m])``. Includes the base-spring
    moments of semi-rigid bases. Base shear down-aisle is ``-reactions[..., 0].sum(-1)``."""
    return support_reactions(model, U, model.base_nodes)


@dataclass(frozen=True)
class UprightMoments:
    """Upright bending moments [N·m] in one bending plane (member convention).

    Attributes:
        base: (n_t, n_column) at the foot of each upright column.
        below: (n_t, n_column, n_level) at the top of the upright segment just below each level.
        above: (n_t, n_column, n_level) at the bottom of the segment just above (0 at the top).
    """

    base: FloatArray
    below: FloatArray
    above: FloatArray

    def peak_abs(self) -> FloatArray:
        """(n_t, n_column) largest |moment| at the base and connections of each upright."""
        return np.maximum(np.abs(self.base), np.abs(np.concatenate(
            [self.below, self.above], axis=2)).max(axis=2))


def upright_moments(model: Any, U: FloatArray, direction: int = 0) -> UprightMoments:
    """Upright end moments at the base and at the beam connections in the bending plane of
    ``direction`` (0 down-aisle, 1 cross-aisle), for (n_t, n_dof) ``U``."""
    U2, _ = _as_2d(U)
    f = element_end_forces(model, U2)
    ci, cj = _MOMENT[_mesh(model).ndm][direction]
    base = -f[:, model.upright_base_elements, ci]
    below = f[:, model.upright_below_elements, cj]
    above_idx = model.upright_above_elements
    above = np.where(above_idx >= 0, -f[:, np.maximum(above_idx, 0), ci], 0.0)
    return UprightMoments(base=base, below=below, above=above)


@dataclass(frozen=True)
class RecoveryOperators:
    """Sparse linear maps from free-DOF displacements to rack forces: ``U @ op``.

    For ``U: (n_t, n_dof)`` [m, rad] each product is exactly the corresponding function of this
    module evaluated on ``U`` (elastic forces only, same sign conventions). Per horizontal
    direction ``d`` (one in 2D, two in 3D):

    Attributes:
        base_shear: (n_dof, n_dir) CSR; column d of ``U @ base_shear`` [N] is the base shear
            along direction d, ``-Σ`` of the base reactions along it.
        base_moment: per direction, (n_dof, n_column) CSR; ``U @ base_moment[d]`` [N·m] is
            ``upright_moments(model, U, d).base``.
        below, above: per direction, (n_dof, n_column·n_level) CSR; ``U @ below[d]`` [N·m] is
            ``upright_moments(model, U, d).below`` flattened over (column, level),
            column-major (column ``c·n_level + l``); likewise ``above`` (0 above the top).
        n_upright (columns), n_level: the shapes to unflatten with.

    Each column has at most a few dozen non-zeros (one element's stiffness row), so the
    operators cost O(n_column·n_level) memory, unlike evaluating the functions on
    ``np.eye(n_dof)``.
    """

    base_shear: sp.csr_matrix
    base_moment: tuple[sp.csr_matrix, ...]
    below: tuple[sp.csr_matrix, ...]
    above: tuple[sp.csr_matrix, ...]
    n_upright: int
    n_level: int

    @property
    def n_dir(self) -> int:
        return len(self.base_moment)

    def upright_moments(self, U: FloatArray, direction: int = 0) -> UprightMoments:
        """:class:`UprightMoments` of ``U: (n_t, n_dof)`` in one bending plane."""
        U2, _ = _as_2d(U)
        shape = (U2.shape[0], self.n_upright, self.n_level)
        return UprightMoments(base=np.asarray(U2 @ self.base_moment[direction]),
                              below=np.asarray(U2 @ self.below[direction]).reshape(shape),
                              above=np.asarray(U2 @ self.above[direction]).reshape(shape))


def rack_operators(model: Any, design: bool = True
                   ) -> tuple[RecoveryOperators, DesignOperators | None]:
    """Both operator sets of a compiled rack from one pass over its members (the design
    operators None unless ``design``)."""
    maps = end_force_maps(_mesh(model))
    return recovery_operators(model, maps), design_operators(model, maps) if design else None


def recovery_operators(model: Any, maps: EndForceMaps | None = None) -> RecoveryOperators:
    """Build the :class:`RecoveryOperators` of a compiled rack from its element stiffness rows
    (``maps``: its :func:`~seisrack.fe.frame_elements.end_force_maps`, computed if not given)."""
    mesh = _mesh(model)
    n, nf, ndm = mesh.n_dof, mesh.ndf, mesh.ndm
    n_dir = len(_SLOT[ndm])
    edofs = mesh.element_dofs
    maps = end_force_maps(mesh) if maps is None else maps
    kt, ktr = maps.kt, maps.bars
    kg = np.einsum("eji,ejk->eik", maps.T, kt)  # Tᵀ k T: global end forces

    # Base shear along d: -Σ of the reactions along d. A restrained translation reacts with the
    # sum of the global end forces of the members and bars meeting there; a free one with its
    # ground spring, -k·u.
    base = np.asarray(model.base_nodes, dtype=np.int64)
    is_base = np.zeros(mesh.nodes.shape[0], dtype=bool)
    is_base[base] = True
    rows, cols, vals = [], [], []
    for d, slot in enumerate(_SLOT[ndm]):
        fixed = mesh.node_dofs[:, slot] < 0
        for end in (0, 1):  # the two ends of every member, not a loop over members
            hit = is_base[mesh.elements[:, end]] & fixed[mesh.elements[:, end]]
            rows.append(edofs[hit].ravel())
            vals.append(-kg[hit, nf * end + slot, :].ravel())  # minus: base shear = -Σ F
            cols.append(np.full(rows[-1].size, d))
            if mesh.trusses.shape[0]:
                hit = is_base[mesh.trusses[:, end]] & fixed[mesh.trusses[:, end]]
                rows.append(mesh.truss_dofs[hit].ravel())
                vals.append(-ktr[hit, ndm * end + slot, :].ravel())
                cols.append(np.full(rows[-1].size, d))
        free = mesh.node_dofs[base, slot][mesh.node_dofs[base, slot] >= 0]
        rows.append(free)
        vals.append(mesh.ground_spring_k[free])  # -(-k·u)
        cols.append(np.full(free.size, d))
    shear = _columns(np.concatenate(rows), np.concatenate(cols), np.concatenate(vals), n,
                     n_dir)

    n_col, n_lev = np.asarray(model.upright_below_elements).shape
    bases, belows, aboves = [], [], []
    for ci, cj in _MOMENT[ndm]:
        bases.append(_element_rows(kt, edofs, np.asarray(model.upright_base_elements), ci,
                                   -1.0, n))
        belows.append(_element_rows(kt, edofs, np.asarray(model.upright_below_elements).ravel(),
                                    cj, 1.0, n))
        aboves.append(_element_rows(kt, edofs, np.asarray(model.upright_above_elements).ravel(),
                                    ci, -1.0, n))
    return RecoveryOperators(base_shear=shear, base_moment=tuple(bases), below=tuple(belows),
                             above=tuple(aboves), n_upright=int(n_col), n_level=int(n_lev))


def _element_rows(kt: FloatArray, edofs: IntArray, elems: IntArray, comp: int, factor: float,
                  n_dof: int) -> sp.csr_matrix:
    """(n_dof, len(elems)) CSR: column j = factor · row ``comp`` of k·T of element ``elems[j]``
    (a zero column where ``elems[j] < 0``)."""
    ok = elems >= 0
    k = edofs.shape[1]
    cols = np.repeat(np.flatnonzero(ok), k)
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
        beam_moment, beam_shear: (n_dof, n_beam_end) bending moment [N·m] in the vertical
            plane (member convention: ``-M_i`` at the left end, ``+M_j`` at the right end) and
            shear force [N] (``V_i`` at the left end, ``-V_j`` at the right end, the same
            internal shear sign on both ends) at the two ends of every beam, level by level,
            bay by bay (front then rear beam in 3D), left end then right end.
            ``beam_labels``: ``"L{l}-B{b}-left"`` (2D), ``"L{l}-B{b}-front-left"`` (3D),
            ``"L{l}-B{b}-R{r}-front-left"`` (back-to-back rows).
        connector_rotation, connector_moment: (n_dof, n_conn) relative rotation [rad] of each
            beam-to-upright spring and its moment ``k·rotation`` [N·m], signed like the beam
            end moment it carries (left end: beam minus upright rotation, right end: upright
            minus beam), so that in equilibrium the connector moment equals the beam end
            moment; ``connector_labels`` name that beam end (same labels as the beams).
        axial: (n_dof, n_column·(n_level + 1)) upright axial force [N], tension positive, at
            the base (section 0) and at the top of the segment below each level (section l,
            l = 1..n_level); column ``c·(n_level + 1) + s``. ``axial_labels``: ``"U{u}-base"``,
            ``"U{u}-L{l}"`` (2D), ``"U{u}-front-base"`` … (3D, u the upright line). The bending
            moments at the same sections are ``RecoveryOperators.base_moment`` / ``below``.
    """

    beam_moment: sp.csr_matrix
    beam_shear: sp.csr_matrix
    beam_labels: tuple[str, ...]
    connector_rotation: sp.csr_matrix
    connector_moment: sp.csr_matrix
    connector_labels: tuple[str, ...]
    axial: sp.csr_matrix
    axial_labels: tuple[str, ...]


def side_names(n_side: int) -> tuple[str, ...]:
    """Label suffix of each upright side: ``("",)`` (2D), ``("-front", "-rear")`` (a 3D rack
    of one row), ``("-R1-front", "-R1-rear", "-R2-front", "-R2-rear")`` (back to back)."""
    if n_side == 1:
        return ("",)
    one = ("-front", "-rear")
    if n_side == 2:
        return one
    return tuple(f"-R{r + 1}{s}" for r in range(n_side // 2) for s in one)


def column_labels(model: Any) -> tuple[str, ...]:
    """Upright column names: ``"U{line}"`` (2D), ``"U{line}-front"`` / ``"-rear"`` (3D),
    ``"U{line}-R{row}-front"`` … (back-to-back rows)."""
    names = side_names(int(np.max(model.column_side, initial=0)) + 1)
    return tuple(f"U{int(ln) + 1}{names[int(s)]}"
                 for ln, s in zip(model.column_line, model.column_side, strict=True))


def design_operators(model: Any, maps: EndForceMaps | None = None) -> DesignOperators:
    """Build the :class:`DesignOperators` of a compiled rack (beam ends, connectors, upright N;
    ``maps`` as for :func:`recovery_operators`)."""
    mesh = _mesh(model)
    n, ndm, nf = mesh.n_dof, mesh.ndm, mesh.ndf
    edofs = mesh.element_dofs
    kt = (end_force_maps(mesh) if maps is None else maps).kt
    kind = np.asarray(model.element_kind)
    storey = np.asarray(model.element_storey)
    line = np.asarray(model.element_line)
    side = np.asarray(model.element_side)
    n_side = int(side.max(initial=0)) + 1
    ux = np.asarray(model.upright_x, dtype=float)
    n_lev, n_bay = len(model.level_y), ux.size - 1
    xi = mesh.nodes[mesh.elements[:, 0], 0]
    xj = mesh.nodes[mesh.elements[:, 1], 0]
    tol = 1e-9 * max(1.0, float(np.ptp(ux)))
    beam = kind == 1
    # the end element of each beam: its i node on the left upright / its j node on the right
    left = np.full((n_lev, n_bay, n_side), -1, dtype=np.int64)
    right = np.full((n_lev, n_bay, n_side), -1, dtype=np.int64)
    for e in np.flatnonzero(beam & (np.abs(xi - ux[np.clip(line, 0, n_bay)]) < tol)):
        left[storey[e], line[e], side[e]] = e
    for e in np.flatnonzero(beam & (np.abs(xj - ux[np.clip(line + 1, 0, n_bay)]) < tol)):
        right[storey[e], line[e], side[e]] = e
    ends = np.stack([left, right], axis=-1).ravel()  # (l, b, s, e) order
    n_ends = ends.size
    (vi, vj), (mi, mj) = _SHEAR[ndm][0], _MOMENT[ndm][0]
    comp_m = np.tile([mi, mj], n_ends // 2)
    comp_v = np.tile([vi, vj], n_ends // 2)
    sign = np.tile([-1.0, 1.0], n_ends // 2)
    beam_m = _end_rows(kt, edofs, ends, comp_m, sign, n)
    beam_v = _end_rows(kt, edofs, ends, comp_v, -sign, n)
    side_name = side_names(n_side)
    beam_labels = tuple(f"L{lv + 1}-B{b + 1}{side_name[s]}-{e}" for lv in range(n_lev)
                        for b in range(n_bay) for s in range(n_side) for e in ("left", "right"))

    # connectors: springs between two free rotation DOFs about z (the down-aisle bending
    # rotation), the second on a beam end node
    rz = nf - 1  # the rotation about z is the last slot in 2D and 3D
    node_of_rot = np.full(n + 1, -1, dtype=np.int64)
    rot = mesh.node_dofs[:, rz]
    node_of_rot[rot[rot >= 0]] = np.flatnonzero(rot >= 0)
    end_of_node: dict[int, int] = {}
    for k, e in enumerate(ends):
        if e >= 0:
            end_of_node[int(mesh.elements[e, k % 2])] = k
    springs = np.asarray(mesh.springs)
    conn, labels, ks = [], [], []
    for si, (a, b) in enumerate(springs):
        if a < 0 or b < 0:
            continue
        for up, bm in ((a, b), (b, a)):
            k = end_of_node.get(int(node_of_rot[bm]), -1)
            if k >= 0:
                conn.append((up, bm, k))
                labels.append(beam_labels[k])
                ks.append(float(mesh.spring_k[si]))
                break
    order = np.argsort([c[2] for c in conn], kind="stable")
    conn = [conn[i] for i in order]
    labels = [labels[i] for i in order]
    ks = np.asarray([ks[i] for i in order])
    nc = len(conn)
    r_rows = np.array([[bm, up] for up, bm, _ in conn], dtype=np.int64).reshape(-1)
    r_cols = np.repeat(np.arange(nc), 2)
    # sign of the beam's member convention: the connector moment equals the beam end moment
    # (equilibrium of the beam end node, no external moment there) and the rotation follows it
    lside = np.array([1.0 if lab.endswith("left") else -1.0 for lab in labels])
    r_vals = np.repeat(lside, 2) * np.tile([1.0, -1.0], nc)
    conn_rot = _columns(r_rows, r_cols, r_vals, n, nc)
    conn_m = _columns(r_rows, r_cols, r_vals * np.repeat(ks, 2), n, nc)

    n_col = int(np.asarray(model.base_nodes).size)
    sec = np.empty((n_col, n_lev + 1), dtype=np.int64)
    sec[:, 0] = np.asarray(model.upright_base_elements)
    sec[:, 1:] = np.asarray(model.upright_below_elements)
    ai, aj = _AXIAL[ndm]
    comp_n = np.tile(np.r_[ai, np.full(n_lev, aj)], n_col)
    sign_n = np.tile(np.r_[-1.0, np.ones(n_lev)], n_col)  # tension positive: -N_i, +N_j
    axial = _end_rows(kt, edofs, sec.ravel(), comp_n, sign_n, n)
    axial_labels = tuple(f"{col}-" + ("base" if s_ == 0 else f"L{s_}")
                         for col in column_labels(model) for s_ in range(n_lev + 1))
    return DesignOperators(beam_moment=beam_m, beam_shear=beam_v, beam_labels=beam_labels,
                           connector_rotation=conn_rot, connector_moment=conn_m,
                           connector_labels=tuple(labels), axial=axial,
                           axial_labels=axial_labels)


def _end_rows(kt: FloatArray, edofs: IntArray, elems: IntArray, comp: IntArray,
              factor: FloatArray, n_dof: int) -> sp.csr_matrix:
    """Like :func:`_element_rows` with a component and a factor per column."""
    ok = elems >= 0
    k = edofs.shape[1]
    cols = np.repeat(np.flatnonzero(ok), k)
    e = elems[ok]
    vals = factor[ok, None] * kt[e, comp[ok], :]
    return _columns(edofs[e].ravel(), cols, vals.ravel(), n_dof, elems.size)
