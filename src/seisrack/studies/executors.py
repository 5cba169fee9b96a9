"""Executors: run batches of study runs on a local process pool or a Dask cluster.

The worker side is :func:`run_batch`: it runs each :class:`~seisrack.studies.expand.Run` of a
batch and returns one row (a dict, the store's schema) per run. A worker limits BLAS to one
thread (with the default threaded OpenBLAS, the engine's small dense algebra costs 10–150× more
CPU on a loaded machine), and caches compiled models and scaled records per process. A run that
fails (a :class:`~seisrack.errors.SeisrackError`, a solver status other than "ok", or any other
exception) is a row with ``status = "failed"`` and the reason; it never stops the batch.

IDA with a stop rule (``plan.ida_stop``): a batch holds whole IDA curves (the driver's
batching keeps them together); :func:`run_batch` runs each curve's levels in increasing order
and, from the first level where the rule holds, returns "skipped" rows (:func:`skipped_row`)
for the levels above instead of running them. The rows depend on the curve only, never on how
curves are batched, so they are the same on any executor and number of workers.

The executors are strategies with one method, ``run(batches)``, an iterator over the rows of
each finished batch, in completion order:

- :class:`LocalExecutor`: ``concurrent.futures.ProcessPoolExecutor``; a worker killed by a
  signal breaks the pool: the pool is rebuilt and the unfinished batches resubmitted (split
  into single runs on the second failure; a run that kills its worker three times is recorded
  as failed);
- :class:`DaskExecutor`: a ``dask.distributed.Client`` on a scheduler address, or on a
  ``LocalCluster(n_workers, threads_per_worker=1)``; the context (racks, records) is scattered
  once to every worker.

Results do not depend on the executor: every run is computed from its own inputs only, by the
same code, with one BLAS thread.
"""

from __future__ import annotations

import json
import logging
import math
import os
import time
from collections import deque
from collections.abc import Iterator
from typing import Any

import numpy as np

from seisrack.errors import SeisrackError

log = logging.getLogger(__name__)

#: test hook (JSON): {"kill_once": [run_id, flag_file], "fail": [run_id, ...], "sleep": s}
TEST_HOOK_ENV = "SEISRACK_STUDY_TEST_HOOK"

_CTX: Any = None  # the StudyPlan (without its runs) of the current process
_CTX_ID: str | None = None
_MODELS: dict = {}
_RECORDS: dict = {}
_RIGID: dict = {}  # rigid-pallet companion peaks by (rack, occupancy, record, scale)
_LIMITER: Any = None
_CACHE_MAX = 128
#: [s] how long a --scheduler address may take to answer as a Dask scheduler
SCHEDULER_TIMEOUT_S = 15


def _worker_init(ctx: Any, parent_pid: int) -> None:
    """Initializer of a pool worker: follow the driver if it dies (no orphans, see
    :mod:`seisrack.studies.lifeline`), then take the study's context."""
    from seisrack.studies.lifeline import die_with_parent

    die_with_parent(parent_pid)
    _set_context(ctx)


def _set_context(ctx: Any, ctx_id: str | None = None) -> None:
    global _CTX, _CTX_ID, _LIMITER
    if ctx_id is not None and ctx_id == _CTX_ID:
        return
    _CTX, _CTX_ID = ctx, ctx_id
    _MODELS.clear()
    _RECORDS.clear()
    _RIGID.clear()
    if _LIMITER is None:
        from threadpoolctl import threadpool_limits

        _LIMITER = threadpool_limits(1)  # kept for the life of the worker process


def run_batch(batch: list) -> list[dict[str, Any]]:
    """Rows of the runs of ``batch`` (worker side; the context was set by the initializer)."""
    rule = getattr(_CTX, "ida_stop", None)
    if rule is None:
        return [run_one(r) for r in batch]
    rows = []
    for curve in split_curves(batch):
        stop = None  # the run at which the rule held
        for r in sorted(curve, key=lambda r: r.im_target):
            if stop is not None:
                rows.append(skipped_row(r, stop.im_target, rule))
                continue
            row = run_one(r)
            rows.append(row)
            if rule.holds(row):
                stop = r
    return rows


