"""``seisrack study STUDY.toml --out DIR [--dry-run] [--workers N] [--executor local|dask]
[--scheduler ADDR] [--batch-size N] [--json]`` and ``seisrack study summary DIR ...``.

The first form expands the study (every input error is reported before any run starts), then
runs what ``DIR`` does not hold yet: running the same command again resumes. ``summary`` is
delegated to :mod:`seisrack.cli.study_summary` with the remaining arguments.
"""

from __future__ import annotations

import argparse
import os
import sys
from collections import Counter
from typing import Any


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "study", help="run a study (record suites x intensity stripes x friction), resumable",
        description="Expand a study TOML into runs with stable ids and run those not yet "
                    "stored in --out (Parquet). 'seisrack study summary DIR' post-processes a "
                    "study folder. Keys of the study file: docs/user/study_toml.md.")
    p.add_argument("study", help="study description (TOML), or 'summary' followed by DIR")
    p.add_argument("rest", nargs=argparse.REMAINDER, help=argparse.SUPPRESS)
    _add_options(p)
    p.set_defaults(func=run)


def _add_options(p: argparse.ArgumentParser, defaults: bool = True) -> None:
    """The options of a study run (given before or after the study file)."""
    d = (lambda v: v) if defaults else (lambda v: argparse.SUPPRESS)
    p.add_argument("--out", metavar="DIR", default=d(None),
                   help="study folder (study.json, runs/*.parquet)")
    p.add_argument("--dry-run", action="store_true", default=d(False),
                   help="print the run table and exit")
    p.add_argument("--workers", type=int, default=d(None), metavar="N",
                   help="worker processes (default: one per core; locally at most four per core)")
    p.add_argument("--executor", choices=("local", "dask"), default=d("local"),
                   help="local process pool (default) or a Dask LocalCluster")
    p.add_argument("--scheduler", metavar="ADDR", default=d(None),
                   help="address of a running Dask scheduler, e.g. tcp://SCHEDULER-HOST:8786")
    p.add_argument("--batch-size", type=int, default=d(None), metavar="N",
                   help="runs per task (default: up to 32, fewer for small studies)")
    p.add_argument("--json", action="store_true", default=d(False), help="print one JSON object")
    p.add_argument("--no-progress", action="store_true", default=d(False),
                   help="no progress bar")
    p.add_argument("--yes", action="store_true", default=d(False),
                   help="run a study above the size limits (more than 100,000 runs, or "
                        "estimated longer than 24 h on its workers); without it such a study "
                        "is refused with its estimate")


def run(args: argparse.Namespace) -> int:
    if args.study == "summary":
        from seisrack.cli.study_summary import run as summary

        argv = list(args.rest)
        for flag in ("json",):  # options argparse took for itself belong to the summary
            if getattr(args, flag):
                argv.append(f"--{flag}")
        if args.out:
            argv += ["--out", args.out]
        return summary(argv)
    return _run_study(args)


