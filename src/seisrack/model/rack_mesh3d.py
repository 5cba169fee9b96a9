"""Geometry → mesh of a space (3D) rack, a :class:`~seisrack.model.rack_mesh.RackMesh`:
uprights, front and rear beams, bracing, row spacers, DOF map and springs.

Global axes: x down-aisle (along the beams), y up, z cross-aisle. A rack of one row has its
front frame in the plane z = 0 and its rear frame at z = ``depth``; a back-to-back rack
(``[geometry] rows = 2``) has row 2's frames at z = depth + length and 2·depth + length (length:
the row spacers'), so four upright *sides* (0, 1: row 1 front and rear; 2, 3: row 2), given by
:attr:`~seisrack.model.spec.Geometry.frame_z`. Six DOFs per node ``(ux, uy, uz, rx, ry, rz)``.

- Uprights (beam-columns, ``vecxz`` = +z): local z = global z, so ``Iz`` (the 2D ``I``) is
  bending in the down-aisle plane and ``Iy`` cross-aisle bending. Nodes at the ``subdivisions``
  divisions of every storey, at every panel point, every bracing end and every row spacer
  (merged when within 1e-6 m).
- Beams (``vecxz`` = +z): one per side in every bay and level (a front and a rear beam per
  row), stations as in 2D (:func:`seisrack.model.rack_mesh.beam_stations`; every beam of a bay
  and level has the same stations, from the pallets of both rows). A beam end is its own node
  sharing the upright node's translations and its rotations rx, ry (rigid in those directions)
  and, for a semi-rigid or pinned connector, owning its rotation rz about the cross-aisle axis,
  tied to the upright's by a spring (none for pinned); a rigid connector shares rz too.
- Bases: translations and the twist ry fixed; rz (down-aisle bending) and rx (cross-aisle
  bending) each fixed (rigid), free with a spring to the ground (semi-rigid: ``base`` and
  ``base_cross``) or free (pinned).
- Bracing: pin-ended bars (3D trusses) between upright nodes of each upright frame, the same in
  each row (F its front, R its rear upright), and the spine diagonals in each row's back plane
  (the rear frame of row 1, the front frame of row 2: the faces on the flue, the aisle faces
  being the loading faces); eccentricities ignored.
- Row spacers (back-to-back racks): pin-ended bars joining the inner uprights of the two rows
  (sides 1 and 2) on every upright line at the spacer heights; eccentricities ignored.
"""

from __future__ import annotations

import math

import numpy as np

from seisrack.fe.mesh import FloatArray, FrameMesh
from seisrack.model.bracing import FRONT
from seisrack.model.rack_mesh import (
    BEAM,
    BRACING,
    SPACER,
    SPINE,
    UPRIGHT,
    RackMesh,
    beam_stations,
)
from seisrack.model.spec import RackSpec

_Z_AXIS = (0.0, 0.0, 1.0)
_MERGE = 1e-6  # m


def _upright_heights(spec: RackSpec) -> FloatArray:
    """Heights of the upright nodes: storey divisions, panel points, bracing ends and row
    spacers."""
    geo = spec.geometry
    ys = (0.0, *geo.level_y)
    pts = [float(y) for s in range(geo.n_levels)
           for y in np.linspace(ys[s], ys[s + 1], geo.subdivisions + 1)]
    assert spec.bracing is not None
    pts += list(spec.bracing.heights)
    if geo.row_spacer is not None:
        pts += list(geo.row_spacer.heights)
    out: list[float] = []
    for y in sorted(pts):
        if not out or y - out[-1] > _MERGE:
            out.append(y)
    return np.array(out)