def split_curves(runs: list) -> list[list]:
    """``runs`` grouped by IDA curve (:func:`~seisrack.studies.expand.curve_key`), in order of
    first appearance."""
    from seisrack.studies.expand import curve_key

    groups: dict = {}
    for r in runs:
        groups.setdefault(curve_key(r), []).append(r)
    return list(groups.values())


def run_batch_ctx(ctx: Any, ctx_id: str, batch: list) -> list[dict[str, Any]]:
    """:func:`run_batch` with its context passed in (Dask: a scattered future)."""
    _set_context(ctx, ctx_id)
    return run_batch(batch)


def _hook(run) -> None:  # noqa: ANN001
    text = os.environ.get(TEST_HOOK_ENV)
    if not text:
        return
    hook = json.loads(text)
    if hook.get("sleep"):
        time.sleep(float(hook["sleep"]))
    kill = hook.get("kill_once")
    if kill and kill[0] == run.run_id and not os.path.exists(kill[1]):
        with open(kill[1], "w") as fh:
            fh.write(str(os.getpid()))
        import signal

        os.kill(os.getpid(), signal.SIGKILL)
    if run.run_id in hook.get("fail", ()):
        raise SeisrackError(f"test hook: run {run.run_id} made to fail")


def _model(run):  # noqa: ANN001, ANN202
    """(model with the run's friction, rack spec as loaded, prepared run) for ``run``.

    Friction enters the compiled model only through its pallet friction arrays, and what a
    run prepares (:func:`seisrack.analysis.prepare_run`: the basis and the operators) depends
    on the structure and the pallet masses only: both are built once per (rack, occupancy) and
    process; a run replaces the friction arrays (exactly what
    ``compile_rack(with_friction(rack, mu_s, mu_d))`` gives).
    """
    from dataclasses import replace

    key = (run.rack_hash, run.occupancy)
    hit = _MODELS.get(key)
    if hit is None:
        from seisrack.model import compile_rack
        from seisrack.studies.expand import apply_pattern

        rack = apply_pattern(_CTX.racks[run.rack_hash], _CTX.patterns[key])
        from seisrack.analysis import prepare_run

        model = compile_rack(rack)
        hit = (model, rack, prepare_run(model))
        if len(_MODELS) >= _CACHE_MAX:
            _MODELS.clear()
        _MODELS[key] = hit
    model, rack, prepared = hit
    n = model.pallet_mass.shape[0]
    model = replace(model, pallet_mu_static=np.full(n, float(run.mu_static)),
                    pallet_mu_dynamic=np.full(n, float(run.mu_dynamic)))
    return model, rack, prepared


def _scaled(run):  # noqa: ANN001, ANN202
    """The run's ground motion: its record (every component) scaled by the run's factor, a
    pair or a turned motion as a GroundMotion (3D racks)."""
    key = (run.record_hash, run.scale_factor, getattr(run, "angle_deg", 0.0))
    rec = _RECORDS.get(key)
    if rec is None:
        from seisrack.motion import Record
        from seisrack.motion.components import combine

        comps = tuple(Record(c.accel * run.scale_factor, c.dt, name=c.name,
                             provenance=f"{c.provenance}, scaled by {run.scale_factor:.6g}")
                      for c in _CTX.records[run.record_hash])
        angle = getattr(run, "angle_deg", 0.0)
        rec = comps[0] if len(comps) == 1 and angle == 0.0 else combine(
            comps[0], comps[1] if len(comps) > 1 else None, None, angle)
        if not isinstance(rec, Record) and _CTX.racks[run.rack_hash].ndm == 2:
            # a warehouse's 2D row: the motion along its down-aisle axis
            rec = Record(rec.x, rec.dt, name=comps[0].name,
                         provenance=f"{comps[0].provenance}, along a row at {-angle:g} deg")
        if len(_RECORDS) >= _CACHE_MAX:
            _RECORDS.clear()
        _RECORDS[key] = rec
    return rec


