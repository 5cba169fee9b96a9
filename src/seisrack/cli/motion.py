"""``seisrack motion generate|spectrum|check``: ground motions from the command line."""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import Any

from seisrack.cli._common import float_list, print_json

#: most periods of one response spectrum: each costs a pass over the record; 10,000 periods
#: resolve any spectrum far beyond plotting
MAX_PERIODS = 10_000


def register(subparsers: Any) -> None:
    p = subparsers.add_parser("motion", help="ground motions: generate, spectrum, check")
    sub = p.add_subparsers(dest="motion_command", metavar="ACTION", required=True)

    g = sub.add_parser("generate", help="EC8 spectrum-compatible artificial accelerograms")
    g.add_argument("--spectrum", choices=["ec8"], default="ec8")
    g.add_argument("--type", type=int, choices=[1, 2], default=1)
    g.add_argument("--ground", choices=list("ABCDE"), default="C")
    g.add_argument("--ag", type=float, required=True, help="reference PGA on ground A [g]")
    g.add_argument("--importance", type=float, default=1.0, help="importance factor γ_I")
    g.add_argument("--duration", type=float, default=15.0, help="[s]")
    g.add_argument("--dt", type=float, default=0.01, help="[s]")
    g.add_argument("--damping", type=float, default=0.05)
    g.add_argument("--count", type=int, default=1)
    g.add_argument("--seed", type=int, required=True)
    g.add_argument("--envelope", choices=["trapezoidal", "jennings", "saragoni-hart"],
                   default="trapezoidal")
    g.add_argument("--out", required=True, help="CSV file (one record) or folder (several)")
    g.add_argument("--force", action="store_true",
                   help="overwrite existing record files (refused by default)")
    g.add_argument("--plot", help="PNG of the first record and its spectrum vs the target")
    g.add_argument("--json", action="store_true")
    g.set_defaults(func=_generate)

    s = sub.add_parser("spectrum", help="response spectrum of a record file")
    s.add_argument("file")
    s.add_argument("--units", help="'g' or 'm/s2' (needed unless .AT2 or seisrack CSV)")
    s.add_argument("--dt", type=float, help="[s] time step of a one-column file")
    s.add_argument("--damping", type=float, default=0.05)
    s.add_argument("--periods", type=float_list, help="P1,P2,... [s]")
    s.add_argument("--json", action="store_true")
    s.add_argument("--plot", help="PNG: accelerogram and spectrum")
    s.set_defaults(func=_spectrum)

    c = sub.add_parser(
        "check", help="EN 1998-1 §3.2.3.1.2 report for a suite of records (files or folders)",
        description="Check a suite of accelerograms against EN 1998-1 §3.2.3.1.2: at least 3 "
                    "records, mean PGA >= ag·S, mean 5%-damped spectrum >= 90% of the elastic "
                    "spectrum over 0.2 T1 - 2 T1, stationary part >= 10 s. Reports the smallest "
                    "common scale factor meeting the PGA and spectrum rules.")
    c.add_argument("files", nargs="+",
                   help="record files and/or folders (a folder contributes its .AT2, .csv and "
                        ".txt files)")
    c.add_argument("--units", help="'g' or 'm/s2' for files that do not declare them (.AT2 "
                                   "files are in g, seisrack CSV files in m/s2)")
    c.add_argument("--dt", type=float, help="[s] time step of one-column files")
    c.add_argument("--type", type=int, choices=[1, 2], required=True)
    c.add_argument("--ground", choices=list("ABCDE"), required=True)
    c.add_argument("--ag", type=float, required=True, help="[g]")
    c.add_argument("--importance", type=float, default=1.0)
    c.add_argument("--damping", type=float, default=0.05)
    per = c.add_mutually_exclusive_group(required=True)
    per.add_argument("--period", type=float, help="fundamental period T1 [s]")
    per.add_argument("--rack", metavar="RACK.toml",
                     help="take T1 from the modal analysis of this rack")
    c.add_argument("--scale-suite", action="store_true",
                   help="multiply every record by the reported common factor and report the "
                        "scaled suite")
    c.add_argument("--json", action="store_true")
    c.set_defaults(func=_check)


#: ``motion generate``'s options by the library parameter they set (its errors name those)
_GENERATE_FLAGS = {"ag": "--ag", "importance": "--importance", "damping": "--damping",
                   "duration": "--duration", "dt": "--dt", "seed": "--seed",
                   "envelope_kind": "--envelope", "type": "--type", "ground": "--ground"}


