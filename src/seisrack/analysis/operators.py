"""The rack's recovery and design operators projected onto the engine's basis, built once per
compiled model and basis: :func:`rack_operators` (one pass over the members,
:func:`seisrack.fe.recovery.rack_operators`).

Every rack quantity a run reports is ``q @ op`` of the basis coordinates ``q``, so the peaks
(:mod:`seisrack.analysis.peaks`) never form an ``(n_t, n_dof)`` array. Per-direction
quantities carry one operator per horizontal direction of the rack.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp


@dataclass(frozen=True)
class RackOperators:
    """Maps from basis coordinates ``q: (·, r)`` to rack quantities (``q @ op``), one entry per
    horizontal direction ``d`` where the quantity has a direction.

    level[d]: (r, n_level) mean displacement of each beam level along d [m per unit q];
    shear: (r, n_dir) base shear along each direction [N]; base_moment[d]: (r, n_upright);
    below[d], above[d]: (r, n_upright · n_level) upright end moments at each connection in
    the bending plane of d [N·m]; a1: stiffness-proportional damping coefficient (the support
    reactions include ``a1 K v``); n_upright (upright columns), n_level: shapes.
    """

    level: tuple[np.ndarray, ...]
    shear: np.ndarray
    base_moment: tuple[np.ndarray, ...]
    below: tuple[np.ndarray, ...]
    above: tuple[np.ndarray, ...]
    a1: float
    n_upright: int
    n_level: int
    design: DesignOps | None = None

    @property
    def n_dir(self) -> int:
        return len(self.level)


#: the suffix of a per-direction quantity's name, by direction (down-aisle has none, so the
#: names of a 2D rack are those of its only direction)
DIRECTION_SUFFIX = ("", "_cross_aisle")


@dataclass(frozen=True)
class DesignOps:
    """Design quantities in basis coordinates (``q @ ops[name]``, each ``(r, k)``), see
    :class:`seisrack.fe.recovery.DesignOperators` for the conventions.

    ops: name -> (r, k): ``drift`` (interstorey drift ratio of each storey along each
    direction, ``drift_cross_aisle`` in 3D) [-]; ``beam_moment``, ``beam_shear`` (beam ends,
    vertical plane) [N·m], [N]; ``connector_rotation``, ``connector_moment`` [rad], [N·m];
    ``axial`` upright axial force at the sections (base, top of the segment below each level),
    tension + [N]; ``section_moment`` (``section_moment_cross_aisle`` in 3D) upright bending
    moment at the same sections [N·m]. ``static`` holds each quantity under gravity alone (a
    static solve of the full model), ``labels`` the member labels, ``storey_height`` (n_level,)
    [m].
    """

    ops: dict[str, np.ndarray]
    static: dict[str, np.ndarray]
    labels: dict[str, tuple[str, ...]]
    storey_height: np.ndarray

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self.ops)


def project(op, phi) -> np.ndarray:  # noqa: ANN001
    """(r, k) dense ``phiᵀ op`` of an operator ``op`` (n, k), dense or sparse, onto a basis
    ``phi`` (n, r), dense or sparse (the local engine's basis), neither densified first."""
    x = (op.T @ phi).T
    return x.toarray() if sp.issparse(x) else np.asarray(x)


def _level_mean(phi, dofs) -> np.ndarray:  # noqa: ANN001
    """(r,) mean of the rows ``dofs`` of ``phi`` (dense or sparse)."""
    return np.asarray(phi[np.asarray(dofs)].mean(axis=0)).ravel()


def rack_operators(model, phi: np.ndarray, design: bool = True) -> RackOperators:  # noqa: ANN001
    """Project the level-averaging and force-recovery operators of ``model`` onto ``phi``
    (dense, or sparse for the local engine's basis)."""
    from seisrack.fe.recovery import rack_operators as element_operators

    ops, des = element_operators(model, design)  # one pass over the members
    level = tuple(np.column_stack([_level_mean(phi, d) for d in dofs])
                  for dofs in model.level_dofs)

    def proj(op) -> np.ndarray:  # noqa: ANN001
        return project(op, phi)  # (r, k), sparse op never densified

    return RackOperators(
        level=level, shear=proj(ops.base_shear),
        base_moment=tuple(proj(o) for o in ops.base_moment),
        below=tuple(proj(o) for o in ops.below), above=tuple(proj(o) for o in ops.above),
        a1=float(model.damping_coefficients[1]), n_upright=ops.n_upright, n_level=ops.n_level,
        design=design_ops(model, phi, ops, level, des) if design else None,
    )


def _sections(base, below, n_up: int, n_lev: int):  # noqa: ANN001, ANN202
    """Stack base (·, n_up) and below (·, n_up·n_lev) moments into the section order
    ``u·(n_lev + 1) + s`` of the axial force."""
    lead = base.shape[:-1]
    out = np.concatenate([np.asarray(base).reshape(*lead, n_up, 1),
                          np.asarray(below).reshape(*lead, n_up, n_lev)], axis=-1)
    return out.reshape(*lead, n_up * (n_lev + 1))


def design_ops(model, phi: np.ndarray, rec, level: tuple, d) -> DesignOps:  # noqa: ANN001
    """:class:`DesignOps` of ``model`` in the basis ``phi`` (and the gravity state), from its
    :func:`~seisrack.fe.recovery.design_operators` ``d``."""
    from seisrack.fe.stability import symmetric_lu

    n_up, n_lev = rec.n_upright, rec.n_level
    y0 = float(np.mean(model.nodes[np.asarray(model.base_nodes), 1]))
    height = np.diff(np.r_[y0, np.asarray(model.level_y, dtype=float)])
    diff = np.eye(n_lev) - np.eye(n_lev, k=1)  # level l minus level l - 1
    drift_map = diff / height[None, :]

    def proj(op) -> np.ndarray:  # noqa: ANN001
        return project(op, phi)

    # gravity alone, K u = -g M r_y (M holds the members and the pallets' vertical masses);
    # a sparse solve of the full model, once per model
    u0 = np.atleast_2d(symmetric_lu(model.K_sparse).solve(
        -model.g * (model.M_sparse @ model.r_y)))
    storeys = tuple(f"S{s + 1}" for s in range(n_lev))
    ops: dict[str, np.ndarray] = {}
    static: dict[str, np.ndarray] = {}
    labels: dict[str, tuple[str, ...]] = {}
    for di, sfx in enumerate(DIRECTION_SUFFIX[:len(level)]):
        lvl0 = np.array([u0[0, np.asarray(dofs)].mean() for dofs in model.level_dofs[di]])
        ops["drift" + sfx] = level[di] @ drift_map
        static["drift" + sfx] = lvl0 @ drift_map
        labels["drift" + sfx] = storeys
    for name, op in (("beam_moment", d.beam_moment), ("beam_shear", d.beam_shear),
                     ("connector_rotation", d.connector_rotation),
                     ("connector_moment", d.connector_moment), ("axial", d.axial)):
        ops[name] = proj(op)
        static[name] = np.asarray(u0 @ op)[0]
    labels.update(beam_moment=d.beam_labels, beam_shear=d.beam_labels,
                  connector_rotation=d.connector_labels, connector_moment=d.connector_labels,
                  axial=d.axial_labels)
    for di, sfx in enumerate(DIRECTION_SUFFIX[:len(level)]):
        name = "section_moment" + sfx
        ops[name] = _sections(proj(rec.base_moment[di]), proj(rec.below[di]), n_up, n_lev)
        static[name] = _sections(np.asarray(u0 @ rec.base_moment[di])[0],
                                 np.asarray(u0 @ rec.below[di])[0], n_up, n_lev)
        labels[name] = d.axial_labels
    return DesignOps(ops=ops, static=static, labels=labels, storey_height=height)