def _inputs(run) -> dict[str, Any]:  # noqa: ANN001
    return {"run_id": run.run_id, "rack": run.rack, "record": run.record,
            "im_measure": run.im_measure, "im_target": run.im_target,
            "scale_factor": run.scale_factor, "stripe": run.stripe, "mu_static": run.mu_static,
            "mu_dynamic": run.mu_dynamic, "occupancy": run.occupancy, "seed": run.seed,
            "angle_deg": float(getattr(run, "angle_deg", 0.0))}


def failed_row(run, reason: str, wall: float = math.nan) -> dict[str, Any]:  # noqa: ANN001
    nan = math.nan
    return {**_inputs(run), "status": "failed", "error": reason, "peak_sliding_max_m": nan,
            "pallet_peak_sliding_m": [], "n_pallets": 0, "any_fall": False, "n_fall": 0,
            "base_shear_N": nan, "beam_displacement_max_m": nan, "drift_ratio_max": nan,
            "upright_moment_connection_Nm": nan, "wall_time_s": wall,
            **dict.fromkeys(REDUCTION_COLUMNS, nan), "any_aisle_fall": False,
            "n_aisle_fall": 0, **dict.fromkeys(DIRECTION_COLUMNS, nan)}


def skipped_row(run, stop_im: float, rule) -> dict[str, Any]:  # noqa: ANN001
    """The row of an IDA level above the stop level ``stop_im`` [m/s²]: not run."""
    return {**failed_row(run, f"IDA stopped at IM = {stop_im!r} m/s² by rule {rule.label}",
                         0.0), "status": "skipped"}


def run_one(run) -> dict[str, Any]:  # noqa: ANN001
    """Scale the record, compile the rack with the run's friction, run it, extract the row."""
    from seisrack.analysis import run_rack

    t0 = time.perf_counter()
    try:
        _hook(run)
        model, rack, prepared = _model(run)
        res = run_rack(model, _scaled(run), dt=_CTX.dt, save_every=None, track_energy=False,
                       throw=False, prepared=prepared)
        if res.status != "ok":
            return failed_row(run, f"solver status: {res.status}", time.perf_counter() - t0)
        fp = res.full_peaks
        sliding = res.pallet_peak_sliding()
        disp = np.asarray(fp["beam_displacement"], dtype=float)[:, 0]
        # drift: an envelope from the per-level peaks (exact for one level; above, peaks of
        # adjacent levels need not be simultaneous)
        heights = np.asarray(rack.geometry.levels, dtype=float)
        drift = np.abs(np.diff(np.concatenate([[0.0], disp]))) / heights
        at_risk = res.pallets_at_risk()
        return {**_inputs(run), "status": "ok", "error": "",
                "peak_sliding_max_m": float(sliding.max()) if sliding.size else 0.0,
                "pallet_peak_sliding_m": [float(s) for s in sliding],
                "n_pallets": int(res.n_pallets), "any_fall": bool(at_risk),
                "n_fall": len(at_risk), "base_shear_N": float(np.max(fp["base_shear"])),
                "beam_displacement_max_m": float(disp.max()),
                "drift_ratio_max": float(drift.max()),
                "upright_moment_connection_Nm": float(np.max(fp["upright_moment_connection"])),
                **_reduction_columns(run, res, model, prepared),
                **_direction_columns(res),
                "wall_time_s": time.perf_counter() - t0}
    except Exception as exc:  # noqa: BLE001 - a failed run is a row, never a stopped study
        kind = "" if isinstance(exc, SeisrackError) else f"{type(exc).__name__}: "
        return failed_row(run, f"{kind}{exc}", time.perf_counter() - t0)


