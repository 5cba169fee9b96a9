"""``seisrack run RACK.toml --motion FILE``: earthquake time history of a rack (issue #5).

Thin: parse and check the options, load the rack and the record, call
:func:`seisrack.analysis.run_rack`, print a summary or the ``--json`` object, and write the
results with :mod:`seisrack.report.rack_io` and :mod:`seisrack.report.rack_plot`.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from seisrack.cli.run_inputs import (  # noqa: F401  (re-exported: report.py, tests)
    PGA_WARN,
    PGA_WARN_G,
    _apply_scaling,
    _check_number,
    _input_warnings,
    _records,
    ground_motion_from_args,
    output_folder,
    register_motion_options,
    warn,
)
from seisrack.cli.run_text import format_report
from seisrack.progress import busy

#: runs with more analysis steps than this report their progress (a bar on a terminal, plain
#: lines every few seconds otherwise: seisrack.progress)
PROGRESS_MIN_STEPS = 20_000

_OUT_HELP = (
    "folder for the results (created if needed): timehistory.nc (netCDF, all time histories), "
    "peaks.csv, summary.json and, with --plot (the default with --out), "
    "beam_displacement.png, beam_acceleration.png, contact_force.png, pallet_sliding.png, "
    "sliding_heatmap.png (every level) and, with nonlinear connections, hinge_loops.png. "
    "The data files of these names are overwritten; "
    "existing figures only with --force; nothing else in the folder is touched"
)


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "run", help="earthquake time history of a rack with sliding pallets",
        description="Apply a horizontal ground acceleration at the supports of a rack and "
                    "report the beam displacement and acceleration, the pallet-beam contact "
                    "force, base shear, upright moments, and each pallet's sliding against its "
                    "fall limit (paper §IV). Units: SI (m, s, kg, N).")
    p.add_argument("rack", help="rack description (TOML)")
    register_motion_options(p)
    p.add_argument("--mu", type=float, metavar="MU",
                   help="static friction coefficient of every pallet (overrides the file)")
    p.add_argument("--mu-dynamic", type=float, metavar="MUD",
                   help="dynamic friction coefficient of every pallet (default: --mu); "
                        "needs --mu")
    p.add_argument("--dt", type=float, metavar="DT",
                   help="[s] analysis time step, the record dt divided by a whole number "
                        "(default: the largest such step <= 5 ms)")
    p.add_argument("--method", choices=("auto", "exact", "newmark"), default="auto",
                   help="time integration: exact modal propagators per contact configuration "
                        "(needs no damping or stiffness-proportional damping), Newmark average "
                        "acceleration, or auto (exact when it applies; default)")
    p.add_argument("--basis", choices=("auto", "full", "reduced"), default="auto",
                   help="structure basis: every mode (full), a load-dependent Ritz basis "
                        "(reduced), or auto (full up to 50 DOFs; default)")
    p.add_argument("--engine", choices=("default", "local"), default="default",
                   help="stick-slip engine: default, or local (opt-in: a local basis and "
                        "per-pallet events, cost linear in the rack's length; linear "
                        "connections and Coulomb friction, --method and --basis left auto)")
    p.add_argument("--save-every", type=int, default=1, metavar="K",
                   help="keep every K-th analysis step in the histories (peaks always use "
                        "every step; default 1)")
    p.add_argument("--rigid-check", action="store_true",
                   help="also run the rack with rigidly held pallets, for the simplified "
                        "mu >= alpha check (a second run)")
    p.add_argument("--free-vibration", type=float, default=0.0, metavar="S",
                   help="[s] of free vibration after the record (default 0)")
    p.add_argument("--out", metavar="DIR", help=_OUT_HELP)
    p.add_argument("--plot", action=argparse.BooleanOptionalAction, default=None,
                   help="write the figures (PNG, every level and a sliding heat map) into "
                        "--out DIR (default: yes with --out)")
    p.add_argument("--force", action="store_true",
                   help="overwrite figures that already exist in --out DIR")
    p.add_argument("--accel-filter", type=float, default=None, metavar="HZ",
                   help="[Hz] cut-off of the low-pass filter of the reported floor "
                        "accelerations (default 20, at least 0.1; the raw peak is reported too)")
    p.add_argument("--json", action="store_true",
                   help="print one JSON object (the summary) instead of the text report")
    _register_scaling(p)
    p.set_defaults(func=run)


def _register_scaling(p: argparse.ArgumentParser) -> None:
    grp = p.add_argument_group(
        "record scaling (at most one; the vertical record gets the same factor)")
    sc = grp.add_mutually_exclusive_group()
    sc.add_argument("--scale-pga", type=float, metavar="VALUE",
                    help="scale the record to this peak ground acceleration (m/s², or g with "
                         "--scale-units g)")
    sc.add_argument("--scale-sa", nargs=2, metavar=("T", "VALUE"),
                    help="scale the record so that its 5%%-damped pseudo-spectral acceleration "
                         "at period T [s] (0.01-10 s, or T1: the rack's first period) is VALUE "
                         "(m/s², or g with --scale-units g)")
    sc.add_argument("--scale", type=float, metavar="FACTOR",
                    help="multiply the record by FACTOR (> 0)")
    grp.add_argument("--scale-units", choices=("m/s2", "g"), default="m/s2",
                     help="units of the VALUE of --scale-pga / --scale-sa (default m/s2)")


def _check_options(args: argparse.Namespace) -> None:
    from seisrack.errors import InputError

    _check_number("--mu", args.mu, "a friction coefficient >= 0",
                  args.mu is not None and args.mu >= 0)
    if args.mu_dynamic is not None:
        if args.mu is None:
            raise InputError("--mu-dynamic", args.mu_dynamic, "used together with --mu")
        _check_number("--mu-dynamic", args.mu_dynamic, "a friction coefficient >= 0",
                      args.mu_dynamic >= 0)
        if args.mu_dynamic > args.mu:
            raise InputError("--mu-dynamic", args.mu_dynamic, f"a value <= --mu ({args.mu:g})",
                             hint="The dynamic friction coefficient cannot exceed the static one")
    _check_number("--dt", args.dt, "a time step > 0 s", args.dt is not None and args.dt > 0)
    _check_number("--motion-dt", args.motion_dt, "a time step > 0 s",
                  args.motion_dt is not None and args.motion_dt > 0)
    _check_number("--free-vibration", args.free_vibration, "a duration >= 0 s",
                  args.free_vibration >= 0)
    if args.save_every < 1:
        raise InputError("--save-every", args.save_every, "an integer >= 1")
    if args.plot and not args.out:
        raise InputError("--plot", True, "used together with --out DIR (figures go there)")
    if args.accel_filter is not None:
        from seisrack.analysis.response import ACCEL_FILTER_MIN_HZ

        _check_number("--accel-filter", args.accel_filter,
                      f"a frequency >= {ACCEL_FILTER_MIN_HZ:g} Hz (the low-pass keeps the "
                      "sway modes)", args.accel_filter >= ACCEL_FILTER_MIN_HZ)


def _result_warnings(resp: Any, model: Any) -> None:
    """Warn when a pallet slid further than the rack is long (the results are not physical
    beyond a fall: the model keeps a fallen pallet on its beam)."""
    import numpy as np

    if not resp.n_pallets:
        return
    length = float(np.ptp(model.upright_x))
    peak = resp.pallet_peak_sliding()
    far = [j + 1 for j in np.flatnonzero(peak > length)]
    if far:
        warn(f"pallet(s) {', '.join(map(str, far[:20]))}{' ...' if len(far) > 20 else ''} "
             f"slid more than the rack's length ({length:.3g} m): they fell long before; "
             "sliding beyond the free distance is not physical (the model keeps a pallet on "
             "its beam)")


# ------------------------------------------------------------------------------ run
def run(args: argparse.Namespace) -> int:
    import numpy as np

    from seisrack.analysis import analysis_grid, run_rack
    from seisrack.cli._common import print_json
    from seisrack.errors import InputError
    from seisrack.model import compile_rack, load_rack, with_friction
    from seisrack.model.features import check_engine, require

    _check_options(args)
    spec = load_rack(args.rack)
    if args.mu is not None:
        spec = with_friction(spec, args.mu, args.mu_dynamic)
    with busy(f"building the rack ({args.rack})"):
        model = compile_rack(spec)
    if args.method == "exact" and model.n_dir > 1:
        require("exact modal propagators (method exact)", model.ndm, "--method", args.method)
    engine = getattr(args, "engine", "default")
    check_engine(engine, model, method=args.method, basis=args.basis, cli=True)
    motion, scaling = ground_motion_from_args(args, model)
    check_run_size(args, model, motion)  # before the run allocates anything
    try:
        k = analysis_grid(motion, args.dt)
    except InputError as exc:
        raise InputError("--dt", args.dt, exc.allowed) from None
    from seisrack.report.rack_plot import existing_figures

    plot, out = output_folder(args, existing_figures)
    n_pad = int(round(args.free_vibration / motion.dt))
    n_steps = (motion.n - 1 + n_pad) * k
    bar = _progress_bar(n_steps)
    try:
        resp = run_rack(model, motion, dt=motion.dt / k, free_vibration=args.free_vibration,
                        method=args.method, basis=args.basis, save_every=args.save_every,
                        rigid_companion=args.rigid_check, engine=engine,
                        progress=None if bar is None else bar.update,
                        **({} if args.accel_filter is None
                           else {"accel_filter_hz": args.accel_filter}))
    finally:
        if bar is not None:
            bar.close()

    _result_warnings(resp, model)
    summary = {"rack": args.rack, "title": spec.title, **resp.summary(),
               "integration": resp.history.method, "basis": resp.history.basis}
    if engine != "default":
        summary["engine"] = engine
    if resp.history.work:
        summary["work"] = resp.history.work
    if scaling is not None:
        scaling["run_ground_pga_m_s2"] = float(np.max(np.abs(resp.ground_accel)))
        summary["scaling"] = scaling
    from seisrack.checks.plausibility import format_warnings, plausibility_warnings

    summary["warnings"] = plausibility_warnings(spec, model, summary)
    if out is not None:
        _write_outputs(resp, model, spec, summary, out, plot, args.force)  # adds "outputs"
    if args.json:
        print_json(summary)
    else:
        print(format_report(resp, spec, motion, summary) + format_warnings(summary["warnings"]))
    return 0


def _progress_bar(n_steps: int) -> Any:
    """Progress of a long run on stderr (:func:`seisrack.progress.progress`: a tqdm bar on a
    terminal, a plain line every few seconds otherwise), or None for a short one."""
    if n_steps <= PROGRESS_MIN_STEPS:
        return None
    from seisrack.progress import progress

    return progress(n_steps, "time history", "step")


def check_run_size(args: argparse.Namespace, model: Any, motion: Any) -> None:
    """Estimate the run's memory and time from the ground motion's length and the rack, and
    refuse it up front when out of reach (:mod:`seisrack.limits`); announce a long one."""
    import numpy as np

    from seisrack.analysis import analysis_grid
    from seisrack.errors import InputError
    from seisrack.limits import ANNOUNCE_S, check_run, design_items, estimate_run

    try:
        k = analysis_grid(motion, args.dt)
    except InputError:
        return  # the run reports the bad --dt itself
    n_pad = int(round(args.free_vibration / motion.dt))
    n_lev = max(1, len(model.level_y))
    n_design = 0 if getattr(args, "out", None) is None else design_items(
        n_bays=max(1, len(model.upright_x) - 1), n_levels=n_lev, three_d=model.ndm == 3,
        n_sides=int(np.max(model.element_side, initial=0)) + 1)
    est = estimate_run(n_record=motion.n, k=k, n_pad=n_pad, n_dof=model.n_dof,
                       n_pallets=model.n_pallets, n_levels=n_lev,
                       save_every=args.save_every, vertical=motion.v is not None,
                       three_d=model.ndm == 3, n_design=n_design,
                       engine=getattr(args, "engine", "default"))
    check_run(est, n_record=motion.n, n_pad=n_pad, save_every=args.save_every)
    if est.seconds * (2 if getattr(args, "rigid_check", False) else 1) > ANNOUNCE_S:
        print(f"seisrack: estimated: {est.describe()} (one core)", file=sys.stderr)


def _write_outputs(resp: Any, model: Any, spec: Any, summary: dict[str, Any], out: Path,
                   plot: bool, force: bool = False) -> list[Path]:
    from seisrack.report import rack_io

    title = spec.title or Path(summary["rack"]).stem
    written = [
        rack_io.write_timehistory(resp, out / rack_io.TIMEHISTORY_FILE, model=model,
                                  title=title, summary=summary),
        rack_io.write_peaks_csv(resp, out / rack_io.PEAKS_FILE),
    ]
    if plot:
        from seisrack.report.rack_plot import save_rack_figures

        written += save_rack_figures(resp, out, model=model,
                                     suptitle=f"{title} - {resp.record_name}", force=force)
    summary_path = out / rack_io.SUMMARY_FILE
    written.append(summary_path)
    summary["outputs"] = [str(p) for p in written]
    rack_io.write_summary_json(summary, summary_path)
    return written


# ------------------------------------------------------------------------------ text report
