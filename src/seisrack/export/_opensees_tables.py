"""The data tables of an exported OpenSeesPy script, from a compiled rack, 2D or 3D.

Everything here reads the model's arrays (``model.mesh``, the pallet and level arrays) and
returns plain Python rows with 1-based OpenSees tags;
the text is written by :mod:`seisrack.export.opensees` and the functions that use the tables
are in :mod:`seisrack.export._opensees_template`. The dimension is data: ``mesh.ndm`` and
``mesh.ndf`` set the row lengths.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from seisrack.errors import InputError


def script_tables(model: Any, mu: float | None) -> dict[str, list]:
    """The script's tables (names as in the script, lower case) from the compiled model."""
    mesh = model.mesh
    n_node = int(mesh.nodes.shape[0])
    owner, equal_dof, fix = _dof_owners(mesh)
    sections, transforms, members = _members(mesh)
    ground, springs = _springs(model, owner, n_node + 1)
    next_node = n_node + 1 + len(ground)
    pallets, vertical = _pallets(model, mu, owner, next_node)
    return {
        "nodes": [tuple(float(c) for c in x) for x in mesh.nodes],
        "fix": fix, "equal_dof": equal_dof, "sections": sections, "transforms": transforms,
        "members": members, "trusses": _trusses(mesh), "ground": ground, "springs": springs,
        "vertical_mass": vertical, "pallets": pallets,
        "levels": _levels(model, owner, 0),
        "levels_z": _levels(model, owner, 1) if model.n_dir == 2 else [],
    }


def _dof_owners(mesh: Any) -> tuple[dict[int, tuple[int, int]], list, list]:
    """The node (0-based) and slot owning each DOF (the first node holding it), the equalDOF
    ties of the other nodes holding it, and the restraints."""
    owner: dict[int, tuple[int, int]] = {}  # dof -> (node index, slot)
    ties: dict[tuple[int, int], list[int]] = {}
    fix = []
    for i, row in enumerate(mesh.node_dofs):
        d = [int(v) for v in row]
        if any(v < 0 for v in d):
            fix.append((i + 1, *(int(v < 0) for v in d)))
        for k, dof in enumerate(d):
            if dof < 0:
                continue
            if dof in owner:
                m_node, m_slot = owner[dof]
                if m_slot != k:
                    raise InputError("mesh.node_dofs", f"DOF {dof} in two directions",
                                     "a DOF shared by nodes in one direction")
                ties.setdefault((m_node, i), []).append(k + 1)
            else:
                owner[dof] = (i, k)
    equal_dof = [(a + 1, b + 1, tuple(dirs)) for (a, b), dirs in ties.items()]
    return owner, equal_dof, fix


def _members(mesh: Any) -> tuple[list, list, list]:
    """Sections, geometric transformations and members (i, j, section[, transformation]: 3D
    only, a plane rack has one transformation, tag 1).

    2D section: (E, A, I, ρA). 3D section: (E, A, Iz, Iy, G', J', ρA) for ``elasticBeamColumn``
    with J' = Ip and G' = G J / Ip: its stiffness G'J' is seisrack's G J and its consistent
    twist inertia ρ J' L / 3 is seisrack's ρ Ip L / 3 (OpenSees 3.7's ElasticBeam3d takes the
    torsional inertia from J).
    """
    sections: dict[tuple[float, ...], int] = {}
    transforms: dict[tuple[float, ...], int] = {}
    members = []
    three_d = mesh.ndm == 3
    for e, (i, j) in enumerate(mesh.elements):
        rho_a = float(mesh.density[e] * mesh.A[e])
        if three_d:
            ip, jt = float(mesh.Ip[e]), float(mesh.J[e])
            key: tuple[float, ...] = (float(mesh.E[e]), float(mesh.A[e]), float(mesh.I[e]),
                                      float(mesh.Iy[e]), float(mesh.G[e]) * jt / ip, ip, rho_a)
            vec = tuple(float(v) for v in mesh.vecxz[e])
        else:
            key = (float(mesh.E[e]), float(mesh.A[e]), float(mesh.I[e]), rho_a)
            vec = ()
        sec = sections.setdefault(key, len(sections) + 1)
        tr = transforms.setdefault(vec, len(transforms) + 1)
        members.append((int(i) + 1, int(j) + 1, sec, tr) if three_d else
                       (int(i) + 1, int(j) + 1, sec))  # 2D: one transformation, tag 1
    return list(sections), list(transforms), members