#: per-direction peak sliding columns (null cross-aisle on a 2D rack: not applicable)
DIRECTION_COLUMNS = ("peak_sliding_down_aisle_max_m", "peak_sliding_cross_aisle_max_m")


def _direction_columns(res) -> dict[str, Any]:  # noqa: ANN001
    """Falls into the aisles (3D racks; none on a 2D rack) and the peak sliding along each
    direction."""
    by_dir = res.pallet_peak_sliding_by_direction()
    peak = by_dir.max(axis=0) if by_dir.size else np.zeros(by_dir.shape[1])
    aisle = sum(1 for f in res.falls if f.into_aisle)  # a back-to-back rack's flue excluded
    return {"any_aisle_fall": aisle > 0, "n_aisle_fall": aisle,
            "peak_sliding_down_aisle_max_m": float(peak[0]),
            "peak_sliding_cross_aisle_max_m": float(peak[1]) if peak.size > 1 else None}


#: columns of the sliding reduction (issue 24 item 2): this run's seismic connector and upright
#: moments, and the peaks of the same rack and scaled record with the pallets held rigidly
#: (rigid_alpha: its peak absolute level acceleration over g, the paper's alpha)
REDUCTION_COLUMNS = ("connector_moment_Nm", "upright_moment_Nm", "rigid_base_shear_N",
                     "rigid_connector_moment_Nm", "rigid_upright_moment_Nm",
                     "rigid_alpha")


def _reduction_columns(run, res, model, prepared) -> dict[str, float]:  # noqa: ANN001
    """This run's peaks for the sliding reduction and its rigid companion's (the rigid run
    depends on the rack, occupancy, record, scale and incidence angle only: one per process
    and key)."""
    from seisrack.design.sliding_reduction import response_peaks, rigid_model

    mine = response_peaks(res)
    key = (run.rack_hash, run.occupancy, run.record_hash, run.scale_factor,
           getattr(run, "angle_deg", 0.0))
    rigid = _RIGID.get(key)
    if rigid is None:
        rigid = dict.fromkeys(REDUCTION_COLUMNS[2:], math.nan)
        if model.n_pallets:
            from seisrack.analysis import run_rack

            try:
                r = run_rack(rigid_model(model), _scaled(run), dt=_CTX.dt, save_every=None,
                             track_energy=False, throw=False, prepared=prepared)
            except Exception as exc:  # noqa: BLE001 - the companion never fails the run
                log.warning("rigid companion of run %s failed: %s", run.run_id, exc)
                r = None
            if r is not None and r.status == "ok":
                p = response_peaks(r)
                rigid = {"rigid_base_shear_N": p["base_shear_N"],
                         "rigid_connector_moment_Nm": p["connector_moment_Nm"],
                         "rigid_upright_moment_Nm": p["upright_moment_Nm"],
                         "rigid_alpha": p["level_acceleration_m_s2"] / float(model.g)}
        if len(_RIGID) >= _CACHE_MAX:
            _RIGID.clear()
        _RIGID[key] = rigid
    return {"connector_moment_Nm": mine["connector_moment_Nm"],
            "upright_moment_Nm": mine["upright_moment_Nm"], **rigid}


def _context_of(plan) -> Any:  # noqa: ANN001
    from dataclasses import replace

    return replace(plan, runs=())


