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
    from seisrack.limits import MAX_MODES, check_modes
    from seisrack.model import compile_rack, load_rack
    from seisrack.progress import busy

    if not 1 <= args.modes <= MAX_MODES:
        raise InputError("--modes", args.modes, f"an integer from 1 to {MAX_MODES:,}")
    spec = load_rack(args.rack)
    with busy(f"building the rack ({args.rack})"):
        model = compile_rack(spec)
    check_modes(args.modes, model.n_dof)
    with busy(f"modal analysis ({model.n_dof:,} DOFs, {args.modes} modes)"):
        res = modal_analysis(model, args.modes)
    if args.plot:
        try:
            import matplotlib  # noqa: F401
        except ImportError:
            raise InputError("--plot", args.plot, "a PNG path, with matplotlib installed",
                             hint="Install it with: pip install 'seisrack[plot]'") from None
        from seisrack.report.frame_plot import save_modes_figure

        save_modes_figure(model, res, args.plot)
    from seisrack.checks.plausibility import plausibility_warnings

    warnings = plausibility_warnings(spec, model)
    planar = model.r_z is not None  # a cross-aisle direction: z and plan-rotation terms
    cx = res.mass_participation.cumsum()
    if args.json:
        out = {
            "rack": args.rack, "title": spec.title, "n_dof": model.n_dof,
            "dimension": f"{model.ndm}D", "three_d": planar,
            "periods_s": res.periods, "frequencies_hz": res.frequencies,
            "mass_participation": res.mass_participation,
            "cumulative_mass_participation": cx,
            "effective_mass_x_kg": res.effective_mass_x, "total_mass_x_kg": res.total_mass_x,
            "damping_coefficients": list(model.damping_coefficients),
            "critical_load_factor": model.critical_load_factor,
            "plot": args.plot, "warnings": warnings,
        }
        if planar:
            out.update({
                "direction": list(res.direction),
                "mass_participation_x": res.mass_participation,
                "mass_participation_z": res.mass_participation_z,
                "participation_theta": res.participation_theta,
                "cumulative_mass_participation_z": res.mass_participation_z.cumsum(),
                "effective_mass_z_kg": res.effective_mass_z,
                "total_mass_z_kg": res.total_mass_z,
                "effective_inertia_theta_kgm2": res.effective_inertia_theta,
                "total_inertia_theta_kgm2": res.total_inertia_theta,
                "plan_centre_m": list(model.plan_centre),
            })
        print_json(out)
        return 0
    print(f"{spec.title or args.rack}")
    plan = (f", plan inertia {res.total_inertia_theta:.1f} kg·m² about "
            f"x = {model.plan_centre[0]:.3f} m, z = {model.plan_centre[1]:.3f} m"
            if planar else "")
    print(f"{model.ndm}D rack, {model.n_dof} DOFs, horizontal mass {res.total_mass_x:.1f} kg "
          f"(pallets rigidly attached){plan}")
    if model.critical_load_factor is not None:
        print(f"P-Δ on ({spec.second_order.form} geometric stiffness of the gravity load): "
              f"critical load factor {model.critical_load_factor:.4g}")
    head = f"{'mode':>4} {'period [s]':>11} {'freq [Hz]':>10} {'x-part.':>8} "
    print(head + (f"{'z-part.':>8} {'θ-part.':>8} {'cum. x':>7} {'cum. z':>7}  direction"
                  if planar else f"{'cum. x':>7}"))
    cz = res.mass_participation_z.cumsum() if planar else None
    for k in range(res.n_modes):
        row = (f"{k + 1:>4} {res.periods[k]:>11.4f} {res.frequencies[k]:>10.3f} "
               f"{100 * res.mass_participation[k]:>7.2f}% ")
        if planar:
            row += (f"{100 * res.mass_participation_z[k]:>7.2f}% "
                    f"{100 * res.participation_theta[k]:>7.2f}% {100 * cx[k]:>6.1f}% "
                    f"{100 * cz[k]:>6.1f}%  {res.direction[k]}")
        else:
            row += f"{100 * cx[k]:>6.2f}%"
        print(row)
    if args.plot:
        print(f"plot written to {args.plot}")
    if warnings:
        from seisrack.checks.plausibility import format_warnings

        print(format_warnings(warnings).lstrip("\n"))
    return 0
