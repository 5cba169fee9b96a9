"""The size of a study, estimated before it is expanded and before it runs (issue 23).

:func:`count_runs` multiplies what the study file lists (racks x occupancies x records x
friction samples x intensity levels) without loading a rack or a record, so a study of two
million runs is refused in a second rather than after minutes of expansion.
:func:`estimate_study` uses the expanded plan: per (rack, occupancy, record), the estimated
time of one run (:func:`seisrack.limits.estimate_run` on the rack's DOF estimate), times the
runs still to do, over the workers. :func:`check_study_size` refuses what is above
:data:`~seisrack.limits.MAX_STUDY_RUNS` or :data:`~seisrack.limits.MAX_STUDY_SECONDS` unless
the user confirms (``--yes``).
"""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

from seisrack.errors import InputError
from seisrack.limits import (
    MAX_STUDY_RUNS,
    MAX_STUDY_SECONDS,
    estimate_run,
    fmt_seconds,
    rack_size,
)
from seisrack.studies.spec import StudySpec

#: bytes of one stored row (Parquet, compressed; measured about 250 B plus 8 per pallet)
ROW_BYTES = 250


def count_runs(spec: StudySpec) -> int:
    """Runs of ``spec``, counted from the file alone (nothing loaded)."""
    from seisrack.studies.expand import RECORD_SUFFIXES

    rs = spec.records
    n_rec = len(rs.builtin) + sum(s.count for s in rs.ec8)
    if rs.folder is not None:
        n_files = sum(1 for p in Path(rs.folder).iterdir()
                      if p.is_file() and p.suffix.lower() in RECORD_SUFFIXES)
        n_rec += n_files // 2 if rs.pairs else n_files
    f = spec.friction
    n_mu = len(f.values) if f.kind == "values" else f.samples
    a = spec.angle
    # rack x angle cells: a warehouse gives each rack its rows' angles
    n_rack_angle = (sum(len(x) for x in spec.rack_angles) if spec.rack_angles else
                    len(spec.racks) * (len(a.values) if a.kind == "values" else a.samples))
    return (n_rack_angle * len(spec.occupancy) * max(n_rec, 1) * n_mu
            * len(spec.intensity.levels))


@dataclass(frozen=True)
class StudyEstimate:
    runs: int  # runs still to do
    core_seconds: float
    seconds: float  # on the workers
    store_bytes: float

    def describe(self, workers: int) -> str:
        return (f"{self.runs:,} runs, about {fmt_seconds(self.core_seconds)} of computing "
                f"({fmt_seconds(self.seconds)} on {workers} worker"
                f"{'s' if workers > 1 else ''}), {self.store_bytes / 1e6:.3g} MB of results")


def estimate_study(plan, todo_ids: set[str] | None, workers: int) -> StudyEstimate:  # noqa: ANN001
    """Estimated cost of the runs of ``plan`` (those in ``todo_ids``; all if None)."""
    from seisrack.analysis import analysis_grid

    cells = Counter((r.rack_hash, r.occupancy, r.record_hash) for r in plan.runs
                    if todo_ids is None or r.run_id in todo_ids)
    per_run: dict = {}
    total = stored = 0.0
    for (rh, occ, rech), n in cells.items():
        key = (rh, occ, rech)
        if key not in per_run:
            rack, rec = plan.racks[rh], plan.records[rech]
            rec = rec[0] if isinstance(rec, tuple) else rec  # a pair: its components share n
            g = rack.geometry
            m = len(plan.patterns[(rh, occ)])
            pts = 0 if rack.bracing is None else len(rack.bracing.panel_points)
            three_d = g.depth is not None
            size = rack_size(g.n_bays, g.n_levels, g.subdivisions, m,
                             three_d=three_d, panel_points=pts, rows=g.rows)
            try:
                k = analysis_grid(rec, plan.dt)
            except InputError:
                k = 1
            est = estimate_run(n_record=rec.n, k=k, n_pad=0, n_dof=size.dofs, n_pallets=m,
                               n_levels=g.n_levels, save_every=None, three_d=three_d)
            per_run[key] = (est.seconds, ROW_BYTES + 8 * m)
        sec, row = per_run[key]
        total += n * sec
        stored += n * row
    n_runs = sum(cells.values())
    return StudyEstimate(runs=n_runs, core_seconds=total,
                         seconds=total / max(1, min(workers, max(n_runs, 1))),
                         store_bytes=stored)


def check_study_count(spec: StudySpec, confirmed: bool) -> int:
    """Refuse a study of more than :data:`MAX_STUDY_RUNS` runs unless ``confirmed``."""
    n = count_runs(spec)
    if n > MAX_STUDY_RUNS and not confirmed:
        raise InputError("study", f"{n:,} runs", f"a study of at most {MAX_STUDY_RUNS:,} runs, "
                         "or --yes to run a larger one", source=spec.source,
                         hint=f"Expanding it alone would take about "
                              f"{fmt_seconds(n * 1e-4)} and "
                              f"{n * 1.4e3 / 1e9:.3g} GB; split it into several studies")
    return n


def check_study_time(est: StudyEstimate, workers: int, confirmed: bool,
                     source: str | None = None) -> None:
    """Refuse a study estimated above :data:`MAX_STUDY_SECONDS` unless ``confirmed``."""
    if est.seconds > MAX_STUDY_SECONDS and not confirmed:
        more = math.ceil(est.core_seconds / MAX_STUDY_SECONDS)
        raise InputError("study", est.describe(workers),
                         f"a study estimated within {fmt_seconds(MAX_STUDY_SECONDS)}, or --yes "
                         "to run a longer one", source=source,
                         hint=f"About {more} workers would bring it within the limit "
                              "(--workers, or a Dask cluster with --scheduler)")
