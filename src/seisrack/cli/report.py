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
    p.add_argument("rack", help="rack description (TOML), 2D or 3D")
    from seisrack.cli.run_inputs import register_motion_options

    register_motion_options(p)
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
                        "uses the designer's (rigid) alpha, and report the force reduction "
                        "sliding gives (peaks sliding / rigid)")
    p.add_argument("--q", type=float, nargs="+", default=[1.0], metavar="Q",
                   help="behaviour factor of the design analysis run with --ec8 (default 1)")
    p.add_argument("--factors", nargs="+", metavar="KEY=VALUE",
                   help="design analysis factors, e.g. e_d1=1.0 (see seisrack design)")
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
    from seisrack.cli.run import check_run_size
    from seisrack.cli.run_inputs import ground_motion_from_args
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
    if summary_path.exists() and not summary_path.is_file():  # checked before anything is written
        raise InputError("--out", str(summary_path), "a folder where summary.json is a file "
                         "(or absent): here it is a folder or a special file, which --force "
                         "does not replace")
    if summary_path.exists() and not args.force:
        raise InputError("--out", str(summary_path), "a folder without summary.json",
                         hint="Pass --force to overwrite it")
    design = _design_spectrum(args.ec8)
    from seisrack.design import parse_factor_overrides

    factors = parse_factor_overrides(getattr(args, "factors", None))
    spec = load_rack(args.rack)
    if args.mu is not None:
        spec = with_friction(spec, args.mu)
    with busy(f"building the rack ({args.rack})"):
        model = compile_rack(spec)
    n_modes = min(args.modes, model.n_dof)
    check_modes(n_modes, model.n_dof)
    rec, scaling = ground_motion_from_args(args, model)
    for key, default in (("dt", None), ("free_vibration", 0.0), ("save_every", 1)):
        vars(args).setdefault(key, default)  # the run's defaults, for its size estimate
    check_run_size(args, model, rec)
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
    section = _design_section(args, model, resp, rec, factors)
    if section.get("design") is not None:
        summary["design_analysis"] = section["design"]
    if section.get("reduction") is not None:
        summary["sliding_reduction"] = section["reduction"]
    summary["warnings"] = plausibility_warnings(spec, model, summary)
    write_html_report(out, spec=spec, model=model, response=resp, record=rec, summary=summary,
                      modal=modal, checks=checks, force=args.force, design_spectrum=design,
                      rack_file=args.rack, design_section=section)
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
        if "design_analysis" in summary:
            da = summary["design_analysis"]["quantities"]["base_shear_x"]
            print(f"  design analysis (EN 1998-1 modal response spectrum): base shear "
                  f"{da['max'] / 1e3:.3f} kN")
        if "sliding_reduction" in summary:
            r = summary["sliding_reduction"]
            print("  sliding / rigid peaks: " + ", ".join(
                f"{row['quantity']} {row['ratio']:.3f}" for row in r["rows"])
                + f" (mu/alpha = {r['mu_over_alpha']:.3f})")
        text = format_warnings(summary["warnings"])
        if text:
            print(text.lstrip("\n"))
    return 0


def _design_section(args: argparse.Namespace, model: Any, resp: Any, rec: Any,
                    factors: Any) -> dict[str, Any]:
    """The report's design section: the design analysis (with --ec8) beside this run's peaks,
    and the sliding reduction (with --rigid-check, needs pallets)."""
    from seisrack.design import design_analysis
    from seisrack.design.sliding_reduction import one_run_table, response_peaks, rigid_model
    from seisrack.design.spectrum import design_spectra
    from seisrack.report.html.design import beside_rows

    out: dict[str, Any] = {}
    spectra = None
    if args.ec8 is not None:
        kind, ground, ag = args.ec8
        spectra = design_spectra((kind, ground.upper(), float(ag)), tuple(args.q),
                                 tuple(model.directions), beta=factors.beta)
        res = design_analysis(model, spectra, factors=factors)
        out["design"] = res.as_dict()
        out["beside"] = beside_rows(res, response_peaks(resp))
    else:
        out["note"] = ("Give --ec8 TYPE GROUND AG (and --q) to run the design analysis; "
                       "the sliding reduction needs --rigid-check.")
    if args.rigid_check and model.n_pallets:
        from seisrack.analysis import run_rack

        rigid = run_rack(rigid_model(model), rec, save_every=None, track_energy=False)
        out["reduction"] = one_run_table(model, resp, rigid, factors=factors,
                                         spectrum=None if spectra is None
                                         else spectra["down-aisle"])
    return out


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
