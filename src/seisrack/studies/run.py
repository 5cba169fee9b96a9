"""Run a study: expand, skip what is stored, execute in batches, append to the store.

:func:`run_study` is the driver. It expands the study (all input errors are raised here, before
any run), sets aside unreadable part files, writes ``study.json`` (refused when the folder
holds another study: :func:`~seisrack.studies.store.check_extends`), reads the run ids already
in the store and runs only the others, in batches (:data:`DEFAULT_BATCH` runs per task, fewer
when there are few runs, so that every worker gets work). Rows come back as batches finish and
wait in a buffer of at most ``flush_rows`` rows (or ``flush_seconds`` seconds) before being
written as one Parquet part file: the driver's memory does not grow with the study. On Ctrl-C
the buffer is flushed before the interrupt propagates; a driver killed outright loses at most
its buffer, which a resumed run recomputes.

IDA with a stop rule: batches hold whole IDA curves (the worker runs a curve's levels in order
and skips those above the level where the rule holds); the rows of one batch are written in
one part file, so a curve is stored whole or not at all. A stored "skipped" row counts as done
while the study's rule is the one that skipped it; with another rule (or none) the level is run
again. Levels missing from the store above a stored level where the rule holds (e.g. a grid
extended upwards) are recorded as skipped by the driver without a task.
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from seisrack.errors import InputError
from seisrack.studies.expand import Run, StudyPlan, curve_key, plan
from seisrack.studies.spec import IdaStop, StudySpec
from seisrack.studies.store import (
    check_parts,
    part_files,
    read_runs,
    stored_run_ids,
    write_part,
    write_study_json,
)

log = logging.getLogger(__name__)

DEFAULT_BATCH = 32
EXECUTORS = ("local", "dask")


@dataclass(frozen=True)
class StudyRunSummary:
    """What one call of :func:`run_study` did (counts over the runs of the study)."""

    out_dir: str
    runs_total: int  # runs of the study
    runs_already_stored: int  # skipped (resume)
    runs_executed: int  # run by a worker (ok + failed)
    runs_ok: int  # of the executed runs
    runs_failed: int
    runs_skipped: int  # IDA levels above a stop rule's level, recorded without being run
    wall_time_s: float
    executor: str
    workers: int
    part_files_written: int
    #: part files found unreadable or foreign and moved to runs/quarantine/ (their runs were
    #: recomputed): :meth:`seisrack.studies.store.SetAside.message` of each
    parts_set_aside: tuple[str, ...] = ()


#: local workers allowed per CPU of the machine: each is a process with its own copy of the
#: model and its numba code (some 100 MB); beyond the cores they only share them (300 workers
#: on 2 cores ran a 6-run study 12 times slower and forked 9 GB of processes). A cluster is for
#: more (``--executor dask``)
LOCAL_WORKERS_PER_CPU = 4


def check_local_workers(workers: int | None, field: str = "workers") -> None:
    """Refuse more local workers than :data:`LOCAL_WORKERS_PER_CPU` per CPU."""
    import os

    n_cpu = os.cpu_count() or 1
    if workers is not None and workers > LOCAL_WORKERS_PER_CPU * n_cpu:
        raise InputError(field, workers, f"at most {LOCAL_WORKERS_PER_CPU * n_cpu} local "
                         f"workers on this machine ({n_cpu} CPUs)", hint="Each worker is a "
                         "process of its own; more than the cores only slow the study. Use "
                         "--executor dask with a cluster for more")


def make_batches(runs: Sequence[Run], workers: int, batch_size: int | None = None,
                 *, by_curve: bool = False) -> list[list[Run]]:
    """Consecutive batches: ``batch_size`` runs each, or fewer so every worker gets ~4.

    by_curve: never split an IDA curve (:func:`~seisrack.studies.expand.curve_key`): whole
    curves are packed up to ``batch_size`` runs, a longer curve is a batch of its own.
    """
    if not runs:
        return []
    size = batch_size or max(1, min(DEFAULT_BATCH, math.ceil(len(runs) / (4 * workers))))
    if not by_curve:
        return [list(runs[i:i + size]) for i in range(0, len(runs), size)]
    curves: dict = {}
    for r in runs:
        curves.setdefault(curve_key(r), []).append(r)
    batches: list[list[Run]] = [[]]
    for c in curves.values():
        if batches[-1] and len(batches[-1]) + len(c) > size:
            batches.append([])
        batches[-1].extend(c)
    return batches


def _todo_with_rule(runs: Sequence[Run], out: Path, rule: IdaStop
                    ) -> tuple[list[Run], list[dict]]:
    """(runs to execute, rows of runs skipped by the driver) under the IDA stop ``rule``.

    Stored rows are done, except "skipped" rows of another rule. In a curve, a missing level
    above the lowest stored level where the rule holds is skipped without a task.
    """
    from seisrack.studies.executors import skipped_row

    stored = {}
    if part_files(out):
        table = read_runs(out, columns=["error", "any_fall", "peak_sliding_max_m"])
        stored = {row["run_id"]: row for row in table.to_pylist()}
    reason_end = f"by rule {rule.label}"
    todo: list[Run] = []
    skipped: list[dict] = []
    curves: dict = {}
    for r in runs:
        curves.setdefault(curve_key(r), []).append(r)
    for curve in curves.values():
        stop = None
        for r in sorted(curve, key=lambda r: r.im_target):
            row = stored.get(r.run_id)
            if row is not None and row["status"] == "skipped" and not row[
                    "error"].endswith(reason_end):
                row = None  # skipped by another rule: run it (or skip it) under this one
            if row is not None:
                if stop is None and rule.holds(row):
                    stop = r
            elif stop is not None:
                skipped.append(skipped_row(r, stop.im_target, rule))
            else:
                todo.append(r)
    return todo, skipped


def run_study(spec: StudySpec | StudyPlan, out_dir: str | Path, *, executor: str = "local",
              workers: int | None = None, scheduler: str | None = None, progress: bool = True,
              batch_size: int | None = None, flush_rows: int = 512,
              flush_seconds: float = 30.0) -> StudyRunSummary:
    """Run the runs of ``spec`` not yet stored in ``out_dir`` and append their rows.

    executor: "local" (a process pool, ``workers`` processes, default one per core) or "dask"
    (a ``LocalCluster`` of ``workers`` processes, or the cluster at ``scheduler``, e.g.
    ``"tcp://SCHEDULER-HOST:8786"``; giving ``scheduler`` implies "dask"). progress: a tqdm bar on
    stderr with ETA and the running count of failures.
    """
    import os

    if scheduler and executor == "local":
        executor = "dask"
    if executor not in EXECUTORS:
        raise InputError("executor", executor, "'local' or 'dask'")
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int)
                                or workers < 1):
        raise InputError("workers", workers, "an integer >= 1")
    if batch_size is not None and (not isinstance(batch_size, int) or batch_size < 1):
        raise InputError("batch_size", batch_size, "an integer >= 1")
    if executor == "local":
        check_local_workers(workers)
    t0 = time.perf_counter()
    pl = spec if isinstance(spec, StudyPlan) else plan(spec)
    out = Path(out_dir)
    aside = check_parts(out)  # a damaged or foreign part never stops a resume
    for a in aside:
        log.warning("%s; they are run again", a.message())
    if isinstance(spec, StudySpec):  # refuses a study that does not extend the stored one
        write_study_json(out, spec, pl.runs)
    rule = pl.ida_stop
    pre_skipped: list[dict] = []
    if rule is None:
        done = stored_run_ids(out, skipped=False)  # skipped by a rule no longer set: run
        todo = [r for r in pl.runs if r.run_id not in done]
    else:
        todo, pre_skipped = _todo_with_rule(pl.runs, out, rule)
    n_missing = len(todo) + len(pre_skipped)
    n_workers = workers or os.cpu_count() or 1
    log.info("study: %d runs, %d already stored, %d to run on %s (%d workers)",
             len(pl.runs), len(pl.runs) - n_missing, len(todo), executor, n_workers)
    ok = failed = skipped = parts = 0
    if pre_skipped:
        parts += write_part(out, pre_skipped) is not None
        skipped = len(pre_skipped)
    if todo:
        batches = make_batches(todo, n_workers, batch_size, by_curve=rule is not None)
        if executor == "local":
            from seisrack.studies.executors import LocalExecutor

            # no more processes than batches: the others would only start and wait
            ex = LocalExecutor(pl, min(n_workers, len(batches)))
        else:
            from seisrack.studies.executors import DaskExecutor

            ex = DaskExecutor(pl, n_workers, scheduler)
        bar = _bar(len(todo), progress)
        buffer: list[dict] = []
        last = time.monotonic()
        stream = ex.run(batches)
        try:
            for rows in stream:
                buffer.extend(rows)
                n_bad = sum(r["status"] == "failed" for r in rows)
                n_skip = sum(r["status"] == "skipped" for r in rows)
                failed += n_bad
                skipped += n_skip
                ok += len(rows) - n_bad - n_skip
                if bar is not None:
                    bar.update(len(rows))
                    bar.set_postfix(failed=failed, refresh=False)
                if len(buffer) >= flush_rows or time.monotonic() - last > flush_seconds:
                    parts += write_part(out, buffer) is not None
                    buffer, last = [], time.monotonic()
        finally:
            # Ctrl-C or an error: keep every finished row (the part is written atomically;
            # on a full disk nothing is left half-written) and stop the workers in any case
            try:
                parts += write_part(out, buffer) is not None
            finally:
                stream.close()
                if bar is not None:
                    bar.close()
    return StudyRunSummary(out_dir=str(out), runs_total=len(pl.runs),
                           runs_already_stored=len(pl.runs) - n_missing,
                           runs_executed=ok + failed, runs_ok=ok, runs_failed=failed,
                           runs_skipped=skipped,
                           wall_time_s=time.perf_counter() - t0, executor=executor,
                           workers=n_workers, part_files_written=parts,
                           parts_set_aside=tuple(a.message() for a in aside))


def _bar(total: int, enabled: bool):  # noqa: ANN202
    """Progress of the runs on stderr: a tqdm bar on a terminal, plain lines otherwise."""
    if not enabled:
        return None
    from seisrack.progress import progress

    return progress(total, "study", "run")
