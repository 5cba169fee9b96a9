"""``seisrack sdof``: exact §II sliding-block solution and its regime (paper Eqs 1–5, Fig. 6)."""

from __future__ import annotations

import argparse
import math
from typing import Any

from seisrack.cli._common import print_json
from seisrack.errors import InputError


def register(sub: Any) -> None:
    p = sub.add_parser(
        "sdof",
        help="closed-form stick-slip of a block on a sinusoidally accelerated rigid support",
        description=(
            "Exact piecewise-analytic solution of a mass on a rigid support with acceleration "
            "-alpha g sin(2 pi f t) (paper §II), or the continuous-sliding threshold."
        ),
    )
    p.add_argument("--alpha", type=float, help="support acceleration amplitude [g]")
    p.add_argument("--mu", type=float, help="static friction coefficient")
    p.add_argument("--mu-dynamic", type=float, default=None, help="sliding coefficient (<= mu)")
    p.add_argument("--frequency", type=float, help="support frequency [Hz]")
    p.add_argument("--duration", type=float, help="analysis duration [s]")
    p.add_argument("--g", type=float, default=9.81, help="gravity [m/s2] (default 9.81)")
    p.add_argument("--threshold", action="store_true", help="print the sliding threshold")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.add_argument("--plot", metavar="FILE.png", default=None, help="draw x, v and friction")
    p.set_defaults(func=run)


def _required(args: argparse.Namespace, name: str) -> float:
    val = getattr(args, name)
    if val is None:
        raise InputError(name, None, f"--{name.replace('_', '-')} is required")
    return float(val)


def run(args: argparse.Namespace) -> int:
    from seisrack.sdof.regime import continuous_sliding_threshold, sdof_regime

    if args.threshold:
        value = continuous_sliding_threshold()
        if args.json:
            print_json({"continuous_sliding_threshold": value})
        else:
            print(f"continuous-sliding threshold mu/alpha = {value:.9f}")
        return 0

    from seisrack.sdof.closed_form import solve_sdof, validate_sdof_inputs

    alpha = _required(args, "alpha")
    mu = _required(args, "mu")
    frequency = _required(args, "frequency")
    duration = _required(args, "duration")
    mu_d = mu if args.mu_dynamic is None else float(args.mu_dynamic)
    validate_sdof_inputs(alpha, mu, mu_d, frequency, duration, float(args.g))
    if duration * frequency > 1e5:
        raise InputError("duration", duration, "at most 1e5 support periods")
    sol = solve_sdof(alpha, mu, frequency, duration, mu_dynamic=mu_d, g=args.g)
    regime = sdof_regime(mu / alpha, mu_d / alpha)
    out = {
        "regime": regime,
        "mu_over_alpha": mu / alpha,
        "mu_dynamic_over_alpha": mu_d / alpha,
        "events": [{"time_s": t, "kind": k} for t, k in sol.events],
        "sliding_phases": sol.sliding_phases,
        "final_sliding_m": float(sol.sliding(duration)),
        "final_relative_velocity_m_s": float(sol.sliding_velocity(duration)),
    }
    if args.plot:
        from seisrack.report.sdof_plot import save_sdof_figure

        save_sdof_figure(sol, args.plot)
        out["plot"] = str(args.plot)
    if args.json:
        print_json(out)
    else:
        print(f"regime: {regime} (mu/alpha = {mu / alpha:.6g})")
        for ev in out["events"]:
            print(f"  {ev['time_s']:.9f} s  {ev['kind']}")
        print(f"final sliding: {out['final_sliding_m']:.6g} m")
    return 0 if math.isfinite(out["final_sliding_m"]) else 1
