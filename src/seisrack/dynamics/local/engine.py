"""Entry point of the local engine: :func:`simulate_local` (theory:
``docs/theory/local_engine.md``).

Validate, build (or take) the local basis and report its measured error, then hand the run to
:func:`seisrack.dynamics.local.scheme.run_local_scheme` (memory estimated and a run too large
refused before allocating, then the chunked integration).
"""

from __future__ import annotations

import logging
from collections.abc import Callable

import numpy as np

from seisrack.dynamics import _inputs as chk
from seisrack.dynamics.local.basis import (
    DEFAULT_PATCH,
    DEFAULT_TOL,
    LocalBasis,
    local_basis,
    measure_error,
)
from seisrack.dynamics.local.result import LocalChunk, LocalHistory
from seisrack.dynamics.local.scheme import memory_estimate, run_local_scheme
from seisrack.dynamics.local.sliders import LocalSliders
from seisrack.errors import InputError

__all__ = ["memory_estimate", "simulate_local"]

_LOG = logging.getLogger(__name__)


def simulate_local(
    M, C, K, sliders: LocalSliders, *,  # noqa: ANN001, N803
    dt: float,
    ground: np.ndarray | None = None,
    influence: np.ndarray | None = None,
    vertical_accel: np.ndarray | None = None,
    vertical_influence: np.ndarray | None = None,
    g: float = 9.81,
    n_steps: int | None = None,
    slices: np.ndarray | None = None,
    basis: LocalBasis | None = None,
    global_loads: np.ndarray | None = None,
    tol: float = DEFAULT_TOL,
    patch: int = DEFAULT_PATCH,
    check: str = "static",
    accuracy: float | None = None,
    hinges: object | None = None,
    save_every: int | None = 1,
    keep_coordinates: bool = True,
    chunk_steps: int | None = None,
    on_chunk: Callable[[LocalChunk], None] | None = None,
    progress: Callable[[int], None] | None = None,
    max_events: int = 2_000_000,
    max_memory: float | None = None,
    throw: bool = True,
    backend: str = "auto",
) -> LocalHistory:
    """Time history of a linear structure (M, C, K: sparse or dense; M without the pallets'
    horizontal masses) carrying pallets that stick or slide in ``sliders.n_dir`` directions.

    ground: (n_steps + 1, n_dir) [m/s²] ground accelerations along the sliding directions,
    linear between samples; influence: (n_dir, n) their influence vectors. vertical_accel:
    normal forces m (g + a_v) (clipped at 0) and, with ``vertical_influence``, the load
    −M r_v a_v. slices: (n,) slice of each DOF (default: one slice); basis: a prebuilt
    :class:`LocalBasis` (else built with ``tol``, ``patch``, ``global_loads``). check: the
    basis error measured against the full model, "static" (static responses), "full" (plus
    the lowest frequencies) or "none"; accuracy: refuse a basis whose measured static energy
    error exceeds it (else a warning above 0.2). keep_coordinates: keep q, v at the kept
    samples (for DOF histories); save_every, on_chunk, progress, max_memory, throw, backend as
    :func:`seisrack.dynamics.simulate`.
    """
    if hinges is not None:
        raise InputError("hinges", type(hinges).__name__,
                         "None: nonlinear connections are not built in the local engine yet")
    M = chk.square("M", M, None)
    n = M.shape[0]
    C = chk.square("C", C, n)
    K = chk.square("K", K, n)
    if not isinstance(sliders, LocalSliders):
        raise InputError("sliders", type(sliders).__name__, "a LocalSliders")
    nd = sliders.n_dir
    sup = sliders.support
    if np.any(sup < -1) or np.any(sup >= n):
        raise InputError("sliders.support", sup[(sup < -1) | (sup >= n)].tolist(),
                         f"DOF indices in [0, {n - 1}] or -1 (the ground)")
    if not (isinstance(dt, int | float) and np.isfinite(dt) and dt > 0):
        raise InputError("dt", dt, "a finite time step > 0 s")
    if not (np.isfinite(g) and g > 0):
        raise InputError("g", g, "a finite gravity > 0 m/s²")
    if check not in ("static", "full", "none"):
        raise InputError("check", check, '"static", "full" or "none"')
    lengths = [np.shape(a)[0] for a in (ground, vertical_accel) if a is not None]
    if n_steps is None:
        if not lengths:
            raise InputError("n_steps", None, "a number of steps when no excitation is given")
        n_steps = lengths[0] - 1
    n_steps = chk.positive_int("n_steps", n_steps)
    n_t = n_steps + 1
    ag = np.zeros((n_t, nd)) if ground is None else chk.series("ground", np.reshape(
        ground, (np.shape(ground)[0], -1)), (n_t, nd))
    if ground is not None:
        if influence is None:
            raise InputError("influence", None, f"({nd}, {n}) influence vectors of the ground "
                             "components")
        r = chk.series("influence", np.reshape(influence, (nd, -1)), (nd, n))
    else:
        r = np.zeros((nd, n))
    av = None if vertical_accel is None else chk.series("vertical_accel", vertical_accel,
                                                         (n_t,))
    rv = None if (av is None or vertical_influence is None) else chk.series(
        "vertical_influence", vertical_influence, (n,))
    if save_every is not None:
        save_every = chk.positive_int("save_every", save_every)
    loads = [M @ r[d] for d in range(nd)] + ([M @ rv] if rv is not None else [])
    L = np.column_stack(loads) if loads else np.zeros((n, 0))
    if not np.any(L):  # nothing loads the structure: its own static shape under 1s
        L = np.ones((n, 1))
    pats = sliders.patterns(n)
    extra = sliders.attached_mass(n)
    if basis is None:
        sl = np.zeros(n, dtype=np.int64) if slices is None else np.asarray(slices)
        gl = global_loads
        basis = local_basis(M, C, K, sl, L, pats,
                            global_loads=gl, mass_extra=extra, tol=tol, patch=patch)
    elif not isinstance(basis, LocalBasis) or basis.n_dof != n:
        raise InputError("basis", type(basis).__name__, f"a LocalBasis of this structure "
                         f"({n} DOFs)")
    if check != "none" and not basis.error:
        err = measure_error(basis, M, K, L, pats,
                            mass_extra=extra, n_modes=8 if check == "full" else 0)
        object.__setattr__(basis, "error", err)
    worst = basis.error.get("static_energy_max") if basis.error else None
    if worst is not None:
        if accuracy is not None and worst > accuracy:
            raise InputError("accuracy", accuracy, f"a looser accuracy, or a tighter basis tol: "
                             f"the basis' static energy error is {worst:.3g}")
        if worst > 0.2:
            _LOG.warning("local basis: static energy error %.3g of the load patterns", worst)
    return run_local_scheme(M, sliders, basis, dt=float(dt), ag=ag, r=r, av=av, rv=rv, g=g,
                            save_every=save_every, keep_coordinates=keep_coordinates,
                            chunk_steps=chunk_steps, on_chunk=on_chunk, progress=progress,
                            max_events=max_events, max_memory=max_memory, throw=throw,
                            backend=backend)
