"""Geometry → mesh of a rack: :class:`RackMesh` (the :class:`~seisrack.fe.mesh.FrameMesh` plus
the rack's bookkeeping), whatever the rack's dimension, and the builder of the plane rack
(:func:`build_rack_mesh`; the space rack's builder is :mod:`seisrack.model.rack_mesh3d`).

Plane rack: uprights are meshed column by column (bottom to top), then beams level by level, bay
by bay. A beam end is its own node at the upright's position: it shares the upright node's
translations and, for a semi-rigid or pinned joint, owns its rotation, tied to the upright's by
a rotational spring (none for pinned). A rigid joint shares the rotation too. A base node has
its translations fixed; its rotation is fixed (rigid), free with a spring to ground (semi-rigid)
or free (pinned). Beam stations are the ``subdivisions`` equal divisions plus the pallet
centres.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from seisrack.fe.mesh import FloatArray, FrameMesh, IntArray
from seisrack.model.spec import RackSpec

_MERGE_TOL = 1e-6  # relative to the span: pallet centres this close to a station reuse it

#: element_kind of a beam-column, truss_kind of a bar
UPRIGHT, BEAM, BRACING, SPINE, SPACER = 0, 1, 2, 3, 4


@dataclass(frozen=True)
class RackMesh:
    """The mesh plus the rack bookkeeping needed by compile_rack, for a 2D or a 3D rack.

    An upright *column* is one upright of one upright line: a plane rack has one per line, a
    space rack two per row (front, side 0, at z = 0 and rear, side 1, at z = depth; a
    back-to-back rack's row 2 has sides 2 and 3), column ``c = n_side·line + side``; side ``s``
    belongs to row ``s // 2`` of a space rack.

    element_kind (UPRIGHT, BEAM), element_storey (storey of an upright, level of a beam),
    element_line (upright line of an upright, bay of a beam), element_side: (n_el,) int.
    truss_kind (BRACING, SPINE, SPACER), truss_line (upright line of a bracing bar or a row
    spacer, bay of a spine bar): (n_tr,) int.
    column_line, column_side: (n_col,) int. base_nodes: (n_col,) int; level_nodes:
    (n_col, n_level) int, the upright node at each beam level.
    upright_base_elements: (n_col,) lowest element of each column; upright_below_elements,
    upright_above_elements: (n_col, n_level) the element ending at / starting from each level
    node (-1 above the top level).
    beam_nodes: (level, bay, side) -> the beam's nodes left to right; beam_stations:
    (level, bay) -> their x from the left upright [m].
    """

    mesh: FrameMesh
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
    beam_nodes: dict[tuple[int, int, int], IntArray]
    beam_stations: dict[tuple[int, int], FloatArray]

    @property
    def n_side(self) -> int:
        return int(self.column_side.max(initial=0)) + 1


def beam_stations(span: float, n_sub: int, positions: list[float]) -> FloatArray:
    """Sorted stations along a beam: equal divisions plus pallet centres (merged if close)."""
    st = list(np.linspace(0.0, span, n_sub + 1))
    for p in positions:
        if min(abs(p - s) for s in st) > _MERGE_TOL * span:
            st.append(p)
    return np.array(sorted(st))


def build_rack_mesh(spec: RackSpec) -> RackMesh:
    """The mesh of a plane (2D) rack."""
    geo = spec.geometry
    n_sub, n_lev = geo.subdivisions, geo.n_levels
    xs, ys = geo.upright_x, (0.0, *geo.level_y)
    n_up = len(xs)
    k_joint, k_base = spec.connections.beam_to_upright, spec.connections.base

    nodes: list[tuple[float, float]] = []
    dofs: list[list[int]] = []
    n_dof = 0

    def new_dofs(k: int) -> list[int]:
        nonlocal n_dof
        out = list(range(n_dof, n_dof + k))
        n_dof += k
        return out

    elems: list[tuple[int, int]] = []
    kind: list[int] = []
    storey: list[int] = []
    line: list[int] = []
    sec: list[tuple[float, float]] = []
    springs: list[tuple[int, int, float]] = []

    base_nodes = np.zeros(n_up, dtype=np.int64)
    level_nodes = np.zeros((n_up, n_lev), dtype=np.int64)
    base_el = np.zeros(n_up, dtype=np.int64)
    below = np.zeros((n_up, n_lev), dtype=np.int64)
    above = np.full((n_up, n_lev), -1, dtype=np.int64)

    # Uprights
    for c, x in enumerate(xs):
        base_nodes[c] = len(nodes)
        nodes.append((x, 0.0))
        rz = -1 if math.isinf(k_base) else new_dofs(1)[0]
        dofs.append([-1, -1, rz])
        if 0.0 < k_base < math.inf:
            springs.append((rz, -1, k_base))
        prev = base_nodes[c]
        for s in range(n_lev):
            section = spec.upright_section(s)
            for y in np.linspace(ys[s], ys[s + 1], n_sub + 1)[1:]:
                node = len(nodes)
                nodes.append((x, float(y)))
                dofs.append(new_dofs(3))
                if s > 0 and prev == level_nodes[c, s - 1]:
                    above[c, s - 1] = len(elems)
                if prev == base_nodes[c]:
                    base_el[c] = len(elems)
                elems.append((prev, node))
                kind.append(UPRIGHT)
                storey.append(s)
                line.append(c)
                sec.append((section.A, section.I))
                prev = node
            level_nodes[c, s] = prev
            below[c, s] = len(elems) - 1

    # Beams
    by_member: dict[tuple[int, int], list[float]] = {}
    for p in spec.pallets:
        by_member.setdefault((p.level - 1, p.bay - 1), []).append(p.position)
    b_nodes: dict[tuple[int, int, int], IntArray] = {}
    b_st: dict[tuple[int, int], FloatArray] = {}
    for lev in range(n_lev):
        section = spec.beam_section(lev)
        y = ys[lev + 1]
        for bay, span in enumerate(geo.bays):
            st = beam_stations(span, n_sub, by_member.get((lev, bay), []))
            ids = []
            for i, sx in enumerate(st):
                node = len(nodes)
                nodes.append((xs[bay] + float(sx), y))
                if i in (0, len(st) - 1):
                    up = dofs[level_nodes[bay + (i > 0), lev]]
                    if math.isinf(k_joint):
                        dofs.append(list(up))
                    else:
                        rz = new_dofs(1)[0]
                        dofs.append([up[0], up[1], rz])
                        if k_joint > 0.0:
                            springs.append((up[2], rz, k_joint))
                else:
                    dofs.append(new_dofs(3))
                ids.append(node)
            for a, b in zip(ids[:-1], ids[1:], strict=True):
                elems.append((a, b))
                kind.append(BEAM)
                storey.append(lev)
                line.append(bay)
                sec.append((section.A, section.I))
            b_nodes[(lev, bay, 0)] = np.array(ids, dtype=np.int64)
            b_st[(lev, bay)] = st

    n_el = len(elems)
    sec_arr = np.array(sec, dtype=float).reshape(n_el, 2)
    mesh = FrameMesh(
        nodes=np.array(nodes, dtype=float), elements=np.array(elems, dtype=np.int64),
        node_dofs=np.array(dofs, dtype=np.int64), E=np.full(n_el, spec.material.E),
        A=sec_arr[:, 0].copy(), I=sec_arr[:, 1].copy(),
        density=np.full(n_el, spec.material.density),
        springs=np.array([s[:2] for s in springs], dtype=np.int64).reshape(-1, 2),
        spring_k=np.array([s[2] for s in springs], dtype=float), n_dof=n_dof,
    )
    none = np.zeros(0, dtype=np.int64)
    return RackMesh(mesh=mesh, element_kind=np.array(kind, dtype=np.int64),
                    element_storey=np.array(storey, dtype=np.int64),
                    element_line=np.array(line, dtype=np.int64),
                    element_side=np.zeros(n_el, dtype=np.int64), truss_kind=none,
                    truss_line=none, column_line=np.arange(n_up, dtype=np.int64),
                    column_side=np.zeros(n_up, dtype=np.int64), base_nodes=base_nodes,
                    level_nodes=level_nodes, upright_base_elements=base_el,
                    upright_below_elements=below, upright_above_elements=above,
                    beam_nodes=b_nodes, beam_stations=b_st)