def build_rack_mesh_3d(spec: RackSpec) -> RackMesh:
    geo, br = spec.geometry, spec.bracing
    assert geo.depth is not None and br is not None
    n_lev, n_line = geo.n_levels, geo.n_bays + 1
    xs, zs = geo.upright_x, geo.frame_z
    n_side = len(zs)  # 2 per row
    k_joint = spec.connections.beam_to_upright
    k_base, k_cross = spec.connections.base, spec.connections.base_cross_k
    heights = _upright_heights(spec)
    level_y = np.array(geo.level_y)

    nodes: list[tuple[float, float, float]] = []
    dofs: list[list[int]] = []
    n_dof = 0

    def new(k: int) -> list[int]:
        nonlocal n_dof
        out = list(range(n_dof, n_dof + k))
        n_dof += k
        return out

    el: list[tuple[int, int]] = []
    props: list[tuple[str, int, int, int, int]] = []  # section, kind, storey, line, side
    springs: list[tuple[int, int, float]] = []
    n_col = n_side * n_line  # column n_side·line + side
    base_nodes = np.zeros(n_col, dtype=np.int64)
    level_nodes = np.zeros((n_col, n_lev), dtype=np.int64)
    base_el = np.zeros(n_col, dtype=np.int64)
    below = np.zeros((n_col, n_lev), dtype=np.int64)
    above = np.full((n_col, n_lev), -1, dtype=np.int64)
    at_height: dict[tuple[int, int], np.ndarray] = {}  # (line, side) -> node per height

    def base_rot(k: float) -> int:
        if math.isinf(k):
            return -1
        d = new(1)[0]
        if k > 0.0:
            springs.append((d, -1, k))
        return d

    for c, x in enumerate(xs):
        for side, z in enumerate(zs):
            col = n_side * c + side
            ids = [len(nodes)]
            base_nodes[col] = ids[0]
            nodes.append((x, 0.0, z))
            dofs.append([-1, -1, -1, base_rot(k_cross), -1, base_rot(k_base)])
            first = len(el)
            for y in heights[1:]:
                ids.append(len(nodes))
                nodes.append((x, float(y), z))
                dofs.append(new(6))
                storey = int(np.searchsorted(level_y, y - _MERGE))
                el.append((ids[-2], ids[-1]))
                props.append((geo.upright_sections[storey], UPRIGHT, storey, c, side))
            at_height[(c, side)] = np.array(ids, dtype=np.int64)
            base_el[col] = first
            for lev, y in enumerate(level_y):
                k = int(np.argmin(np.abs(heights - y)))  # node k ends element first + k - 1
                level_nodes[col, lev] = ids[k]
                below[col, lev] = first + k - 1
                if k < len(heights) - 1:
                    above[col, lev] = first + k

    by_member: dict[tuple[int, int], list[float]] = {}
    for p in spec.pallets:
        by_member.setdefault((p.level - 1, p.bay - 1), []).append(p.position)
    b_nodes: dict[tuple[int, int, int], np.ndarray] = {}
    b_st: dict[tuple[int, int], FloatArray] = {}
    for lev in range(n_lev):
        for bay, span in enumerate(geo.bays):
            st = beam_stations(span, geo.subdivisions, by_member.get((lev, bay), []))
            b_st[(lev, bay)] = st
            for side, z in enumerate(zs):
                ids = []
                for i, sx in enumerate(st):
                    node = len(nodes)
                    nodes.append((xs[bay] + float(sx), float(level_y[lev]), z))
                    if i in (0, len(st) - 1):
                        up = dofs[level_nodes[n_side * (bay + (i > 0)) + side, lev]]
                        if math.isinf(k_joint):
                            dofs.append(list(up))
                        else:
                            rz = new(1)[0]
                            dofs.append(up[:5] + [rz])
                            if k_joint > 0.0:
                                springs.append((up[5], rz, k_joint))
                    else:
                        dofs.append(new(6))
                    ids.append(node)
                for a, b in zip(ids[:-1], ids[1:], strict=True):
                    el.append((a, b))
                    props.append((geo.beam_sections[lev], BEAM, lev, bay, side))
                b_nodes[(lev, bay, side)] = np.array(ids, dtype=np.int64)

    tr: list[tuple[int, int]] = []
    tr_props: list[tuple[str, int, int]] = []

    def node_at(c: int, side: int, y: float) -> int:
        return int(at_height[(c, side)][int(np.argmin(np.abs(heights - y)))])

    rows = n_side // 2
    for r in range(rows):  # each row's upright frames braced alike (F: side 2r, R: 2r + 1)
        for c in range(n_line):
            for (sa, ya, sb, yb), sec in zip(br.members, br.sections, strict=True):
                tr.append((node_at(c, 2 * r + sa, ya), node_at(c, 2 * r + sb, yb)))
                tr_props.append((sec, BRACING, c))
    ys = np.concatenate([[0.0], level_y])
    for back in (1 - FRONT, 2)[:rows]:  # each row's back plane: the faces on the flue
        for bay in br.spine_bays:
            for s in br.spine_levels:
                lo, hi = (bay, bay + 1) if s % 2 == 0 else (bay + 1, bay)
                tr.append((node_at(lo, back, ys[s]), node_at(hi, back, ys[s + 1])))
                tr_props.append((br.spine_section or "", SPINE, bay))
    if geo.row_spacer is not None:  # row 1's rear uprights to row 2's front uprights
        for c in range(n_line):
            for y in geo.row_spacer.heights:
                tr.append((node_at(c, 1, y), node_at(c, 2, y)))
                tr_props.append((geo.row_spacer.section, SPACER, c))

    secs = spec.sections
    n_el = len(el)
    sec_of = [secs[p[0]] for p in props]
    col = np.array([(s.A, s.Iy or 0.0, s.I, s.J or 0.0,
                     s.Ip if s.Ip is not None else (s.Iy or 0.0) + s.I) for s in sec_of],
                   dtype=float).reshape(n_el, 5)
    mat = spec.material
    mesh = FrameMesh(
        nodes=np.array(nodes, dtype=float), node_dofs=np.array(dofs, dtype=np.int64),
        elements=np.array(el, dtype=np.int64).reshape(-1, 2), E=np.full(n_el, mat.E),
        G=np.full(n_el, mat.G), A=col[:, 0].copy(), Iy=col[:, 1].copy(), I=col[:, 2].copy(),
        J=col[:, 3].copy(), Ip=col[:, 4].copy(), density=np.full(n_el, mat.density),
        vecxz=np.tile(np.array(_Z_AXIS), (n_el, 1)),
        trusses=np.array(tr, dtype=np.int64).reshape(-1, 2), truss_E=np.full(len(tr), mat.E),
        truss_A=np.array([secs[p[0]].A for p in tr_props], dtype=float),
        truss_density=np.full(len(tr), mat.density),
        springs=np.array([s[:2] for s in springs], dtype=np.int64).reshape(-1, 2),
        spring_k=np.array([s[2] for s in springs], dtype=float), n_dof=n_dof)
    arr = np.array([p[1:] for p in props], dtype=np.int64).reshape(-1, 4)
    tarr = np.array([p[1:] for p in tr_props], dtype=np.int64).reshape(-1, 2)
    return RackMesh(mesh=mesh, element_kind=arr[:, 0].copy(), element_storey=arr[:, 1].copy(),
                    element_line=arr[:, 2].copy(), element_side=arr[:, 3].copy(),
                    truss_kind=tarr[:, 0].copy(), truss_line=tarr[:, 1].copy(),
                    column_line=np.repeat(np.arange(n_line, dtype=np.int64), n_side),
                    column_side=np.tile(np.arange(n_side, dtype=np.int64), n_line),
                    base_nodes=base_nodes, level_nodes=level_nodes, upright_base_elements=base_el,
                    upright_below_elements=below, upright_above_elements=above,
                    beam_nodes=b_nodes, beam_stations=b_st)
