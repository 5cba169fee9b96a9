"""``seisrack modal RACK.toml [--modes N] [--json] [--plot FILE.png]``."""

from __future__ import annotations

import argparse
from typing import Any


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "modal", help="natural periods, mode shapes and mass participation of a rack",
        description="Modal analysis of a rack with its pallets rigidly attached.")
    p.add_argument("rack", help="rack description (TOML)")
    p.add_argument("--modes", type=int, default=6, metavar="N",
                   help="number of modes to report (default 6)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--plot", metavar="FILE.png", help="draw the rack and its first mode shapes")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from seisrack.cli._common import print_json
    from seisrack.errors import InputError
    from seisrack.fe.modal import modal_analysis
    from seisrack.model import compile_rack, load_rack

    if args.modes < 1:
        raise InputError("--modes", args.modes, "an integer >= 1")
    spec = load_rack(args.rack)
    model = compile_rack(spec)
    res = modal_analysis(model, args.modes)
    if args.plot:
        try:
            import matplotlib  # noqa: F401
        except ImportError:
            raise InputError("--plot", args.plot, "a PNG path, with matplotlib installed",
                             hint="Install it with: pip install 'seisrack[plot]'") from None
        from seisrack.report.frame_plot import save_modes_figure

        save_modes_figure(model, res, args.plot)
    cum = res.mass_participation.cumsum()
    if args.json:
        print_json({
            "rack": args.rack, "title": spec.title, "n_dof": model.n_dof,
            "periods_s": res.periods, "frequencies_hz": res.frequencies,
            "mass_participation": res.mass_participation,
            "cumulative_mass_participation": cum,
            "effective_mass_x_kg": res.effective_mass_x, "total_mass_x_kg": res.total_mass_x,
            "damping_coefficients": list(model.damping_coefficients),
            "critical_load_factor": model.critical_load_factor,
            "plot": args.plot,
        })
        return 0
    print(f"{spec.title or args.rack}")
    print(f"{model.n_dof} DOFs, horizontal mass {res.total_mass_x:.1f} kg "
          "(pallets rigidly attached)")
    if model.critical_load_factor is not None:
        print(f"P-Δ on ({spec.second_order.form} geometric stiffness of the gravity load): "
              f"critical load factor {model.critical_load_factor:.4g}")
    print(f"{'mode':>4} {'period [s]':>11} {'freq [Hz]':>10} {'particip.':>10} {'cumul.':>8}")
    for k in range(res.n_modes):
        print(f"{k + 1:>4} {res.periods[k]:>11.4f} {res.frequencies[k]:>10.3f} "
              f"{100 * res.mass_participation[k]:>9.2f}% {100 * cum[k]:>7.2f}%")
    if args.plot:
        print(f"plot written to {args.plot}")
    return 0
