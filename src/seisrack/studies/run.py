"""Run a study: expand, skip what is stored, execute in batches, append to the store.

:func:`run_study` is the driver. It expands the study (all input errors are raised here, before
any run), writes ``study.json``, reads the run ids already in the store and runs only the
others, in batches (:data:`DEFAULT_BATCH` runs per task, fewer when there are few runs, so that
every worker gets work). Rows come back as batches finish and wait in a buffer of at most
``flush_rows`` rows (or ``flush_seconds`` seconds) before being written as one Parquet part
file: the driver's memory does not grow with the study. On Ctrl-C the buffer is flushed before
the interrupt propagates; a driver killed outright loses at most its buffer, which a resumed run
recomputes.
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from seisrack.errors import InputError
from seisrack.studies.expand import Run, StudyPlan, plan
from seisrack.studies.spec import StudySpec
from seisrack.studies.store import stored_run_ids, write_part, write_study_json

log = logging.getLogger(__name__)

DEFAULT_BATCH = 32
EXECUTORS = ("local", "dask")


@dataclass(frozen=True)
class StudyRunSummary:
    """What one call of :func:`run_study` did (counts over the runs of the study)."""

    out_dir: str
    runs_total: int  # runs of the study
    runs_already_stored: int  # skipped (resume)
    runs_executed: int
    runs_ok: int  # of the executed runs
    runs_failed: int
    wall_time_s: float
    executor: str
    workers: int
    part_files_written: int


def make_batches(runs: Sequence[Run], workers: int, batch_size: int | None = None
                 ) -> list[list[Run]]:
    """Consecutive batches: ``batch_size`` runs each, or fewer so every worker gets ~4."""
    if not runs:
        return []
    size = batch_size or max(1, min(DEFAULT_BATCH, math.ceil(len(runs) / (4 * workers))))
    return [list(runs[i:i + size]) for i in range(0, len(runs), size)]


def run_study(spec: StudySpec | StudyPlan, out_dir: str | Path, *, executor: str = "local",
              workers: int | None = None, scheduler: str | None = None, progress: bool = True,
              batch_size: int | None = None, flush_rows: int = 512,
              flush_seconds: float = 30.0) -> StudyRunSummary:
    """Run the runs of ``spec`` not yet stored in ``out_dir`` and append their rows.

    executor: "local" (a process pool, ``workers`` processes, default one per core) or "dask"
    (a ``LocalCluster`` of ``workers`` processes, or the cluster at ``scheduler``, e.g.
    ``"tcp://10.0.0.1:8786"``; giving ``scheduler`` implies "dask"). progress: a tqdm bar on
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
    t0 = time.perf_counter()
    pl = spec if isinstance(spec, StudyPlan) else plan(spec)
    out = Path(out_dir)
    if isinstance(spec, StudySpec):
        write_study_json(out, spec, pl.runs)
    done = stored_run_ids(out)
    todo = [r for r in pl.runs if r.run_id not in done]
    n_workers = workers or os.cpu_count() or 1
    log.info("study: %d runs, %d already stored, %d to run on %s (%d workers)",
             len(pl.runs), len(pl.runs) - len(todo), len(todo), executor, n_workers)
    ok = failed = parts = 0
    if todo:
        if executor == "local":
            from seisrack.studies.executors import LocalExecutor

            ex = LocalExecutor(pl, n_workers)
        else:
            from seisrack.studies.executors import DaskExecutor

            ex = DaskExecutor(pl, n_workers, scheduler)
        bar = _bar(len(todo), progress)
        buffer: list[dict] = []
        last = time.monotonic()
        stream = ex.run(make_batches(todo, n_workers, batch_size))
        try:
            for rows in stream:
                buffer.extend(rows)
                n_bad = sum(r["status"] != "ok" for r in rows)
                failed += n_bad
                ok += len(rows) - n_bad
                if bar is not None:
                    bar.update(len(rows))
                    bar.set_postfix(failed=failed, refresh=False)
                if len(buffer) >= flush_rows or time.monotonic() - last > flush_seconds:
                    parts += write_part(out, buffer) is not None
                    buffer, last = [], time.monotonic()
        finally:
            # Ctrl-C or an error: keep every finished row (the part is written atomically)
            parts += write_part(out, buffer) is not None
            stream.close()
            if bar is not None:
                bar.close()
    return StudyRunSummary(out_dir=str(out), runs_total=len(pl.runs),
                           runs_already_stored=len(pl.runs) - len(todo),
                           runs_executed=ok + failed, runs_ok=ok, runs_failed=failed,
                           wall_time_s=time.perf_counter() - t0, executor=executor,
                           workers=n_workers, part_files_written=parts)


def _bar(total: int, enabled: bool):  # noqa: ANN202
    if not enabled:
        return None
    try:
        from tqdm.auto import tqdm
    except ImportError:  # tqdm is in the [io]/[all] extras
        return None
    return tqdm(total=total, unit="run", desc="study", dynamic_ncols=True, smoothing=0.1)
