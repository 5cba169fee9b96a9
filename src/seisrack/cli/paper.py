"""``seisrack paper [--out DIR] [--quick] [--json]``: reproduce the paper end to end."""

from __future__ import annotations

import argparse
import sys
import time
from typing import Any


def register(sub: Any) -> None:
    p = sub.add_parser(
        "paper", help="reproduce the paper (§II–§IV): figures (PNG) and report.md",
        description="Reproduce Degée & Denoël's sliding-pallet paper end to end: the SDOF "
                    "block (§II), the validation examples (§III) and the rack study (§IV), "
                    "writing PNG figures and a Markdown report.")
    p.add_argument("--out", default="out/paper", metavar="DIR",
                   help="output directory (default out/paper)")
    p.add_argument("--quick", action="store_true",
                   help="fewer cases and a 3-record suite (a fast smoke run)")
    p.add_argument("--rack", default=None, metavar="TOML",
                   help="the paper rack (default examples/paper_rack.toml)")
    p.add_argument("--jobs", type=int, default=2, choices=(1, 2),
                   help="processes: with 2, §II and §III run in a second process beside §IV "
                        "(default 2)")
    p.add_argument("--json", action="store_true",
                   help="print a machine-readable summary (tables, checks, timings)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from seisrack.cli._common import print_json
    from seisrack.paper.reproduce import reproduce_paper

    t0 = time.perf_counter()

    def progress(title: str, seconds: float) -> None:
        print(f"  {title}: {seconds:.1f} s", file=sys.stderr, flush=True)

    print(f"seisrack paper → {args.out}{' (quick)' if args.quick else ''}", file=sys.stderr)
    if args.jobs > 1:
        import multiprocessing as mp
        from concurrent.futures import ProcessPoolExecutor

        # fork: the worker inherits the imported modules and the loaded numba cache
        ctx = mp.get_context("fork") if "fork" in mp.get_all_start_methods() else None
        with ProcessPoolExecutor(max_workers=1, mp_context=ctx) as ex:
            rep = reproduce_paper(args.out, quick=args.quick, rack=args.rack, executor=ex,
                                  progress=progress)
    else:
        rep = reproduce_paper(args.out, quick=args.quick, rack=args.rack, progress=progress)
    wall = time.perf_counter() - t0
    if args.json:
        summary = rep.summary()
        summary["timings_s"]["command_wall"] = round(wall, 3)
        print_json(summary)
    else:
        for c in rep.checks:
            print(f"[{'PASS' if c.passed else 'FAIL'}] {c.section} {c.name}: {c.found}")
        print(f"report: {rep.report}  ({len(rep.files()) - 1} figures)")
        print(f"wall time {wall:.1f} s; all checks {'pass' if rep.passed else 'DO NOT pass'}")
    return 0 if rep.passed else 1
