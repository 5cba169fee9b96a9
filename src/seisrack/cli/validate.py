"""``seisrack validate``: the paper's validation examples 2 and 3 (§III.B, issue #3)."""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import Any

from seisrack.cli._common import print_json
from seisrack.errors import InputError


def register(sub: Any) -> None:
    p = sub.add_parser(
        "validate",
        help="run validation examples 2 and 3 with the engine and the reference solver",
    )
    p.add_argument("--dt", type=float, default=1e-3, help="engine time step [s] (default 0.001)")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.add_argument("--plot", metavar="DIR", default=None, help="write Fig. 11b/12b-like plots")
    p.add_argument(
        "--reference-only", action="store_true", help="skip the production engine"
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from seisrack.validation.examples import run_validation

    if not (math.isfinite(args.dt) and args.dt > 0):
        raise InputError("dt", args.dt, "a finite number > 0")
    plot = args.plot is not None
    res = run_validation(
        dt=args.dt, engine=None if args.reference_only else "auto", keep_histories=plot
    )
    if plot:
        from seisrack.report.validation_plot import save_validation_figures

        save_validation_figures(res, Path(args.plot))
    clean = {
        ex: {mu: {k: v for k, v in e.items() if not k.startswith("_")} for mu, e in d.items()}
        for ex, d in res.items()
    }
    if args.json:
        print_json(clean)
    else:
        for ex, d in clean.items():
            for mu, e in d.items():
                disp = ", ".join(f"{x:.6g}" for x in e["max_abs_displacement_m"])
                print(
                    f"{ex} mu={mu}: max|u| = [{disp}] m, max|sliding| = "
                    f"{e['max_abs_sliding_m']:.6g} m, phases = {e['sliding_phases']} "
                    f"({e['source']})"
                )
    return 0
