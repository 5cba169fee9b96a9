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
        if getattr(model, "is_3d", False):
            from seisrack.report.frame_plot3d import save_modes_figure_3d as save_modes_figure
        else:
            from seisrack.report.frame_plot import save_modes_figure

        save_modes_figure(model, res, args.plot)
    from seisrack.checks.plausibility import format_warnings, plausibility_warnings

    warnings = plausibility_warnings(spec, model)
    if getattr(model, "is_3d", False):
        return _report_3d(args, spec, model, res, warnings)
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
            "plot": args.plot, "warnings": warnings,
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
    if warnings:
        from seisrack.checks.plausibility import format_warnings

        print(format_warnings(warnings).lstrip("\n"))
    return 0


def _report_3d(args: argparse.Namespace, spec: Any, model: Any, res: Any,
               warnings: list[dict[str, Any]]) -> int:
    """Table or JSON of a 3D rack's modes: participation down-aisle (x), cross-aisle (z) and in
    plan rotation (θ about the vertical through the plan mass centre), and each mode's class."""
    from seisrack.cli._common import print_json

    cx, cz = res.mass_participation.cumsum(), res.mass_participation_z.cumsum()
    if args.json:
        print_json({
            "rack": args.rack, "title": spec.title, "n_dof": model.n_dof, "three_d": True,
            "periods_s": res.periods, "frequencies_hz": res.frequencies,
            "direction": list(res.direction),
            "mass_participation": res.mass_participation,
            "mass_participation_x": res.mass_participation,
            "mass_participation_z": res.mass_participation_z,
            "participation_theta": res.participation_theta,
            "cumulative_mass_participation": cx, "cumulative_mass_participation_z": cz,
            "effective_mass_x_kg": res.effective_mass_x, "total_mass_x_kg": res.total_mass_x,
            "effective_mass_z_kg": res.effective_mass_z, "total_mass_z_kg": res.total_mass_z,
            "effective_inertia_theta_kgm2": res.effective_inertia_theta,
            "total_inertia_theta_kgm2": res.total_inertia_theta,
            "plan_centre_m": list(model.plan_centre),
            "damping_coefficients": list(model.damping_coefficients),
            "plot": args.plot, "warnings": warnings,
        })
        return 0
    print(f"{spec.title or args.rack}")
    print(f"3D rack, {model.n_dof} DOFs, horizontal mass {res.total_mass_x:.1f} kg (pallets "
          f"rigidly attached), plan inertia {res.total_inertia_theta:.1f} kg·m² about "
          f"x = {model.plan_centre[0]:.3f} m, z = {model.plan_centre[1]:.3f} m")
    print(f"{'mode':>4} {'period [s]':>11} {'freq [Hz]':>10} {'x-part.':>8} {'z-part.':>8} "
          f"{'θ-part.':>8} {'cum. x':>7} {'cum. z':>7}  direction")
    for k in range(res.n_modes):
        print(f"{k + 1:>4} {res.periods[k]:>11.4f} {res.frequencies[k]:>10.3f} "
              f"{100 * res.mass_participation[k]:>7.2f}% "
              f"{100 * res.mass_participation_z[k]:>7.2f}% "
              f"{100 * res.participation_theta[k]:>7.2f}% {100 * cx[k]:>6.1f}% "
              f"{100 * cz[k]:>6.1f}%  {res.direction[k]}")
    if args.plot:
        print(f"plot written to {args.plot}")
    if warnings:
        from seisrack.checks.plausibility import format_warnings

        print(format_warnings(warnings).lstrip("\n"))
    return 0