def _trusses(mesh: Any) -> list:
    """(node i, node j, E [Pa], A [m²], ρA [kg/m]) of each pin-ended bar (3D bracing)."""
    return [(int(a) + 1, int(b) + 1, float(mesh.truss_E[t]), float(mesh.truss_A[t]),
             float(mesh.truss_density[t] * mesh.truss_A[t]))
            for t, (a, b) in enumerate(mesh.trusses)]


def _springs(model: Any, owner: dict, next_node: int) -> tuple[list, list]:
    """Fixed ground nodes (tag, coordinates...) and springs (node i, node j, direction, k)."""
    mesh = model.mesh
    ground, springs = [], []
    for n, ((da, db), k) in enumerate(zip(mesh.springs, mesh.spring_k, strict=True)):
        da, db = _oriented(model, n, int(da), int(db))
        a = owner.get(int(da)) if da >= 0 else None
        b = owner.get(int(db)) if db >= 0 else None
        if a is None and b is None:
            continue
        if a is None or b is None:
            free = a if a is not None else b
            assert free is not None
            ground.append((next_node, *(float(c) for c in mesh.nodes[free[0]])))
            springs.append((next_node, free[0] + 1, free[1] + 1, float(k)))
            next_node += 1
        else:
            if a[1] != b[1]:
                raise InputError("mesh.springs", f"DOFs {da}, {db}", "DOFs of one direction")
            springs.append((a[0] + 1, b[0] + 1, a[1] + 1, float(k)))
    return ground, springs


def _oriented(model: Any, n: int, da: int, db: int) -> tuple[int, int]:
    """Spring ``n``'s DOFs ordered (b, a) after its hinge (``model.hinge_dofs[n] = (a, b)``), so
    that the zeroLength deformation u_j − u_i is the hinge rotation u[a] − u[b]."""
    hd = getattr(model, "hinge_dofs", None)
    if hd is None:
        return da, db
    a, b = (int(v) for v in hd[n])
    if {a, b} != {da, db}:
        raise InputError("model.hinge_dofs", f"hinge {n}: DOFs ({a}, {b})",
                         f"the DOFs ({da}, {db}) of spring {n} of mesh.springs (one hinge per "
                         "spring, in the same order)")
    return b, a


def _pallets(model: Any, mu: float | None, owner: dict, next_node: int
             ) -> tuple[list, list]:
    """Pallet rows and the vertical masses on their supports.

    A pallet row is (own node, support, mass [kg], mu, 0-based level): in 2D ``support`` is the
    beam node; in 3D it is the tuple of its support nodes (front and rear beam) and the pallet
    has one own node per support (tags own node, own node + 1, ...). Vertical masses: (node,
    mass [kg]), each pallet's mass shared equally by its supports and summed per node (as
    seisrack's ``M``; ``ops.mass`` replaces, so the sum is taken here).
    """
    m = int(model.pallet_mass.size)
    mus = np.broadcast_to(np.asarray(model.pallet_mu_static if mu is None else mu, float), (m,))
    level_of_dof = {int(d): lv for lv, dofs in enumerate(model.level_dofs[0]) for d in dofs}
    k = int(model.pallet_vdof.shape[1]) if m else 1
    vertical: dict[int, float] = {}
    rows = []
    for j in range(m):
        mass = float(model.pallet_mass[j])
        for s in range(k):
            vn = owner[int(model.pallet_vdof[j, s])][0] + 1
            vertical[vn] = vertical.get(vn, 0.0) + mass / k
        supports = tuple(owner[int(model.pallet_dofs[j, s, 0])][0] + 1 for s in range(k))
        level = level_of_dof[int(model.pallet_dofs[j, 0, 0])]
        rows.append((next_node, supports[0] if model.ndm == 2 else supports, mass,
                     float(mus[j]), level))
        next_node += 1 if model.ndm == 2 else k
    return rows, list(vertical.items())


def _levels(model: Any, owner: dict, direction: int) -> list[list[int]]:
    """Per level, bottom to top, one node per distinct DOF of ``direction`` (0 x, 1 z)."""
    return [[owner[int(d)][0] + 1 for d in dofs] for dofs in model.level_dofs[direction]]
