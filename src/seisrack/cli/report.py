"""``seisrack report RACK.toml --motion FILE``: run a rack and write the engineer's HTML report.

Thin: load the rack and the record (with ``seisrack run``'s helpers), run the time history, the
modal analysis and the design checks, then write ``report.html`` and ``summary.json`` beside it.
"""

from __future__ import annotations

import argparse
import math
from typing import Any


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "report", help="run a rack under a record and write a self-contained HTML report",
        description="Run the earthquake time history of a rack, its modal analysis and the "
                    "design checks (FEM 10.2.08 / EN 16681 pallet sliding, EN 1998-1 θ, the "
                    "paper's mu >= alpha rule), and write one self-contained HTML file (opens "
                    "offline, prints on A4) plus summary.json beside it. Units: SI.")
    p.add_argument("rack", help="rack description (TOML)")
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--motion", metavar="FILE",
                     help="horizontal ground acceleration: PEER .AT2, or 1-/2-column text/CSV")
    src.add_argument("--builtin", metavar="NAME", help="a bundled record (e.g. elcentro_1940_ns)")
    p.add_argument("--units", help="units of the record file: 'g' or 'm/s2'")
    p.add_argument("--motion-dt", type=float, metavar="DT",
                   help="[s] time step of a one-column record file")
    p.add_argument("--mu", type=float, metavar="MU",
                   help="static (and dynamic) friction coefficient of every pallet")
    p.add_argument("--ec8", nargs=3, metavar=("TYPE", "GROUND", "AG"),
                   help="EC8 design spectrum for the FEM sliding check and the spectrum figure: "
                        "type 1|2, ground A-E, a_g in g (default: the record's own spectrum)")
    p.add_argument("--modes", type=int, default=6, metavar="N",
                   help="modes in the modal table and the checks (default 6)")
    p.add_argument("--out", default="report.html", metavar="FILE.html",
                   help="the HTML report (default report.html); summary.json goes beside it")
    p.add_argument("--rigid-check", action="store_true",
                   help="also run the rack with rigidly held pallets, so the mu >= alpha rule "
                        "uses the designer's (rigid) alpha")
    p.add_argument("--force", action="store_true", help="overwrite an existing report")
    from seisrack.cli.run import _register_scaling

    _register_scaling(p)
    p.add_argument("--json", action="store_true",
                   help="print the summary with the design checks as one JSON object")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from seisrack.analysis import run_rack
    from seisrack.checks import run_design_checks
    from seisrack.checks.plausibility import format_warnings, plausibility_warnings
    from seisrack.cli._common import print_json
    from seisrack.cli.run import _apply_scaling, _records, check_run_size
    from seisrack.errors import InputError
    from seisrack.fe.modal import modal_analysis
    from seisrack.limits import MAX_MODES, check_modes
    from seisrack.model import compile_rack, load_rack, with_friction
    from seisrack.progress import busy
    from seisrack.report.html import check_report_path, write_html_report
    from seisrack.report.rack_io import SUMMARY_FILE, write_summary_json

    if args.mu is not None and not (math.isfinite(args.mu) and args.mu >= 0):
        raise InputError("--mu", args.mu, "a finite friction coefficient >= 0")
    if not 1 <= args.modes <= MAX_MODES:
        raise InputError("--modes", args.modes, f"an integer from 1 to {MAX_MODES:,}")
    out = check_report_path(args.out, args.force, field="--out")
    summary_path = out.with_name(SUMMARY_FILE)
    if summary_path.exists() and not args.force:
        raise InputError("--out", str(summary_path), "a folder without summary.json",
                         hint="Pass --force to overwrite it")
    design = _design_spectrum(args.ec8)
    vars(args).setdefault("vertical", None)
    spec = load_rack(args.rack)
    if args.mu is not None:
        spec = with_friction(spec, args.mu)
    with busy(f"building the rack ({args.rack})"):
        model = compile_rack(spec)
    n_modes = min(args.modes, model.n_dof)
    check_modes(n_modes, model.n_dof)
    rec, _ = _records(args)
    for key, default in (("dt", None), ("free_vibration", 0.0), ("save_every", 1)):
        vars(args).setdefault(key, default)  # the run's defaults, for its size estimate
    check_run_size(args, model, rec, None)
    rec, _, scaling = _apply_scaling(args, model, rec, None)
    with busy("time history" + (" and the run with rigidly held pallets"
                                if args.rigid_check else "")):
        resp = run_rack(model, rec, rigid_companion=args.rigid_check)
    with busy(f"modal analysis ({model.n_dof:,} DOFs)"):
        modal = modal_analysis(model, n_modes=n_modes)
    checks = run_design_checks(model, resp, modal=modal, spectrum=design, record=rec)
    summary = {"rack": args.rack, "title": spec.title, **resp.summary(),
               "integration": resp.history.method, "basis": resp.history.basis}
    if scaling is not None:
        summary["scaling"] = scaling
    summary["design_checks"] = checks
    summary["warnings"] = plausibility_warnings(spec, model, summary)
    write_html_report(out, spec=spec, model=model, response=resp, record=rec, summary=summary,
                      modal=modal, checks=checks, force=args.force, design_spectrum=design,
                      rack_file=args.rack)
    summary["outputs"] = [str(out), str(summary_path)]
    write_summary_json(summary, summary_path)
    if args.json:
        print_json(summary)
    else:
        print(f"report: {out}\nsummary: {summary_path}")
        for c in checks["checks"]:
            print(f"  {c['title']}: {c['verdict']}")
        for d in checks["disagreements"]:
            print(f"  DISAGREES with the time history: {d}")
        text = format_warnings(summary["warnings"])
        if text:
            print(text.lstrip("\n"))
    return 0


def _design_spectrum(ec8: list[str] | None) -> Any:
    if ec8 is None:
        return None
    from seisrack.errors import InputError
    from seisrack.motion import ec8_spectrum

    kind, ground, ag = ec8
    try:
        ag_v = float(ag)
    except ValueError:
        raise InputError("--ec8 AG", ag, "a design ground acceleration in g > 0") from None
    return ec8_spectrum(kind, ground.upper(), ag_v)


__all__ = ["register", "run"]
