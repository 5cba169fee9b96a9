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
  :func:`~seisrack.fe.recovery.design_operators`: upright axial force and bending moment at the
  base and below each level, beam end moments, connector moments. For a 3D rack they appear
  when those functions accept a 3D model; until then :func:`member_operators` says why not.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.sparse as sp

log = logging.getLogger(__name__)

#: horizontal directions: name -> (component of the node DOFs in 3D, influence vector field)
DIRECTIONS = {"down-aisle": (0, "r_x"), "cross-aisle": (2, "r_z")}
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
    return tuple(DIRECTIONS) if getattr(model, "is_3d", False) else ("down-aisle",)


def influence(model: Any, direction: str) -> np.ndarray:
    """(n_dof,) influence vector of a ground motion in ``direction``."""
    return np.asarray(getattr(model, DIRECTIONS[direction][1]), dtype=float)


def base_height(model: Any) -> float:
    """[m] mean height of the rack's base nodes."""
    base = np.asarray(model.base_nodes).ravel()
    return float(np.mean(model.mesh.nodes[base, 1]))


def storey_heights(model: Any) -> np.ndarray:
    """(n_storey,) [m] storey heights, ground to level 1 first."""
    return np.diff(np.r_[base_height(model), np.asarray(model.level_y, dtype=float)])


def level_dofs(model: Any, direction: str) -> tuple[np.ndarray, ...]:
    """Per level, the horizontal DOFs of its nodes in ``direction``."""
    if getattr(model, "is_3d", False):
        return tuple(model.level_dofs_x if direction == "down-aisle" else model.level_dofs_z)
    return tuple(model.level_dofs)


def _dof_heights(model: Any, direction: str) -> np.ndarray:
    """(n_dof,) [m] height of the node of each translational DOF in ``direction`` (NaN on
    other DOFs)."""
    comp = DIRECTIONS[direction][0] if getattr(model, "is_3d", False) else 0
    nd = np.asarray(model.mesh.node_dofs)[:, comp]
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
    """Member force operators of ``model`` and a note ("" when they are all there).

    2D racks: upright axial force N and bending moment M at the base and below each level,
    beam end moments, connector moments. 3D racks: the same once
    :mod:`seisrack.fe.recovery` builds them for a 3D model; the note says why they are
    missing otherwise.
    """
    from seisrack.fe import recovery

    try:
        rec = recovery.recovery_operators(model)
        des = recovery.design_operators(model)
    except (AttributeError, NotImplementedError, TypeError, ValueError) as exc:
        if not getattr(model, "is_3d", False):
            raise
        log.debug("3D member operators not available: %r", exc)
        return [], ("member forces (upright N and M, beam end and connector moments) need the "
                    "3D recovery operators of seisrack.fe.recovery, not built yet for 3D racks; "
                    "storey quantities are given")
    n_up, n_lev = rec.n_upright, rec.n_level
    section = _section_columns(rec.base_moment, rec.below, n_up, n_lev)
    return [
        NamedOperator("upright_axial_force", des.axial, des.axial_labels, "N",
                      "upright axial force, tension positive, at the base and below each level",
                      "member"),
        NamedOperator("upright_moment", section, des.axial_labels, "N m",
                      "upright bending moment at the base and below each level", "member"),
        NamedOperator("beam_end_moment", des.beam_moment, des.beam_labels, "N m",
                      "bending moment at the beam ends", "member"),
        NamedOperator("connector_moment", des.connector_moment, des.connector_labels, "N m",
                      "moment of the beam-to-upright connector", "member"),
    ], ""
