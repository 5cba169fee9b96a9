"""The local engine's chunked integration with a validated basis: :func:`run_local_scheme`
(theory: ``docs/theory/local_engine.md``), called by :func:`seisrack.dynamics.local.
simulate_local` and by a rack's prepared run. The memory of the run is estimated and a run too
large refused before allocating.
"""

from __future__ import annotations

import logging
from collections.abc import Callable

import numpy as np

from seisrack.dynamics._blas import blas_controller
from seisrack.dynamics._store import check_kept_memory
from seisrack.dynamics.kernels import scheme_kernel, writable_all
from seisrack.dynamics.local.basis import LocalBasis
from seisrack.dynamics.local.result import LocalChunk, LocalHistory, central_accelerations
from seisrack.dynamics.local.sliders import LocalSliders
from seisrack.dynamics.results import STEP_STATUS, recorded_events, run_status
from seisrack.errors import InputError

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


def run_local_scheme(M, sliders: LocalSliders, basis: LocalBasis, *,  # noqa: ANN001, N803
                     dt: float, ag: np.ndarray, r: np.ndarray, av: np.ndarray | None,
                     rv: np.ndarray | None, g: float, save_every: int | None = 1,
                     keep_coordinates: bool = True, chunk_steps: int | None = None,
                     on_chunk: Callable[[LocalChunk], None] | None = None,
                     progress: Callable[[int], None] | None = None,
                     max_events: int = 2_000_000, max_memory: float | None = None,
                     throw: bool = True, backend: str = "auto") -> LocalHistory:
    """The run of :func:`~seisrack.dynamics.local.simulate_local` once its inputs are checked:
    ``M`` the structure's mass (its ground loads), ``basis`` the local basis, ``ag`` (n_t,
    n_dir) [m/s²] the ground accelerations on the step ``dt`` and ``r`` (n_dir, n) their
    influence vectors, ``av``/``rv`` the vertical ones or None; other keywords as
    ``simulate_local``."""
    n_t, nd = ag.shape
    n_steps = n_t - 1
    chunk = min(int(chunk_steps or (500 if progress is not None else DEFAULT_CHUNK)), n_steps)
    m = sliders.count
    N = basis.size
    nq = N if keep_coordinates else 0
    per_sample, fixed = memory_terms(chunk, nq, m, basis)
    P, ps = support_rows(basis, sliders)  # small: (2m, patch) rows
    described = basis.describe()
    keep_idx = check_kept_memory(n_steps, save_every, per_sample, fixed, max_memory,
                                 f"{nq} coordinates and {m} pallets", "Keep fewer samples "
                                 "(save_every=k, or None with on_chunk), or "
                                 "keep_coordinates=False")
    Vm = basis.phi
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

    *mats, sizes, offsets, mass, mus, mud = writable_all(
        basis.Md, basis.Cd, basis.Kd, basis.Mo, basis.Co, basis.Ko, basis.sizes, basis.offsets,
        sliders.mass, sliders.mu_static, sliders.mu_dynamic)
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
    bufs = (np.empty((chunk + 1, nq)), np.empty((chunk + 1, nq)), np.empty((chunk + 1, m, 2)),
            np.empty((chunk + 1, m, 2)), np.empty((chunk + 1, m, 2)),
            np.empty((chunk + 1, m), dtype=np.bool_), np.empty((chunk + 1, 5)))
    acc = np.empty((chunk + 1, nq))  # the central differences of v
    kept = [np.empty((keep_idx.size,) + b.shape[1:], dtype=b.dtype) for b in (*bufs, acc)]
    v_prev = None
    stats = np.zeros(12, dtype=np.int64)
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
            a = central_accelerations(outs[1], v_prev, dt, acc[:k])
            v_prev = outs[1][-2].copy() if k >= 2 else None
            if on_chunk is not None:
                on_chunk(LocalChunk(np.arange(start, start + k) * dt, outs[0], outs[1],
                                    outs[2][:, :, :nd], outs[3][:, :, :nd], outs[4][:, :, :nd],
                                    outs[5], outs[6], a))
            sel = (keep_idx >= start) & (keep_idx <= stop)
            for dst, src in zip(kept, (*outs, a), strict=True):
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
    status_text = run_status(status, _STATUS, "local stick–slip engine", throw, _LOG)
    events = recorded_events(ev_time, ev_pallet, ev_kind, min(n_ev, max_events), by_time=True)
    kq, kv, ku, ks, kl, kst, ke, ka = kept
    normal = np.clip(np.outer(gz[keep_idx], sliders.mass), 0.0, None)
    energy_d = {"input": ke[:, 0], "kinetic": ke[:, 1], "strain": ke[:, 2],
                "damping": ke[:, 3], "friction": ke[:, 4], "hysteresis": np.zeros(len(ke))}
    return LocalHistory(
        t=keep_idx * dt, q=kq, v=kv, a=ka, sliding=ku[:, :, :nd], velocity=ks[:, :, :nd],
        friction=kl[:, :, :nd], normal=normal, stuck=kst, events=events,
        sample_index=keep_idx, energy=energy_d, local_basis=basis, status=status_text,
        backend=used, basis=described,
        work=dict(zip(("steps", "newton_iterations", "factorisations", "local_solves",
                       "line_search_evaluations", "frozen_contacts", "loose_steps",
                       "retried_steps", "placed_onsets", "slipped_at_step_end",
                       "retry_local_solves", "frozen_steps"),
                      (int(x) for x in stats),
                      strict=True)))


def memory_estimate(n_keep: int, chunk: int, nq: int, m: int, basis: LocalBasis) -> int:
    """Bytes the run's kept histories, chunk buffers and kernel work arrays take."""
    per_sample, fixed = memory_terms(chunk, nq, m, basis)
    return n_keep * per_sample + fixed


def memory_terms(chunk: int, nq: int, m: int, basis: LocalBasis) -> tuple[int, int]:
    """(bytes per kept sample, bytes of the chunk buffers and kernel work arrays) of a run
    keeping ``nq`` coordinates and ``m`` pallets per sample."""
    per_row = 8 * (3 * nq + 6 * m + 5) + m
    work = 8 * (13 * basis.n_slices * basis.bmax**2 + 12 * basis.size + 40 * m
                + 2 * m * basis.bmax)
    return per_row + 8 * m, (chunk + 1) * per_row + work
