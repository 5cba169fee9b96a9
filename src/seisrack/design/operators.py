"""Named response-quantity operators of a compiled rack, for the modal combination.

Each :class:`NamedOperator` is a sparse ``(n_dof, k)`` map from free-DOF displacements to k
values of one response quantity (``u @ op``). The design analysis only evaluates
``op.T @ U`` for the modal displacements ``U`` (n_dof, n_modes), so it is generic over them.

- Storey quantities, for any rack (2D or 3D) and each horizontal direction (down-aisle x,
  cross-aisle z): base shear and storey shears (the elastic forces ``K u`` on the DOFs of that
  direction above the bottom of the storey: for a structure on its supports these equal the
  support reactions; ``rᵀ K u_k = Γ_k² ω_k² D_k`` per mode), mean level displacements and
  interstorey drifts.
- Member quantities from :func:`seisrack.fe.recovery.recovery_operators` and
  :func:`~seisrack.fe.recovery.design_operators` (2D and 3D racks): upright axial force and
  bending moment at the base and below each level (in the bending plane of each horizontal
  direction), beam end moments, connector moments.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.sparse as sp

#: horizontal directions: name -> (index of the direction, node DOF slot in 3D)
DIRECTIONS = {"down-aisle": (0, 0), "cross-aisle": (1, 2)}
AXIS = {"down-aisle": "x", "cross-aisle": "z"}


@dataclass(frozen=True)
class NamedOperator:
    """A sparse map ``u @ op`` from displacements (n_dof,) to ``k`` values of a quantity.

    name: key (e.g. ``"storey_shear_x"``); op: (n_dof, k) CSR; labels: (k,) member or storey
    labels; unit: SI unit; description: one line; kind: "storey", "level" or "member".
    """

    name: str
    op: sp.csr_matrix
    labels: tuple[str, ...]
    unit: str
    description: str
    kind: str


def directions_of(model: Any) -> tuple[str, ...]:
    """The horizontal directions of ``model``: down-aisle only in 2D, both in 3D."""
    return tuple(model.directions)


def influence(model: Any, direction: str) -> np.ndarray:
    """(n_dof,) influence vector of a ground motion in ``direction``."""
    return np.asarray(model.influence[DIRECTIONS[direction][0]], dtype=float)


def base_height(model: Any) -> float:
    """[m] mean height of the rack's base nodes."""
    base = np.asarray(model.base_nodes).ravel()
    return float(np.mean(model.mesh.nodes[base, 1]))


def storey_heights(model: Any) -> np.ndarray:
    """(n_storey,) [m] storey heights, ground to level 1 first."""
    return np.diff(np.r_[base_height(model), np.asarray(model.level_y, dtype=float)])


def level_dofs(model: Any, direction: str) -> tuple[np.ndarray, ...]:
    """Per level, the horizontal DOFs of its nodes in ``direction``."""
    return tuple(model.level_dofs[DIRECTIONS[direction][0]])


def _dof_heights(model: Any, direction: str) -> np.ndarray:
    """(n_dof,) [m] height of the node of each translational DOF in ``direction`` (NaN on
    other DOFs)."""
    nd = np.asarray(model.mesh.node_dofs)[:, DIRECTIONS[direction][1]]
    y = np.full(model.n_dof, np.nan)
    free = nd >= 0
    y[nd[free]] = np.asarray(model.mesh.nodes)[free, 1]
    return y


def storey_operators(model: Any, direction: str) -> list[NamedOperator]:
    """Base shear, storey shears, level displacements and interstorey drifts in ``direction``
    (any 2D or 3D rack)."""
    ax = AXIS[direction]
    n = model.n_dof
    K = model.K_sparse
    r = influence(model, direction)
    y = _dof_heights(model, direction)
    level_y = np.asarray(model.level_y, dtype=float)
    n_lev = level_y.size
    tol = 1e-9 * max(1.0, float(np.max(level_y)))
    # storey s (0-based) holds everything above its bottom; storey 1 everything (base shear)
    bottoms = np.r_[-np.inf, level_y[:-1]]
    mask = np.stack([r * (np.nan_to_num(y, nan=-np.inf) > b + tol) for b in bottoms], axis=1)
    shear = sp.csr_matrix(K @ mask)  # (n_dof, n_storey): column s = K r_s (K symmetric)
    base = sp.csr_matrix(K @ r[:, None])
    rows, cols, vals = [], [], []
    for lv, dofs in enumerate(level_dofs(model, direction)):
        d = np.asarray(dofs, dtype=np.int64)
        rows.append(d)
        cols.append(np.full(d.size, lv))
        vals.append(np.full(d.size, 1.0 / d.size))
    level = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                          shape=(n, n_lev))
    diff = sp.csr_matrix(np.eye(n_lev) - np.eye(n_lev, k=1))  # level l minus level l - 1
    drift = sp.csr_matrix(level @ diff)
    storeys = tuple(f"S{s + 1}" for s in range(n_lev))
    levels = tuple(f"L{lv + 1}" for lv in range(n_lev))
    return [
        NamedOperator(f"base_shear_{ax}", base, ("base",), "N",
                      f"base shear {direction} (sum of the support reactions)", "storey"),
        NamedOperator(f"storey_shear_{ax}", shear, storeys, "N",
                      f"storey shear {direction}: forces on the rack above the storey's bottom",
                      "storey"),
        NamedOperator(f"level_displacement_{ax}", level, levels, "m",
                      f"mean displacement of each beam level {direction}", "level"),
        NamedOperator(f"drift_{ax}", drift, storeys, "m",
                      f"interstorey drift {direction}: level above minus level below (or "
                      "the ground)", "storey"),
    ]


def _section_columns(base: sp.csr_matrix, below: sp.csr_matrix, n_up: int, n_lev: int
                     ) -> sp.csr_matrix:
    """(n_dof, n_up·(n_lev + 1)) base and below-level moments in the section order
    ``u·(n_lev + 1) + s`` of the upright axial force."""
    order = []
    for u in range(n_up):
        order.append(base[:, [u]])
        order.append(below[:, u * n_lev:(u + 1) * n_lev])
    return sp.csr_matrix(sp.hstack(order))


def member_operators(model: Any) -> tuple[list[NamedOperator], str]:
    """Member force operators of ``model`` and a note ("": they are all there).

    Upright axial force N and bending moment M at the base and below each level (the moment
    in the bending plane of each horizontal direction: ``upright_moment`` down-aisle,
    ``upright_moment_cross_aisle`` on a 3D rack), beam end moments, connector moments.
    """
    from seisrack.fe import recovery

    rec = recovery.recovery_operators(model)
    des = recovery.design_operators(model)
    n_up, n_lev = rec.n_upright, rec.n_level
    out = [NamedOperator("upright_axial_force", des.axial, des.axial_labels, "N",
                         "upright axial force, tension positive, at the base and below each "
                         "level", "member")]
    for d, (name, plane) in enumerate((("upright_moment", "down-aisle"),
                                       ("upright_moment_cross_aisle", "cross-aisle"))
                                      [:rec.n_dir]):
        section = _section_columns(rec.base_moment[d], rec.below[d], n_up, n_lev)
        out.append(NamedOperator(name, section, des.axial_labels, "N m",
                                 f"upright bending moment in the {plane} plane at the base and "
                                 "below each level", "member"))
    out += [
        NamedOperator("beam_end_moment", des.beam_moment, des.beam_labels, "N m",
                      "bending moment at the beam ends", "member"),
        NamedOperator("connector_moment", des.connector_moment, des.connector_labels, "N m",
                      "moment of the beam-to-upright connector", "member"),
    ]
    return out, ""
