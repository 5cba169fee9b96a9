"""The local engine's inputs from a compiled rack (a 2D or 3D :class:`~seisrack.model.
frame_model.FrameModel`): the slice of every
DOF (the upright line and the bay to its right, from the node's x), the pallets as
:class:`LocalSliders`, and the global loads whose responses carry the far field (a uniform
load on every beam level, per side and direction)."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from seisrack.dynamics.local.sliders import LocalSliders

#: slices on each side of a (half-bay) slice in its patch: one bay each way (measured on the
#: 10-bay example: static energy error 0.09 at 2, 0.16 at 1)
RACK_PATCH = 2


def _node_x(model) -> tuple[np.ndarray, np.ndarray]:  # noqa: ANN001
    """(n,) x of each DOF's node (a DOF shared by nodes takes the largest x; a DOF of no
    node, e.g. a spring's own rotation, that of a DOF it is coupled to) and the nodes' DOF
    table."""
    nodes = np.asarray(model.mesh.nodes)
    nd = np.asarray(model.mesh.node_dofs)
    x = np.full(model.K_sparse.shape[0], -np.inf)
    for c in range(nd.shape[1]):
        on = nd[:, c] >= 0
        np.maximum.at(x, nd[on, c], nodes[on, 0])
    lost = np.flatnonzero(~np.isfinite(x))
    if lost.size:
        K = sp.csr_matrix(model.K_sparse)
        for d in lost:
            cols = K.indices[K.indptr[d]:K.indptr[d + 1]]
            xs = x[cols][np.isfinite(x[cols])]
            x[d] = xs.max() if xs.size else 0.0
    return x, nd


def rack_slices(model) -> np.ndarray:  # noqa: ANN001
    """(n,) slice of every DOF: slice 2c holds the DOFs of upright line c (its frame and the
    beam ends on it), slice 2c + 1 the beams' inner nodes in bay c. Elements join only
    adjacent slices; the frame slices carry the sway and the frames' shapes, the bay slices
    the pallets' local ones (half the block size of a slice per bay: the factorisation's
    cost, in b³, halves)."""
    x, _ = _node_x(model)
    ux = np.asarray(model.upright_x, dtype=float)
    c = np.clip(np.searchsorted(ux, x + 1e-9, side="right") - 1, 0, ux.size - 1)
    on_line = np.abs(x - ux[c]) < 1e-6
    raw = np.where(on_line, 2 * c, 2 * c + 1)
    return np.unique(raw, return_inverse=True)[1].astype(np.int64)


def rack_level_patterns(model) -> np.ndarray:  # noqa: ANN001
    """(n, g) a unit load on every DOF of each beam level (3D: per side, x and z; 2D: x);
    weighted by the mass they are the global loads, whose static responses carry the sway of
    the whole row into every patch."""
    x, nd = _node_x(model)
    nodes = np.asarray(model.mesh.nodes)
    ys = np.asarray(model.level_y)
    n = model.K_sparse.shape[0]
    cols = []
    if model.ndm == 3:
        zs = tuple(float(z) for z in np.asarray(model.frame_z))
        comps = (0, 2)
    else:
        zs = (None,)
        comps = (0,)
    for y in ys:
        on_level = np.abs(nodes[:, 1] - y) < 1e-6
        for z in zs:
            sel = on_level if z is None else on_level & (np.abs(nodes[:, 2] - z) < 1e-6)
            for c in comps:
                d = np.unique(nd[sel, c])
                d = d[d >= 0]
                if d.size == 0:
                    continue
                e = np.zeros(n)
                e[d] = 1.0
                cols.append(e)
    return np.column_stack(cols) if cols else np.zeros((n, 0))


def rack_basis(model, sliders: LocalSliders, *,  # noqa: ANN001
               tol: float | None = None, patch: int | None = None, vertical: bool = False,
               check: str = "static"):  # noqa: ANN201
    """The local basis of a compiled rack (slices by upright line, the pallets' friction
    patterns, the ground loads and a uniform load on every level for the far field), with its
    error measured against the full model (``check``: "static", "full" or "none").
    ``sliders``: the rack's pallets as the run's :class:`LocalSliders` (their supports and
    masses; friction plays no part in the basis: ``analysis.prepare.rack_sliders(model,
    "local")``)."""
    from seisrack.dynamics.local.basis import DEFAULT_TOL, local_basis, measure_error

    slices, levels = rack_slices(model), rack_level_patterns(model)
    sl = sliders
    n = model.K_sparse.shape[0]
    M = model.M_sparse
    extra = sl.attached_mass(n)
    infl = list(model.influence) + ([model.r_y] if vertical else [])
    loads = np.column_stack([M @ r for r in infl])
    pats = sl.patterns(n)
    b = local_basis(M, model.C_sparse, model.K_sparse, slices, loads, pats,
                    global_loads=(M + extra) @ levels, mass_extra=extra,
                    tol=DEFAULT_TOL if tol is None else tol,
                    patch=RACK_PATCH if patch is None else patch)
    if check != "none":
        err = measure_error(b, M, model.K_sparse, loads, pats, mass_extra=extra,
                            n_modes=8 if check == "full" else 0)
        object.__setattr__(b, "error", err)
    return b
