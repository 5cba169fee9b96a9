"""The basis a run integrates in, chosen in one place: :func:`choose_basis` (theory: §10 of
``docs/theory/stick_slip_engine.md`` and §5 of ``docs/theory/planar_friction.md``).

Every mode up to ``AUTO_FULL_MAX_DOF`` DOFs (or with ``basis="full"``), the caller's
:class:`~seisrack.dynamics.basis.Basis`, or a load-dependent Ritz basis of the loads that act:
the ground loads, the sliders' friction forces and, with nonlinear hinges, their moments. Sliders
on a line and sliders in the plane start the Ritz basis from their own force patterns.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from seisrack.dynamics._setup import HINGE_RITZ_BLOCKS, HINGE_RITZ_TOL, given_or_full_basis
from seisrack.dynamics.basis import Basis, reduced_basis
from seisrack.dynamics.hinges import Hinges
from seisrack.dynamics.sliders import PlanarSliders, Sliders


def choose_basis(basis: str | Basis, M, K, sliders: Sliders | PlanarSliders,  # noqa: ANN001, N803
                 influence: Sequence[np.ndarray], *, rv: np.ndarray | None = None,
                 F: np.ndarray | None = None, hinges: Hinges | None = None) -> Basis:  # noqa: N803
    """The run's basis. ``basis``: "auto", "full", "reduced" or a Basis; ``influence``: the
    influence vector of each horizontal ground component (one on a line, x and z in the plane);
    ``rv``: the vertical one when the vertical motion loads the structure; ``F``: (n_t, n)
    applied forces; ``hinges``: the nonlinear hinges (their unit moments join the loads)."""
    chosen = given_or_full_basis(basis, M, K)
    if chosen is not None:
        return chosen
    if isinstance(sliders, PlanarSliders):
        loads = [M @ r for r in influence if np.any(r != 0.0)]
        if rv is not None:
            loads.append(M @ rv)
        n = M.shape[0]
        if hinges is not None and hinges.nonlinear:
            loads.append(hinges.load_vectors(n)[:, hinges.law != 0])
            return planar_basis(M, K, sliders, np.column_stack(loads), tol=PLANAR_HINGE_RITZ_TOL,
                                target_size=PLANAR_HINGE_RITZ_TARGET)
        return planar_basis(M, K, sliders, np.column_stack(loads) if loads else np.ones((n, 1)))
    return _line_basis(M, K, sliders, influence[0], rv, F,
                       hinges if hinges is not None and hinges.nonlinear else None)


def _line_basis(M, K, sliders: Sliders, r, rv, F, hinges) -> Basis:  # noqa: ANN001, N803
    """Load-dependent Ritz basis of sliders on a line: the ground load with the sliders
    attached, the vertical load, unit loads at up to 10 loaded DOFs of ``F``, a unit force at
    every slider DOF and, with nonlinear hinges, a unit moment at each of them."""
    n = M.shape[0]
    on = sliders.dof >= 0
    extra = np.zeros(n)
    np.add.at(extra, sliders.dof[on], sliders.mass[on])
    loads = [M @ r + extra * r]
    if rv is not None:
        loads.append(M @ rv)
    if F is not None:
        loaded = np.flatnonzero(np.any(F != 0.0, axis=0))
        if loaded.size <= 10:
            for d in loaded:
                e = np.zeros(n)
                e[d] = 1.0
                loads.append(e)
    if hinges is not None:
        loads.append(hinges.load_vectors(n)[:, hinges.law != 0])
        return reduced_basis(M, K, sliders.dof, sliders.mass, np.column_stack(loads),
                             blocks=HINGE_RITZ_BLOCKS, tol=HINGE_RITZ_TOL)
    return reduced_basis(M, K, sliders.dof, sliders.mass, np.column_stack(loads))


#: Ritz basis of a 3D rack: compression tolerance and size up to which Krylov blocks are added
#: (tests/test_rack3d_run.py: against the 2D rack on every mode; on the 5 x 10 warehouse rack
#: 0.1 keeps 86 vectors, peaks within 0.5 % of 3e-2 (144 vectors) and 3.4 times faster:
#: benchmarks/results/rack3d.md)
PLANAR_RITZ_TOL = 1e-1
PLANAR_RITZ_TARGET = 40
#: with nonlinear hinges, each hinge's unit moment is a starting load too, compressed at this
#: tolerance (a yielding hinge needs its own directions, as on a line: HINGE_RITZ_TOL)
PLANAR_HINGE_RITZ_TOL = HINGE_RITZ_TOL
PLANAR_HINGE_RITZ_TARGET = 80


def planar_basis(M, K, sliders: PlanarSliders, loads: np.ndarray,  # noqa: ANN001, N803
                 basis: str | Basis = "auto", **ritz) -> Basis:
    """Every mode up to ``AUTO_FULL_MAX_DOF`` DOFs (or ``basis="full"``), else a
    load-dependent Ritz basis from the ground loads ``loads`` (n, k) and each pallet's friction
    force pattern in x and in z (shared by its supports), pallets rigidly attached. ``ritz``:
    options of :func:`~seisrack.dynamics.basis.reduced_basis` (defaults
    ``PLANAR_RITZ_TOL``, ``PLANAR_RITZ_TARGET``)."""
    n = M.shape[0]
    chosen = given_or_full_basis(basis, M, K)
    if chosen is not None:
        return chosen
    m, k = sliders.dof_x.shape
    pat = np.zeros((n, 2 * m))
    for c, dofs in enumerate((sliders.dof_x, sliders.dof_z)):
        for s in range(k):
            on = dofs[:, s] >= 0
            np.add.at(pat, (dofs[on, s], 2 * np.flatnonzero(on) + c), 1.0 / k)
    pat = pat[:, np.any(pat != 0.0, axis=0)]
    dofs = np.concatenate([sliders.dof_x.ravel(), sliders.dof_z.ravel()])
    mass = np.tile(np.repeat(sliders.mass / k, k), 2)
    opts = {"tol": PLANAR_RITZ_TOL, "target_size": PLANAR_RITZ_TARGET, **ritz}
    return reduced_basis(M, K, dofs, mass, np.column_stack([np.asarray(loads).reshape(n, -1),
                                                            pat]), unit_loads=False, **opts)