def _run_study(args: argparse.Namespace) -> int:
    from seisrack.cli._common import print_json
    from seisrack.cli.run_inputs import warn
    from seisrack.errors import InputError
    from seisrack.limits import ANNOUNCE_S
    from seisrack.progress import busy
    from seisrack.studies import load_study, plan, run_study
    from seisrack.studies.size import check_study_count, check_study_time, estimate_study

    if args.rest:  # options after the study file
        from seisrack.cli import _Parser

        extra = _Parser(prog="seisrack study", add_help=False)
        _add_options(extra, defaults=False)
        extra.parse_args(args.rest, namespace=args)
    if args.workers is not None and args.workers < 1:
        raise InputError("--workers", args.workers, "an integer >= 1")
    if args.executor == "local" and not args.scheduler:
        from seisrack.studies.run import check_local_workers

        check_local_workers(args.workers, "--workers")
    if args.batch_size is not None and args.batch_size < 1:
        raise InputError("--batch-size", args.batch_size, "an integer >= 1")
    if not args.out and not args.dry_run:
        raise InputError("--out", None, "a folder for the study results",
                         hint="Add --out DIR (or --dry-run to see the runs)")
    spec = load_study(args.study)
    n_runs = check_study_count(spec, args.yes)  # counted from the file: before expansion
    with busy(f"expanding the study ({n_runs:,} runs)"):
        pl = plan(spec)
    if args.dry_run:
        return _dry_run(args, spec, pl)
    from seisrack.studies.store import check_parts, stored_run_ids, write_study_json

    for aside in check_parts(args.out):  # a damaged part: set aside, its runs run again
        warn(aside.message() + "; they are run again")
    workers = args.workers or (os.cpu_count() or 1)
    done = stored_run_ids(args.out, skipped=False)
    est = estimate_study(pl, {r.run_id for r in pl.runs if r.run_id not in done}, workers)
    check_study_time(est, workers, args.yes, source=spec.source)
    if est.seconds > ANNOUNCE_S:
        print(f"seisrack: study: estimated {est.describe(workers)}", file=sys.stderr)
    write_study_json(args.out, spec, pl.runs)
    s = run_study(pl, args.out, executor=args.executor, workers=args.workers,
                  scheduler=args.scheduler, batch_size=args.batch_size,
                  progress=not args.no_progress and not args.json)
    if args.json:
        from dataclasses import asdict

        print_json(asdict(s))
        return 0
    print(f"{s.runs_total} runs: {s.runs_already_stored} already stored, {s.runs_executed} run "
          f"({s.runs_ok} ok, {s.runs_failed} failed)"
          + (f", {s.runs_skipped} skipped by the IDA stop rule" if s.runs_skipped else "")
          + f" in {s.wall_time_s:.1f} s on {s.executor} "
          f"({s.workers} workers); results in {s.out_dir}/runs")
    return 0


def _dry_run(args: argparse.Namespace, spec, pl) -> int:  # noqa: ANN001
    from seisrack.cli._common import print_json

    runs = pl.runs
    per_level = Counter((r.stripe, r.im_target) for r in runs)
    done = set()
    if args.out:
        from seisrack.studies.store import stored_run_ids

        done = stored_run_ids(args.out)
    n_stored = sum(r.run_id in done for r in runs)
    levels = [{"stripe": k, "im_target": im, "runs": n}
              for (k, im), n in sorted(per_level.items(), key=lambda kv: kv[0][1])]
    if args.json:
        from dataclasses import asdict

        print_json({"runs_total": len(runs), "runs_already_stored": n_stored,
                    "im_measure": spec.intensity.measure, "levels": levels,
                    "runs": [asdict(r) for r in runs]})
        return 0
    unit = "m/s²"
    print(f"{spec.title or spec.source}: {len(runs)} runs "
          f"({n_stored} already stored in {args.out})" if args.out else
          f"{spec.title or spec.source}: {len(runs)} runs")
    kind = "IDA level" if spec.intensity.is_ida else "stripe"
    for lv in levels:
        print(f"  {kind} {lv['stripe']:>3}  {spec.intensity.measure} = {lv['im_target']:.4g} "
              f"{unit}: {lv['runs']} runs")
    planar = any(r.angle_deg != 0.0 or r.components > 1 for r in runs)
    head = f"{'run_id':<16} {'rack':<20} {'record':<26} {'IM [m/s²]':>10} {'scale':>7} " \
           f"{'mu_s':>6} {'mu_d':>6} {'occ':>5}" + (f" {'comp':>4} {'angle':>6}" if planar
                                                    else "")
    print(head)
    for r in runs[:12]:
        print(f"{r.run_id:<16} {r.rack[-20:]:<20} {r.record[:26]:<26} {r.im_target:>10.4g} "
              f"{r.scale_factor:>7.3f} {r.mu_static:>6.3f} {r.mu_dynamic:>6.3f} "
              f"{r.occupancy:>5.2f}" + (f" {r.components:>4} {r.angle_deg:>6.1f}" if planar
                                        else ""))
    if len(runs) > 12:
        print(f"... {len(runs) - 12} more (--json lists them all)")
    sys.stdout.flush()
    return 0
