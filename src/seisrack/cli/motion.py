"""``seisrack motion generate|spectrum|check``: ground motions from the command line."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from seisrack.cli._common import float_list, print_json


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

    c = sub.add_parser("check", help="EN 1998-1 §3.2.3.1.2 report for a suite of records")
    c.add_argument("files", nargs="+")
    c.add_argument("--units", help="'g' or 'm/s2' (needed unless .AT2 or seisrack CSV)")
    c.add_argument("--dt", type=float)
    c.add_argument("--type", type=int, choices=[1, 2], required=True)
    c.add_argument("--ground", choices=list("ABCDE"), required=True)
    c.add_argument("--ag", type=float, required=True, help="[g]")
    c.add_argument("--importance", type=float, default=1.0)
    c.add_argument("--damping", type=float, default=0.05)
    c.add_argument("--period", type=float, required=True, help="fundamental period T1 [s]")
    c.add_argument("--json", action="store_true")
    c.set_defaults(func=_check)


def _generate(args: argparse.Namespace) -> int:
    from seisrack.errors import InputError
    from seisrack.motion import ec8_spectrum, generate_ec8_suite, write_record_csv

    if args.count < 1:
        raise InputError("--count", args.count, "an integer >= 1")
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
    target = ec8_spectrum(args.type, args.ground, args.ag, damping=args.damping,
                          importance=args.importance)
    recs = generate_ec8_suite(args.count, seed=args.seed, spectrum=target,
                              duration=args.duration, dt=args.dt, envelope_kind=args.envelope)
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

    from seisrack.motion import read_record, response_spectrum

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
    from seisrack.motion import check_ec8_suite, ec8_spectrum, read_record

    recs = [read_record(f, units=args.units, dt=args.dt) for f in args.files]
    target = ec8_spectrum(args.type, args.ground, args.ag, damping=args.damping,
                          importance=args.importance)
    rep = check_ec8_suite(recs, target, args.period)
    if args.json:
        d = rep.to_dict()
        d["target"] = target.name
        print_json(d)
    else:
        print(f"target: {target.name}, ag·S = {target.pga:.4g} m/s2, T1 = {args.period:g} s")
        print(rep.text())
    return 0 if rep.passed else 1