class LocalExecutor:
    """A ``ProcessPoolExecutor`` with ``workers`` processes (default: one per core)."""

    name = "local"

    def __init__(self, plan, workers: int | None = None) -> None:  # noqa: ANN001
        self.ctx = _context_of(plan)
        self.workers = workers or os.cpu_count() or 1

    def run(self, batches: list[list]) -> Iterator[list[dict[str, Any]]]:
        from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
        from concurrent.futures.process import BrokenProcessPool

        pending = deque((b, 0) for b in batches)
        while pending:
            pool = ProcessPoolExecutor(self.workers, initializer=_worker_init,
                                       initargs=(self.ctx, os.getpid()))
            inflight: dict = {}
            broken: list = []
            try:
                while (pending or inflight) and not broken:
                    while pending and len(inflight) < 2 * self.workers:
                        b, a = pending.popleft()
                        inflight[pool.submit(run_batch, b)] = (b, a)
                    done, _ = wait(inflight, return_when=FIRST_COMPLETED)
                    for f in done:
                        b, a = inflight.pop(f)
                        try:
                            rows = f.result()
                        except BrokenProcessPool:
                            broken.append((b, a))
                            continue
                        yield rows
            finally:
                pool.shutdown(wait=True, cancel_futures=True)
            if broken:
                broken.extend(inflight.values())
                log.warning("a worker process died: resubmitting %d batch(es)", len(broken))
                yield from self._requeue(broken, pending)

    def _requeue(self, broken: list, pending: deque) -> Iterator[list[dict[str, Any]]]:
        # the unit of a split: one run, or one IDA curve with a stop rule (run in order)
        for b, a in broken:
            units = split_curves(b) if self.ctx.ida_stop is not None else [[r] for r in b]
            if a == 0:
                pending.append((b, 1))
            elif len(units) > 1:
                pending.extend((u, 2) for u in units)
            elif a < 3:
                pending.append((b, a + 1))
            else:
                yield [failed_row(r, "the worker process died (killed by a signal?) three "
                                     "times on this run" + (" or its IDA curve" if len(b) > 1
                                                            else "")) for r in b]


class DaskExecutor:
    """Batches on a Dask cluster: ``scheduler`` address, or a new ``LocalCluster``."""

    name = "dask"

    def __init__(self, plan, workers: int | None = None,  # noqa: ANN001
                 scheduler: str | None = None) -> None:
        self.ctx = _context_of(plan)
        self.workers = workers or os.cpu_count() or 1
        self.scheduler = scheduler

    def run(self, batches: list[list]) -> Iterator[list[dict[str, Any]]]:
        import uuid

        from dask.distributed import Client, LocalCluster, as_completed

        if not log.isEnabledFor(logging.INFO):  # dask sets its loggers to INFO: quiet them
            for name in ("distributed", "dask"):
                logging.getLogger(name).setLevel(logging.WARNING)
        cluster = None
        if self.scheduler:
            try:
                client = Client(self.scheduler, timeout=f"{SCHEDULER_TIMEOUT_S}s")
            except Exception as exc:  # noqa: BLE001 - whatever answered is not a scheduler
                # (an HTTP server's reply read as a Dask frame length asks for exabytes: a
                # MemoryError; nothing at all: a timeout; a bad address: ValueError)
                from seisrack.errors import InputError

                why = str(exc).strip().splitlines()[0][:200] if str(exc).strip() else ""
                raise InputError("--scheduler", self.scheduler, "the address of a running Dask "
                                 "scheduler, e.g. tcp://SCHEDULER-HOST:8786",
                                 hint=f"What is there is not a Dask scheduler, or it did not "
                                      f"answer within {SCHEDULER_TIMEOUT_S} s "
                                      f"({type(exc).__name__}"
                                      + (f": {why}" if why else "") + ")") from None
        else:
            # on the loopback interface: a local cluster is nobody else's business
            cluster = LocalCluster(n_workers=self.workers, threads_per_worker=1, processes=True,
                                   host="127.0.0.1", dashboard_address=None,
                                   silence_logs=logging.WARNING)
            client = Client(cluster)
        try:
            ctx = client.scatter(self.ctx, broadcast=True)
            ctx_id = uuid.uuid4().hex
            futures = {client.submit(run_batch_ctx, ctx, ctx_id, b, pure=False): b
                       for b in batches}
            for f in as_completed(futures):
                b = futures.pop(f)
                try:
                    rows = f.result()
                except Exception as exc:  # noqa: BLE001 - e.g. KilledWorker: runs fail
                    rows = [failed_row(r, f"dask task failed: {type(exc).__name__}: {exc}")
                            for r in b]
                f.release()
                yield rows
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
