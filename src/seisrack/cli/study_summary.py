"""``seisrack study summary DIR [--d-slide D ...] [--shear-capacity N] [--boot N] [--seed S]
[--no-plots] [--json] [--hazard FILE.csv] [--report FILE.html [--force]]``: post-process a
study folder.

Thin: parse (usage errors are JSON under ``--json``, as for every command), call
:func:`seisrack.studies.summary.summarize`, print the text or the JSON object, and write the
study's HTML report when asked. Errors are raised to the command-line boundary
(:mod:`seisrack.cli._boundary`): one paragraph, or the JSON error object under ``--json``.
"""

from __future__ import annotations

import argparse
import math
from typing import Any


def parser() -> argparse.ArgumentParser:
    from seisrack.cli import _Parser
    from seisrack.studies.summary import DEFAULT_D_SLIDE

    p = _Parser(prog="seisrack study summary",
                description="Summarise a study: counts, EC8 means, fragility.")
    p.add_argument("dir", help="the study output folder (--out of `seisrack study`)")
    p.add_argument("--d-slide", type=float, nargs="+", default=list(DEFAULT_D_SLIDE),
                   metavar="D", help="sliding thresholds [m] (default 0.05)")
    p.add_argument("--shear-capacity", type=float, default=None, metavar="N",
                   help="base shear capacity [N] for the 'base shear > capacity' state")
    p.add_argument("--boot", type=int, default=200, metavar="N", help="bootstrap resamples")
    p.add_argument("--seed", type=int, default=0, help="bootstrap seed")
    p.add_argument("--no-plots", action="store_true", help="skip the figures")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--hazard", metavar="FILE.csv", default=None,
                   help="site hazard curve (CSV: '# measure = pga', '# units = g', then "
                        "im,annual_frequency): mean annual frequency and 50-year probability "
                        "of each fragility (and, for a warehouse, falling pallets per year)")
    p.add_argument("--report", metavar="FILE.html", default=None,
                   help="also write the study's self-contained HTML report")
    p.add_argument("--force", action="store_true", help="overwrite an existing --report")
    return p


#: most bootstrap resamples per fit (each costs one likelihood maximisation per damage state)
MAX_BOOT = 100_000


def run(argv: list[str]) -> int:
    from seisrack.cli._common import print_json
    from seisrack.errors import InputError
    from seisrack.studies.summary import (
        _jsonable,
        check_distinct_thresholds,
        format_summary,
        summarize,
    )

    a = parser().parse_args(argv)
    if not 0 <= a.boot <= MAX_BOOT:
        raise InputError("--boot", a.boot, f"an integer from 0 to {MAX_BOOT:,}")
    if a.seed < 0:
        raise InputError("--seed", a.seed, "an integer >= 0")
    if any(not (math.isfinite(d) and d > 0) for d in a.d_slide):
        raise InputError("--d-slide", a.d_slide, "sliding thresholds > 0 [m]")
    check_distinct_thresholds("--d-slide", a.d_slide)
    if a.shear_capacity is not None and not (math.isfinite(a.shear_capacity)
                                             and a.shear_capacity > 0):
        raise InputError("--shear-capacity", a.shear_capacity, "a base shear capacity > 0 [N]")
    boots: list[Any] = []
    if a.report:  # refuse an existing report before any work
        from seisrack.report.html import check_report_path

        check_report_path(a.report, a.force, field="--report")
    s = summarize(a.dir, d_slide=a.d_slide, shear_capacity=a.shear_capacity, n_boot=a.boot,
                  seed=a.seed, plots=not a.no_plots, boots=boots, hazard=a.hazard)
    if a.report:
        from seisrack.report.html import write_study_report
        from seisrack.studies.warehouse_summary import plan_axes

        wh = s.get("warehouse") or {}
        plans = plan_axes(wh, wh.get("path")) if wh else []
        html = write_study_report(a.report, _jsonable(s), out_dir=a.dir, boots=boots,
                                  seed=a.seed, force=a.force, plans=plans)
        s.setdefault("files", {})["report_html"] = str(html)
    if a.json:
        print_json(_jsonable(s))
    else:
        print(format_summary(s))
    return 0
