"""The basis a run integrates in, chosen in one place: :func:`choose_basis` (theory: §10 of
``docs/theory/stick_slip_engine.md`` and §5 of ``docs/theory/planar_friction.md``).

Every mode up to ``AUTO_FULL_MAX_DOF`` DOFs (or with ``basis="full"``), the caller's
:class:`~seisrack.dynamics.basis.Basis`, or a load-dependent Ritz basis of the loads that act:
the ground loads, the sliders' friction forces and, with nonlinear hinges, their moments. Sliders
on a line and sliders in the plane start the Ritz basis from their own force patterns.
:func:`seisrack.dynamics.simulate` calls it once, before its scheme runs.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import scipy.sparse as sp

from seisrack.dynamics.basis import Basis, full_basis, reduced_basis
from seisrack.dynamics.hinges import Hinges
from seisrack.dynamics.sliders import PlanarSliders, Sliders
from seisrack.errors import InputError

#: with ``basis="auto"``, structures up to this many DOFs keep every mode
AUTO_FULL_MAX_DOF = 50
#: with nonlinear hinges the Ritz basis also starts from a unit moment at every hinge (the
#: static response to the hinges' correction forces), with this many Krylov blocks and this
#: compression tolerance (a yielding hinge needs its own directions: at 3e-2 they are merged
#: and peak hinge rotations are 5 % off); on the paper rack with pallets sliding and hinges
#: yielding, 16 vectors keep the peaks within 1e-4 of the full basis
#: (tests/test_engine_hinges.py)
HINGE_RITZ_BLOCKS = 2
HINGE_RITZ_TOL = 1e-3
#: the size cap of that basis, on a line and in the plane (the reduced basis's default, 200,
#: without hinges): the directions the hinges need cost r³ a factorisation, but the cap of 200
#: gave wrong answers. 2D warehouse example, every connection bilinear (400 pallets, 421
#: hinges), 20 s of EC8: 523 vectors (static error 0.008) in 77 s of CPU, where 200 (static
#: error 0.94) took 8 s with peak sliding 6.9 mm against 17.6 mm and level peaks up to 45 % off.
#: 3D 5 x 10 example, bilinear: 398 vectors (0.0046) in 28 s against 200 (0.78) in 8.6 s, level
#: peaks down-aisle up to 100 % off; 3D 10 x 5 example: 433 vectors in 224 s, peak sliding
#: 158.4 mm against 144.7 mm (benchmarks/results/nonlinear_scale.md)
HINGE_RITZ_MAX_SIZE = 600


def choose_basis(basis: str | Basis, M, K, sliders: Sliders | PlanarSliders,  # noqa: ANN001, N803
                 influence: Sequence[np.ndarray], *, rv: np.ndarray | None = None,
                 F: np.ndarray | None = None, hinges: Hinges | None = None) -> Basis:  # noqa: N803
    """The run's basis: the caller's :class:`Basis` (checked), every mode (``"full"``, or
    ``"auto"`` up to ``AUTO_FULL_MAX_DOF`` DOFs), or a load-dependent Ritz basis
    (``"reduced"``, or ``"auto"`` above). ``influence``: the influence vector of each
    horizontal ground component (one on a line, x and z in the plane); ``rv``: the vertical one
    when the vertical motion loads the structure; ``F``: (n_t, n) applied forces; ``hinges``:
    the nonlinear hinges (their unit moments join the loads)."""
    n = M.shape[0]
    if isinstance(basis, Basis):
        if basis.phi.shape[0] != n:
            raise InputError("basis", f"phi of shape {basis.phi.shape}", f"phi with {n} rows")
        return basis
    if basis not in ("auto", "full", "reduced"):
        raise InputError("basis", basis, '"auto", "full", "reduced" or a seisrack Basis')
    if basis == "reduced" or (basis == "auto" and n > AUTO_FULL_MAX_DOF):
        yielding = hinges if hinges is not None and hinges.nonlinear else None
        if isinstance(sliders, PlanarSliders):
            dofs, mass, loads, opts = _planar_ritz(M, sliders, influence, rv, yielding)
        else:
            dofs, mass, loads, opts = _line_ritz(M, sliders, influence[0], rv, F, yielding)
        return reduced_basis(M, K, dofs, mass, loads, **opts)
    return full_basis(M, K)


def _line_ritz(M, sliders: Sliders, r, rv, F, hinges):  # noqa: ANN001, ANN202, N803
    """Starting loads of the Ritz basis of sliders on a line: the ground load with the sliders
    attached, the vertical load, unit loads at up to 10 loaded DOFs of ``F``, a unit force at
    every slider DOF (``reduced_basis``'s unit loads) and, with nonlinear hinges, a unit moment
    at each of them. Returns (slider DOFs, their masses, loads, options)."""
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
    opts = {}
    if hinges is not None:
        loads.append(hinges.load_vectors(n)[:, hinges.law != 0])
        opts = {"blocks": HINGE_RITZ_BLOCKS, "tol": HINGE_RITZ_TOL,
                "max_size": HINGE_RITZ_MAX_SIZE}
    return sliders.dof, sliders.mass, np.column_stack(loads), opts


#: Ritz basis of a 3D rack: compression tolerance and size up to which Krylov blocks are added
#: (tests/test_rack3d_run.py: against the 2D rack on every mode; on the 5 x 10 warehouse rack
#: 0.1 keeps 86 vectors, peaks within 0.5 % of 3e-2 (144 vectors) and 3.4 times faster:
#: benchmarks/results/rack3d.md)
PLANAR_RITZ_TOL = 1e-1
PLANAR_RITZ_TARGET = 40
#: with nonlinear hinges, each hinge's unit moment is a starting load too, compressed at this
#: tolerance (a yielding hinge needs its own directions, as on a line: HINGE_RITZ_TOL); Krylov
#: blocks are added up to 120 vectors: at 80 the stiff rack of tests/test_planar_stiff.py kept
#: 3 blocks (78 vectors), whose inertial coupling of the pallets' supports released a stuck
#: pallet at its neighbour's slip onset (peak +16.5 %, 6 slip phases against the rigid blocks'
#: 3); with the 4th block (104) every pallet is within 0.09 % (docs/theory/planar_friction.md
#: §10). The 3D paper rack with hinges goes from 78 to 104 vectors; the long racks' first
#: block is larger than either target
PLANAR_HINGE_RITZ_TOL = HINGE_RITZ_TOL
PLANAR_HINGE_RITZ_TARGET = 120


def _planar_ritz(M, sliders: PlanarSliders, influence, rv, hinges):  # noqa: ANN001, ANN202, N803
    """Starting loads of the Ritz basis of sliders in the plane: the ground loads, the vertical
    load, with nonlinear hinges a unit moment at each of them, and each pallet's friction force
    pattern in x and in z (shared by its supports), pallets rigidly attached. Returns (slider
    DOFs, their masses, loads, options)."""
    n = M.shape[0]
    loads = [M @ r for r in influence if np.any(r != 0.0)]
    if rv is not None:
        loads.append(M @ rv)
    opts = {"tol": PLANAR_RITZ_TOL, "target_size": PLANAR_RITZ_TARGET}
    if hinges is not None:
        loads.append(hinges.load_vectors(n)[:, hinges.law != 0])
        opts = {"tol": PLANAR_HINGE_RITZ_TOL, "target_size": PLANAR_HINGE_RITZ_TARGET,
                "max_size": HINGE_RITZ_MAX_SIZE}
    return (*_planar_patterns(sliders, n, np.column_stack(loads) if loads
                              else np.ones((n, 1))), {**opts, "unit_loads": False})


def _planar_patterns(sliders: PlanarSliders, n: int, loads: np.ndarray):  # noqa: ANN202
    """(DOFs, masses, loads with each pallet's x and z friction patterns appended)."""
    m, k = sliders.dof_x.shape
    rows, cols = [], []
    for c, dofs in enumerate((sliders.dof_x, sliders.dof_z)):
        for s in range(k):
            on = dofs[:, s] >= 0
            rows.append(dofs[on, s])
            cols.append(2 * np.flatnonzero(on) + c)
    row, col = np.concatenate(rows), np.concatenate(cols)
    # sparse (a rack row: 2,000 patterns on 20,000 DOFs), supports on one DOF summed
    pat = sp.csc_matrix((np.full(row.size, 1.0 / k), (row, col)), shape=(n, 2 * m))
    pat.sum_duplicates()
    pat = pat[:, np.diff(pat.indptr) > 0]
    dofs = np.concatenate([sliders.dof_x.ravel(), sliders.dof_z.ravel()])
    mass = np.tile(np.repeat(sliders.mass / k, k), 2)
    return dofs, mass, sp.hstack([sp.csc_matrix(np.asarray(loads).reshape(n, -1)), pat],
                                 format="csc")


def planar_basis(M, K, sliders: PlanarSliders, loads: np.ndarray, **ritz) -> Basis:  # noqa: ANN001, N803
    """A load-dependent Ritz basis of sliders in the plane from the ground loads ``loads``
    (n, k) and each pallet's friction force patterns; ``ritz``: options of
    :func:`~seisrack.dynamics.basis.reduced_basis` (defaults ``PLANAR_RITZ_TOL``,
    ``PLANAR_RITZ_TARGET``)."""
    dofs, mass, pats = _planar_patterns(sliders, M.shape[0], loads)
    opts = {"tol": PLANAR_RITZ_TOL, "target_size": PLANAR_RITZ_TARGET, **ritz}
    return reduced_basis(M, K, dofs, mass, pats, unit_loads=False, **opts)
