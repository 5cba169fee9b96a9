"""Entry point of the local engine: :func:`simulate_local` (theory:
``docs/theory/local_engine.md``).

Validate, build (or take) the local basis and report its measured error, estimate the memory
and refuse a run too large before allocating, then integrate in chunks.
"""

from __future__ import annotations

import logging
from collections.abc import Callable

import numpy as np

from seisrack.dynamics import _inputs as chk
from seisrack.dynamics._blas import blas_controller
from seisrack.dynamics._store import keep_index, refuse_over_budget
from seisrack.dynamics.kernels import scheme_kernel, writable
from seisrack.dynamics.local.basis import (
    DEFAULT_PATCH,
    DEFAULT_TOL,
    LocalBasis,
    local_basis,
    measure_error,
)
from seisrack.dynamics.local.result import LocalChunk, LocalHistory
from seisrack.dynamics.local.sliders import LocalSliders
from seisrack.dynamics.results import EVENT_KINDS, STEP_STATUS, Event
from seisrack.errors import InputError, SolverError

_LOG = logging.getLogger(__name__)

DEFAULT_CHUNK = 2000
_STATUS = {**STEP_STATUS, 2: "the step's Newton iteration did not converge (reduce dt)"}


def _kernel(backend: str):  # noqa: ANN202
    return scheme_kernel(backend, "seisrack.dynamics.local._numba",
                         "seisrack.dynamics.local._kernel")


