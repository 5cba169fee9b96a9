"""Inputs of ``seisrack run`` shared by the 2D and the 3D paths: record files, scaling, the
output folder, and the warnings on implausible input (issue #14)."""

from __future__ import annotations

import argparse
import math
import os
import sys
from pathlib import Path
from typing import Any

#: [g] a record PGA above this draws a warning (issue #14: implausible input)
PGA_WARN_G = 3.0
#: [g] a scaling that takes the record's PGA above this is refused: no earthquake comes near,
#: and --scale 1e300 overflowed the response to inf and NaN, reported as a result
PGA_MAX_G = 100.0


def _check_number(name: str, value: float | None, allowed: str, ok: bool) -> None:
    from seisrack.errors import InputError

    if value is not None and not (math.isfinite(value) and ok):
        raise InputError(name, value, allowed)


def _read(path: str, option: str, args: argparse.Namespace) -> Any:
    from seisrack.errors import InputError
    from seisrack.motion import read_record

    p = Path(path)
    if not p.is_file():
        raise InputError(option, path, "an existing record file (.AT2, or 1- or 2-column "
                                       "text/CSV)",
                         hint="Check the path" if not p.exists() else "It is not a file")
    try:
        return read_record(p, units=args.units, dt=args.motion_dt)
    except InputError as exc:
        # name the command-line option, not the library argument
        cli = {"units": "--units", "dt": "--motion-dt"}.get(exc.field)
        if cli is None or type(exc) is not InputError:
            raise
        raise InputError(cli, exc.value, exc.allowed, source=exc.source or path,
                         hint=exc.hint) from None


def _records(args: argparse.Namespace) -> tuple[Any, Any]:
    from seisrack.errors import InputError
    from seisrack.motion import list_builtin_records, load_builtin_record

    if args.builtin is not None:
        if args.builtin not in list_builtin_records():
            raise InputError("--builtin", args.builtin, ", ".join(list_builtin_records()))
        rec = load_builtin_record(args.builtin)
    else:
        rec = _read(args.motion, "--motion", args)
    if rec.n < 3:
        raise InputError("--motion", f"{rec.n} samples", "a record of at least 3 samples")
    vert = None
    if args.vertical is not None:
        vert = _read(args.vertical, "--vertical", args)
        if abs(vert.dt - rec.dt) > 1e-9 * rec.dt:
            raise InputError("--vertical", f"time step {vert.dt:g} s",
                             f"the horizontal record's time step ({rec.dt:g} s)")
        if vert.n != rec.n:
            raise InputError("--vertical", f"{vert.n} samples",
                             f"the horizontal record's length ({rec.n} samples)")
    return rec, vert


def _prepare_out(out: str) -> Path:
    """Create ``out`` if needed and check that seisrack may write there (before the run)."""
    from seisrack.errors import InputError

    p = Path(out)
    if p.exists() and not p.is_dir():
        raise InputError("--out", out, "a folder (this is an existing file)")
    try:
        p.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError("--out", out, "a folder that can be created",
                         hint=f"{exc.strerror or exc}") from None
    probe = p / f".seisrack-write-test.{os.getpid()}"
    try:
        probe.write_bytes(b"")
        probe.unlink()
    except OSError as exc:
        raise InputError("--out", out, "a writable folder",
                         hint=f"{exc.strerror or exc}") from None
    return p


def output_folder(args: argparse.Namespace, existing: Any) -> tuple[bool, Path | None]:
    """Whether to plot, and the checked ``--out`` folder (None without it), before the run:
    the folder is writable and holds none of the figures ``existing(folder)`` lists unless
    ``--force``."""
    from seisrack.errors import InputError

    plot = bool(args.out) if args.plot is None else bool(args.plot)
    if not args.out:
        return plot, None
    _need("xarray", "--out", args.out, "io")
    if plot:
        _need("matplotlib", "--plot", True, "plot")
    out = _prepare_out(args.out)
    if plot and not args.force:
        there = existing(out)
        if there:
            raise InputError("--out", args.out, "a folder without seisrack figures, or "
                             "--force to overwrite them",
                             hint="Existing: " + ", ".join(p.name for p in there))
    return plot, out


def _need(module: str, option: str, value: Any, extra: str) -> None:
    from seisrack.errors import InputError

    try:
        __import__(module)
    except ImportError:
        raise InputError(option, value, f"{module} installed",
                         hint=f"Install it with: pip install 'seisrack[{extra}]'") from None


# ------------------------------------------------------------------------------ scaling
#: [m/s²] a scaled PGA above this draws a warning (issue #14: implausible input)
PGA_WARN = 3.0 * 9.80665


