"""``seisrack run`` on a 3D rack (``[geometry] depth``): two horizontal components, an
incidence angle, pallets sliding in the plane (issue 11).

``--motion`` is the down-aisle component, ``--motion-cross`` the cross-aisle one (PEER .AT2
pairs are read directly), ``--vertical`` the vertical one, ``--angle DEG`` turns the pair
(:mod:`seisrack.motion.components`). Calls :func:`seisrack.analysis.rack3d.run_rack_3d` and
writes :mod:`seisrack.report.rack3d_io` and :mod:`seisrack.report.sliding_paths`.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import Any


def check_2d_options(args: argparse.Namespace) -> None:
    """A 2D rack refuses the 3D-only options."""
    from seisrack.errors import InputError

    if args.motion_cross is not None:
        raise InputError("--motion-cross", args.motion_cross,
                         "a 3D rack (with [geometry] depth): a 2D rack takes one horizontal "
                         "component (--motion)")
    if args.angle:
        raise InputError("--angle", args.angle, "0 for a 2D rack (it is for a 3D rack with two "
                         "horizontal components)")


def _check_3d_options(args: argparse.Namespace) -> None:
    from seisrack.errors import InputError

    if args.method == "exact":
        raise InputError("--method", args.method, '"auto" or "newmark" for a 3D rack (planar '
                         "friction is integrated by Newmark with located events)")
    if args.rigid_check:
        raise InputError("--rigid-check", True, "a 2D rack (the simplified check is 2D-only)")
    if args.accel_filter is not None:
        raise InputError("--accel-filter", args.accel_filter, "a 2D rack (3D runs report "
                         "displacements and sliding, not floor accelerations, for now)")
    if not (math.isfinite(args.angle) and -360.0 <= args.angle <= 360.0):
        raise InputError("--angle", args.angle, "an incidence angle in degrees, -360 to 360")


def run_3d(args: argparse.Namespace, spec: Any, model: Any, progress_bar: Any) -> int:
    """The 3D run; ``progress_bar(n_steps)`` gives a tqdm-like bar or None (the 2D run's)."""
    from seisrack.analysis import analysis_grid
    from seisrack.analysis.rack3d import run_rack_3d
    from seisrack.cli._common import print_json
    from seisrack.cli.run_inputs import (
        _apply_scaling,
        _input_warnings,
        _read,
        _records,
        output_folder,
    )
    from seisrack.errors import InputError
    from seisrack.motion import scale_by
    from seisrack.motion.components import combine

    _check_3d_options(args)
    rec, vert = _records(args)
    cross = None
    if args.motion_cross is not None:
        cross = _read(args.motion_cross, "--motion-cross", args)
    rec, vert, scaling = _apply_scaling(args, model, rec, vert)
    if cross is not None and scaling is not None:
        cross = scale_by(cross, scaling["factor"])
    _input_warnings(rec, vert, model.g, scaling is not None)
    motion = combine(rec, cross, vert, args.angle,
                     fields=("--motion", "--motion-cross", "--vertical"))
    try:
        k = analysis_grid(motion, args.dt)  # type: ignore[arg-type]
    except InputError as exc:
        raise InputError("--dt", args.dt, exc.allowed) from None
    from seisrack.report.sliding_paths import existing_figures_3d

    plot, out = output_folder(args, existing_figures_3d)
    n_pad = int(round(args.free_vibration / motion.dt))
    bar = progress_bar((motion.n - 1 + n_pad) * k)
    try:
        resp = run_rack_3d(model, motion, dt=motion.dt / k, free_vibration=args.free_vibration,
                           basis=args.basis, save_every=args.save_every,
                           progress=None if bar is None else bar.update)
    finally:
        if bar is not None:
            bar.close()
    summary = {"rack": args.rack, "title": spec.title, **resp.summary()}
    if scaling is not None:
        summary["scaling"] = scaling
    from seisrack.checks.plausibility import format_warnings, plausibility_warnings

    summary["warnings"] = plausibility_warnings(spec, model, summary)  # issue 23
    if out is not None:
        _write_outputs_3d(resp, model, spec, summary, out, plot, args.force)
    if args.json:
        print_json(summary)
    else:
        print(format_report_3d(summary) + format_warnings(summary["warnings"]))
    return 0


def _write_outputs_3d(resp: Any, model: Any, spec: Any, summary: dict[str, Any], out: Path,
                      plot: bool, force: bool) -> None:
    from seisrack.report import rack3d_io

    title = spec.title or Path(summary["rack"]).stem
    written = [
        rack3d_io.write_timehistory_3d(resp, out / rack3d_io.TIMEHISTORY_FILE, model=model,
                                       title=title, summary=summary),
        rack3d_io.write_peaks_csv_3d(resp, out / rack3d_io.PEAKS_FILE),
    ]
    if plot:
        from seisrack.report.sliding_paths import save_rack3d_figures

        written += save_rack3d_figures(resp, model, out, suptitle=title, force=force)
    path = out / rack3d_io.SUMMARY_FILE
    written.append(path)
    summary["outputs"] = [str(p) for p in written]
    rack3d_io.write_summary_json(summary, path)


def format_report_3d(s: dict[str, Any]) -> str:
    """The text report of a 3D run."""
    lines = [s.get("title") or s["rack"],
             f"record: {s['record']} (down-aisle / cross-aisle), angle {s['angle_deg']:g} deg, "
             f"dt {s['dt_s']:g} s, {s['duration_s']:.2f} s, status {s['status']}"]
    sc = s.get("scaling")
    if sc is not None:
        lines.append(f"scaling: factor {sc['factor']:.6g} on every component")
    lines += ["", f"pallets: {s['n_pallets']}, checked for falls: "
                  f"{s['pallets_checked_for_falls']}, falling: {s['pallets_falling']}"]
    by = ", ".join(f"level {k}: {v}" for k, v in s["falls_by_level"].items() if v)
    if by:
        lines.append(f"falls by level: {by}")
    for f in s["falls"][:20]:
        lines.append(f"  pallet {f['pallet']} (level {f['level']}, bay {f['bay']}) falls to "
                     f"the {f['side']} at {f['time_s']:.3f} s")
    lines.append(f"peak sliding: down-aisle {s['peak_sliding_down_aisle_m'] * 1e3:.1f} mm, "
                 f"cross-aisle {s['peak_sliding_cross_aisle_m'] * 1e3:.1f} mm, magnitude "
                 f"{s['peak_sliding_m'] * 1e3:.1f} mm")
    lines.append(f"down-aisle impacts: {len(s['impacts'])}")
    for i in s["impacts"][:10]:
        lines.append(f"  {i['contact']} at {i['time_s']:.3f} s, closing at "
                     f"{i['closing_speed_m_s']:.3f} m/s")
    lines += ["", "level  height  peak displacement down-aisle / cross-aisle [mm]"]
    for lv in s["level_peak_displacement_m"]:
        lines.append(f"{lv['level']:5d}  {lv['height_m']:5.2f}  {lv['down_aisle'] * 1e3:8.2f}"
                     f"  {lv['cross_aisle'] * 1e3:8.2f}")
    ev = s["events"]
    lines.append("")
    lines.append(f"events: {ev['slip']} slips, {ev['stick']} sticks, {ev['turn']} turns; "
                 f"basis: {s['basis'].get('kind')} ({s['basis'].get('size')} vectors)")
    if s["pallets_checked_for_falls"] < s["n_pallets"]:
        lines.append("note: pallets without depth or overhang are not checked for falls")
    if s["pallets_falling"]:
        lines.append("note: the model keeps a fallen pallet on its beams; its sliding after "
                     "the fall time is not physical")
    return "\n".join(lines)