def _generate(args: argparse.Namespace) -> int:
    from seisrack.errors import InputError
    from seisrack.limits import MAX_SUITE_COUNT
    from seisrack.motion import ec8_spectrum, generate_ec8_suite, write_record_csv

    if not 1 <= args.count <= MAX_SUITE_COUNT:
        raise InputError("--count", args.count, f"an integer from 1 to {MAX_SUITE_COUNT:,}")
    out = Path(args.out)
    single = args.count == 1 and out.suffix.lower() == ".csv"
    if single:
        planned = [out]
    else:
        planned = [
            out / f"EC8_type_{args.type}_ground_{args.ground}_seed{args.seed + i}.csv"
            for i in range(args.count)
        ]
    existing = [p for p in planned if p.exists()]
    if existing and not args.force:
        raise InputError(
            "--out", str(existing[0]),
            "a path that does not exist yet (or pass --force to overwrite)",
            hint=f"{len(existing)} of the {len(planned)} record file(s) already exist",
        )
    if not single and out.exists() and not out.is_dir():
        raise InputError("--out", str(out), "a folder (several records) or a .csv file path")
    try:  # the library names its parameters; the user typed the options
        target = ec8_spectrum(args.type, args.ground, args.ag, damping=args.damping,
                              importance=args.importance)
        recs = generate_ec8_suite(args.count, seed=args.seed, spectrum=target,
                                  duration=args.duration, dt=args.dt,
                                  envelope_kind=args.envelope)
    except InputError as e:
        flag = _GENERATE_FLAGS.get(e.field)
        if flag is None:
            raise
        raise InputError(flag, e.value, e.allowed, source=e.source, hint=e.hint) from None
    if single:
        out.parent.mkdir(parents=True, exist_ok=True)
        paths = [write_record_csv(recs[0], out)]
    else:
        out.mkdir(parents=True, exist_ok=True)
        paths = [write_record_csv(r, out / f"{r.name}.csv") for r in recs]
    if args.plot:
        _plot(recs[0], target, args.damping, args.plot)
    summary = [
        {"file": str(p), "seed": r.meta["seed"], "pga_m_s2": r.pga,
         "max_misfit": r.meta["max_misfit"], "iterations": r.meta["iterations"]}
        for p, r in zip(paths, recs, strict=True)
    ]
    if args.json:
        print_json({"target": target.name, "pga_target_m_s2": target.pga, "records": summary})
    else:
        for s in summary:
            print(f"{s['file']}: PGA {s['pga_m_s2']:.3f} m/s2, "
                  f"max spectral misfit {100 * s['max_misfit']:.1f} %")
    return 0


def _plot(record: Any, target: Any, damping: float, path: str) -> None:
    import matplotlib
    import numpy as np

    from seisrack.motion import response_spectrum
    from seisrack.report.motion_plot import plot_accelerogram, plot_spectrum, save

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a1, a2) = plt.subplots(2, 1, figsize=(7, 6))
    plot_accelerogram(record, a1)
    T = np.geomspace(0.02, 4.0, 150)
    plot_spectrum(T, response_spectrum(record.accel, record.dt, T, damping).psa, a2,
                  target=target, label=f"{record.name}, ξ={damping:g}")
    save(a1, path)
    del fig


def _spectrum(args: argparse.Namespace) -> int:
    import numpy as np

    from seisrack.errors import InputError
    from seisrack.motion import read_record, response_spectrum

    if args.periods and len(args.periods) > MAX_PERIODS:
        raise InputError("--periods", f"{len(args.periods):,} periods",
                         f"at most {MAX_PERIODS:,} periods")
    rec = read_record(args.file, units=args.units, dt=args.dt)
    T = np.asarray(args.periods) if args.periods else np.geomspace(0.02, 4.0, 100)
    sp = response_spectrum(rec.accel, rec.dt, T, args.damping)
    if args.plot:
        _plot(rec, None, args.damping, args.plot)
    if args.json:
        print_json({"file": args.file, "dt_s": rec.dt, "n": rec.n, "pga_m_s2": rec.pga,
                    "damping": args.damping, "periods_s": sp.periods, "psa_m_s2": sp.psa,
                    "psv_m_s": sp.psv, "sd_m": sp.sd})
    else:
        print(f"# {args.file}: {rec.n} samples, dt {rec.dt:g} s, PGA {rec.pga:.4g} m/s2")
        print("period_s,psa_m_s2,psv_m_s,sd_m")
        for row in zip(sp.periods, sp.psa, sp.psv, sp.sd, strict=True):
            print(",".join(f"{x:.6g}" for x in row))
    return 0


def _check(args: argparse.Namespace) -> int:
    from seisrack.errors import InputError
    from seisrack.motion import check_ec8_suite, ec8_spectrum, read_suite, scale_by

    if args.period is not None and not (math.isfinite(args.period) and args.period > 0):
        raise InputError("--period", args.period, "a fundamental period T1 > 0 s")
    recs = read_suite(args.files, units=args.units, dt=args.dt)
    period = args.period if args.period is not None else _rack_period(args.rack)
    target = ec8_spectrum(args.type, args.ground, args.ag, damping=args.damping,
                          importance=args.importance)
    rep = check_ec8_suite(recs, target, period)
    scaled = None
    if args.scale_suite:
        if not (math.isfinite(rep.scale_factor) and rep.scale_factor > 0):
            raise InputError("--scale-suite", True, "a suite with a non-zero mean spectrum",
                             hint="No common factor can make this suite comply")
        factor = rep.scale_factor
        scaled = check_ec8_suite([scale_by(r, factor) for r in recs], target, period)
    if args.json:
        d = rep.to_dict()
        d.update(target=target.name, ag_S_m_s2=target.pga, period_s=period,
                 files=[r.provenance for r in recs])
        if scaled is not None:
            d["scaled"] = {"factor": rep.scale_factor, **scaled.to_dict()}
        print_json(d)
    else:
        print(f"target: {target.name}, ag·S = {target.pga:.4g} m/s2, T1 = {period:.4g} s, "
              f"{len(recs)} records")
        print(rep.text())
        if scaled is not None:
            print(f"\nafter scaling every record by {rep.scale_factor:.4g}:")
            print(scaled.text())
    final = scaled if scaled is not None else rep
    return 0 if final.passed else 1


def _rack_period(path: str) -> float:
    """[s] first period of the rack in ``path`` (pallets rigidly attached)."""
    from seisrack.fe.modal import modal_analysis
    from seisrack.model import compile_rack, load_rack

    return float(modal_analysis(compile_rack(load_rack(path)), n_modes=1).periods[0])