def _apply_scaling(args: argparse.Namespace, model: Any, rec: Any,
                   vert: Any) -> tuple[Any, Any, dict[str, Any] | None]:
    """Scale the horizontal record (and the vertical one by the same factor) as asked."""
    from seisrack.errors import InputError
    from seisrack.motion import G, scale_by
    from seisrack.motion.scaling import check_period, scale_record

    unit = G if args.scale_units == "g" else 1.0
    kw: dict[str, Any] = {}
    if args.scale_pga is not None:
        _check_number("--scale-pga", args.scale_pga, f"a target PGA > 0 {args.scale_units}",
                      args.scale_pga > 0)
        kw["pga"] = args.scale_pga * unit
    elif args.scale_sa is not None:
        t_txt, v_txt = args.scale_sa
        try:
            value = float(v_txt)
        except ValueError:
            raise InputError("--scale-sa VALUE", v_txt, "a spectral acceleration > 0") from None
        _check_number("--scale-sa VALUE", value, f"a target Sa > 0 {args.scale_units}",
                      value > 0)
        if t_txt.strip().lower() == "t1":
            from seisrack.fe.modal import modal_analysis

            kw["period"] = float(modal_analysis(model, n_modes=1).periods[0])
        else:
            try:
                period = float(t_txt)
            except ValueError:
                raise InputError("--scale-sa T", t_txt, "a period [s] or the word T1") from None
            kw["period"] = check_period(period, "--scale-sa T")
        kw["sa"] = value * unit
    elif args.scale is not None:
        _check_number("--scale", args.scale, "a scale factor > 0", args.scale > 0)
        kw["factor"] = args.scale
    else:
        return rec, vert, None
    new, info = scale_record(rec, **kw)
    if not new.pga <= PGA_MAX_G * G:
        opt = ("--scale-pga" if args.scale_pga is not None else "--scale-sa VALUE"
               if args.scale_sa is not None else "--scale")
        given = args.scale_pga if args.scale_pga is not None else (
            args.scale_sa[1] if args.scale_sa is not None else args.scale)
        raise InputError(opt, given, f"a scaling that leaves the record's PGA <= "
                         f"{PGA_MAX_G:g} g (this one gives {new.pga / G:.3g} g)",
                         hint="Check the scaling target and its units (--scale-units)")
    if args.scale_sa is not None:
        info["period_from"] = "T1" if args.scale_sa[0].strip().lower() == "t1" else "given"
    if vert is not None:
        vert = scale_by(vert, info["factor"])
        info["vertical_pga_after"] = vert.pga
    if new.pga > PGA_WARN:
        warn(f"the scaled record's PGA is {new.pga:.3g} m/s² = {new.pga / G:.2f} g, above "
             "3 g; check the scaling target")
    return new, vert, info


def warn(message: str) -> None:
    """A warning on stderr: implausible but accepted input (never an error)."""
    print(f"seisrack: warning: {message}", file=sys.stderr)


def _input_warnings(rec: Any, vert: Any, g: float, scaled: bool) -> None:
    """Warn on implausible records (issue #14): PGA above 3 g, vertical below -g."""
    from seisrack.motion import G

    if not scaled and rec.pga > PGA_WARN_G * G:
        warn(f"the record's PGA is {rec.pga:.3g} m/s² = {rec.pga / G:.2f} g, above "
             f"{PGA_WARN_G:g} g; check --units (g or m/s2)")
    if vert is not None:
        low = float(min(vert.accel))
        if low < -g:
            warn(f"the vertical acceleration reaches {low:.3g} m/s², below -g = {-g:.3g} "
                 "m/s²: the pallets would lift off; the model clips their normal force at 0 "
                 "and does not follow them in the air")


# ------------------------------------------------------------------------------ the motion
def register_motion_options(p: argparse.ArgumentParser) -> None:
    """The ground-motion options of ``seisrack run`` and ``seisrack report``."""
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--motion", metavar="FILE",
                     help="horizontal ground acceleration: PEER .AT2, or 1-/2-column text/CSV")
    src.add_argument("--builtin", metavar="NAME",
                     help="a bundled record instead of --motion (e.g. elcentro_1940_ns)")
    p.add_argument("--units", help="units of the record file: 'g' or 'm/s2' (not needed for "
                                   ".AT2 or seisrack CSV files)")
    p.add_argument("--motion-dt", type=float, metavar="DT",
                   help="[s] time step of a one-column record file")
    p.add_argument("--motion-cross", metavar="FILE",
                   help="3D racks: cross-aisle ground acceleration (the second horizontal "
                        "component; same units, dt and length as --motion)")
    p.add_argument("--angle", type=float, default=0.0, metavar="DEG",
                   help="3D racks: incidence angle [deg] turning the horizontal pair from the "
                        "down-aisle axis towards the cross-aisle one (default 0)")
    p.add_argument("--vertical", metavar="FILE",
                   help="vertical ground acceleration, same units, dt and length as the "
                        "horizontal record (pallet normal forces become m (g + a_v))")


def ground_motion_from_args(args: argparse.Namespace, model: Any
                            ) -> tuple[Any, dict[str, Any] | None]:
    """The ground motion the options describe, scaled as asked: (GroundMotion, scaling)."""
    from seisrack.errors import InputError
    from seisrack.model.features import require
    from seisrack.motion import scale_by
    from seisrack.motion.components import combine

    if args.motion_cross is not None:
        require("a cross-aisle ground motion component", model.ndm, "--motion-cross",
                args.motion_cross)
    if args.angle:
        require("an incidence angle of the horizontal components", model.ndm, "--angle",
                args.angle)
    if not (math.isfinite(args.angle) and -360.0 <= args.angle <= 360.0):
        raise InputError("--angle", args.angle, "an incidence angle in degrees, -360 to 360")
    rec, vert = _records(args)
    cross = None if args.motion_cross is None else _read(args.motion_cross, "--motion-cross",
                                                          args)
    rec, vert, scaling = _apply_scaling(args, model, rec, vert)
    if cross is not None and scaling is not None:
        cross = scale_by(cross, scaling["factor"])
    _input_warnings(rec, vert, model.g, scaling is not None)
    return combine(rec, cross, vert, args.angle,
                   fields=("--motion", "--motion-cross", "--vertical")), scaling