def support_rows(b: LocalBasis, sliders: LocalSliders) -> tuple[np.ndarray, np.ndarray]:
    """(P (m, 2, bmax), ps (m,)): each pallet's support motion from its slice's coordinates
    (the mean of its supports), and that slice. Every support of a pallet must lie in one
    slice."""
    m, k, nd = sliders.support.shape
    where = b._where()  # noqa: SLF001
    P = np.zeros((m, 2, b.bmax))
    ps = np.zeros(m, dtype=np.int64)
    for p in range(m):
        sl = {where[int(d)][0] for d in sliders.support[p].ravel() if d >= 0}
        if len(sl) > 1:
            raise InputError(f"sliders.support[{p}]", sliders.support[p].tolist(),
                             f"supports within one slice (they lie in slices {sorted(sl)})")
        if not sl:
            continue
        s = sl.pop()
        ps[p] = s
        for d in range(nd):
            for j in range(k):
                dof = int(sliders.support[p, j, d])
                if dof >= 0:
                    P[p, d, :b.sizes[s]] += b.blocks[s][where[dof][1]] / k
    return P, ps


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
    chunk = min(int(chunk_steps or (500 if progress is not None else DEFAULT_CHUNK)), n_steps)
    m = sliders.count

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
    N = basis.size
    n_keep = keep_index(n_steps, save_every).size
    need = memory_estimate(n_keep, chunk, N if keep_coordinates else 0, m, basis)
    refuse_over_budget(need, max_memory,
                       f"{n_keep} kept samples of {N if keep_coordinates else 0} coordinates "
                       f"and {m} pallets", "Keep fewer samples (save_every=k, or None with "
                       "on_chunk), or keep_coordinates=False")

    P, ps = support_rows(basis, sliders)
    Vm = basis.matrix()
    pats_r = [-(Vm.T @ (M @ r[d])) for d in range(nd)]
    series = [ag[:, d] for d in range(nd)]
    if rv is not None:
        pats_r.append(-(Vm.T @ (M @ rv)))
        series.append(av)
    pat = np.ascontiguousarray(np.array(pats_r).reshape(len(pats_r), N))
    ser = np.column_stack(series) if series else np.zeros((n_t, 0))
    agp = np.zeros((n_t, 2))
    agp[:, :nd] = ag
    gz = g + (av if av is not None else np.zeros(n_t))
    mod, used = _kernel(backend)

    w = writable
    mats = [w(getattr(basis, k)) for k in ("Md", "Cd", "Kd", "Mo", "Co", "Ko")]
    sizes, offsets = w(basis.sizes), w(basis.offsets)
    mass, mus, mud = w(sliders.mass), w(sliders.mu_static), w(sliders.mu_dynamic)
    q, v, dvp = np.zeros(N), np.zeros(N), np.zeros(N)
    stuck = np.ones(m, dtype=np.bool_)
    sv, dirn, uu, lam, beta = (np.zeros((m, 2)) for _ in range(5))
    jerk = np.zeros((m, 4))  # the jerk estimate and the last difference of beta
    nprev = np.zeros(m, dtype=np.int64)
    Dp = np.zeros((m, 4))
    rows_state = np.zeros((2, m, 19))
    energy = np.zeros(3)
    ev_time = np.empty(max_events + 1)
    ev_pallet = np.empty(max_events + 1, dtype=np.int64)
    ev_kind = np.empty(max_events + 1, dtype=np.int64)
    nq = N if keep_coordinates else 0
    bufs = (np.empty((chunk + 1, nq)), np.empty((chunk + 1, nq)), np.empty((chunk + 1, m, 2)),
            np.empty((chunk + 1, m, 2)), np.empty((chunk + 1, m, 2)),
            np.empty((chunk + 1, m), dtype=np.bool_), np.empty((chunk + 1, 5)))
    keep_idx = keep_index(n_steps, save_every)
    kept = [np.empty((keep_idx.size,) + b.shape[1:], dtype=b.dtype) for b in bufs]
    stats = np.zeros(7, dtype=np.int64)
    status, n_ev, start = 0, 0, 0
    limiter = blas_controller().limit(limits=1, user_api="blas")
    try:
        while start < n_steps:
            stop = min(start + chunk, n_steps)
            rows = slice(start, stop + 1)
            k = stop - start + 1
            outs = tuple(b[:k] for b in bufs)
            left = max(int(max_events) - n_ev, 0)
            st, ne, kd_done = mod.run_local(
                *mats, sizes, offsets, P, ps, nd, mass, mus, mud, float(dt), pat,
                np.ascontiguousarray(ser[rows]), np.ascontiguousarray(agp[rows]),
                np.ascontiguousarray(gz[rows]), start > 0, q, v, dvp, stuck, sv, dirn, uu,
                lam, beta, jerk, nprev, Dp, rows_state, energy, start * float(dt), left, *outs,
                ev_time[n_ev:], ev_pallet[n_ev:], ev_kind[n_ev:], stats)
            n_ev += int(ne)
            status = int(st)
            if on_chunk is not None:
                on_chunk(LocalChunk(np.arange(start, start + k) * dt, outs[0], outs[1],
                                    outs[2][:, :, :nd], outs[3][:, :, :nd], outs[4][:, :, :nd],
                                    outs[5], outs[6]))
            sel = (keep_idx >= start) & (keep_idx <= stop)
            for dst, src in zip(kept, outs, strict=True):
                dst[sel] = src[keep_idx[sel] - start]
            if status != 0:
                last = start + int(kd_done)
                keep_n = int(np.searchsorted(keep_idx, last, side="right"))
                keep_idx = keep_idx[:keep_n]
                kept = [a[:keep_n] for a in kept]
                break
            if progress is not None:
                progress(stop - start)
            start = stop
    finally:
        limiter.restore_original_limits()
    status_text = _STATUS.get(status, f"status {status}")
    if status != 0:
        msg = f"local stick–slip engine stopped: {status_text}"
        if throw:
            raise SolverError(msg)
        _LOG.warning(msg)
    n_rec = min(n_ev, max_events)
    order = np.argsort(ev_time[:n_rec], kind="stable")
    events = [Event(float(ev_time[i]), int(ev_pallet[i]), EVENT_KINDS[int(ev_kind[i])])
              for i in order]
    kq, kv, ku, ks, kl, kst, ke = kept
    normal = np.clip(np.outer(gz[keep_idx], sliders.mass), 0.0, None)
    energy_d = {"input": ke[:, 0], "kinetic": ke[:, 1], "strain": ke[:, 2],
                "damping": ke[:, 3], "friction": ke[:, 4], "hysteresis": np.zeros(len(ke))}
    return LocalHistory(
        t=keep_idx * dt, q=kq, v=kv, sliding=ku[:, :, :nd], velocity=ks[:, :, :nd],
        friction=kl[:, :, :nd], normal=normal, stuck=kst, events=events,
        sample_index=keep_idx, energy=energy_d, local_basis=basis, status=status_text,
        backend=used, basis=basis.describe(),
        work=dict(zip(("steps", "newton_iterations", "factorisations", "local_solves",
                       "line_search_evaluations", "frozen_contacts", "loose_steps"),
                      (int(x) for x in stats),
                      strict=True)))


def memory_estimate(n_keep: int, chunk: int, nq: int, m: int, basis: LocalBasis) -> int:
    """Bytes the run's kept histories, chunk buffers and kernel work arrays take."""
    per_row = 8 * (2 * nq + 6 * m + 5) + m
    work = 8 * (13 * basis.n_slices * basis.bmax**2 + 12 * basis.size + 40 * m
                + 2 * m * basis.bmax)
    return n_keep * (per_row + 8 * m) + (chunk + 1) * per_row + work
