"""The basis a run integrates in, chosen in one place, and the memory the run may take, checked
before anything is allocated: :func:`choose_basis`, :func:`check_memory` (theory: §10 of
``docs/theory/stick_slip_engine.md`` and §5 of ``docs/theory/planar_friction.md``).

Every mode up to ``AUTO_FULL_MAX_DOF`` DOFs (or with ``basis="full"``), the caller's
:class:`~seisrack.dynamics.basis.Basis`, or a load-dependent Ritz basis of the loads that act:
the ground loads, the sliders' friction forces and, with nonlinear hinges, their moments. Sliders
on a line and sliders in the plane start the Ritz basis from their own force patterns.
:func:`seisrack.dynamics.simulate` calls both once, before its scheme runs.
"""

from __future__ import annotations

import os
from collections.abc import Sequence

import numpy as np

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
#: default cap on what one run's kept histories and buffers may take [bytes]
DEFAULT_MAX_MEMORY = 4 * 2**30


def given_or_full_basis(basis, M, K) -> Basis | None:  # noqa: ANN001, N803
    """The caller's Basis (checked), every mode for ``"full"`` (or ``"auto"`` up to
    ``AUTO_FULL_MAX_DOF`` DOFs), or None when a reduced basis is to be built."""
    n = M.shape[0]
    if isinstance(basis, Basis):
        if basis.phi.shape[0] != n:
            raise InputError("basis", f"phi of shape {basis.phi.shape}", f"phi with {n} rows")
        return basis
    if basis not in ("auto", "full", "reduced"):
        raise InputError("basis", basis, '"auto", "full", "reduced" or a seisrack Basis')
    if basis == "full" or (basis == "auto" and n <= AUTO_FULL_MAX_DOF):
        return full_basis(M, K)
    return None


def kept_samples(n_steps: int, save_every: int | None) -> int:
    """How many samples a run of ``n_steps`` keeps (every ``save_every``-th and the last;
    ``None``: the first and the last)."""
    if save_every is None:
        return 2
    return n_steps // save_every + 1 + (1 if n_steps % save_every else 0)


def keep_index(n_steps: int, save_every: int | None) -> np.ndarray:
    """The steps a run keeps (:func:`kept_samples` of them)."""
    if save_every is None:
        return np.array([0, n_steps])
    idx = np.arange(0, n_steps + 1, save_every)
    if idx[-1] != n_steps:
        idx = np.append(idx, n_steps)
    return idx


def memory_budget(max_memory: float | None) -> float | None:
    """Bytes one run may take: ``max_memory`` if given, else half of the memory free now and
    at most :data:`DEFAULT_MAX_MEMORY` (studies run several at once; ask for more with
    ``max_memory=``); None where the free memory cannot be read."""
    if max_memory is not None:
        return max_memory
    try:
        avail = os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):  # pragma: no cover - non-POSIX
        return None
    return min(0.5 * avail, DEFAULT_MAX_MEMORY)


def check_memory(n_keep: int, chunk: int, nb: int, m: int, n_t: int,
                 max_memory: float | None) -> None:
    """Refuse a run whose histories and buffers would not fit, before allocating them."""
    per_row = 8 * (3 * nb + 4 * m + 5) + m
    need = n_keep * (per_row + 8 * m) + (chunk + 1) * (per_row + 8 * (nb + 2 * m)) + 8 * 4 * n_t
    max_memory = memory_budget(max_memory)
    if max_memory is None:  # pragma: no cover - non-POSIX: the free memory is unknown
        return
    if need > max_memory:
        raise InputError(
            "n_steps", f"{n_t - 1} steps keeping {n_keep} samples of {nb} coordinates and "
            f"{m} sliders ({need / 2**30:.2f} GiB)",
            f"a run that fits in {max_memory / 2**30:.2f} GiB",
            hint="Keep fewer samples (save_every=k, or None with on_chunk for peaks only)",
        )


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
