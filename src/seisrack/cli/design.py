"""``seisrack design RACK.toml --ec8 TYPE GROUND AG --q Q``: the rack's seismic design analysis.

Thin: load and compile the rack, build the EN 1998-1 spectra, run
:func:`seisrack.design.design_analysis`, print a text summary or one JSON object.
"""

from __future__ import annotations

import argparse
from typing import Any


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "design", help="modal response spectrum design analysis (EN 1998-1, EN 16681 factors)",
        description="Seismic design analysis of a rack: EN 1998-1 §4.3.3.3 modal response "
                    "spectrum analysis with the behaviour factor q and the EN 16681 / FEM "
                    "10.2.08 unit-load factors (E_D1, E_D2, E_D3; placeholders marked as "
                    "assumptions, override them with --factors). Gives periods and modal "
                    "masses, base shear, level forces, drifts, theta per storey, upright N "
                    "and M, beam end and connector moments. Units: SI.")
    p.add_argument("rack", help="rack description (TOML, 2D or 3D)")
    p.add_argument("--ec8", nargs=3, required=True, metavar=("TYPE", "GROUND", "AG"),
                   help="EN 1998-1 spectrum: type 1|2, ground A-E, reference a_gR in g")
    p.add_argument("--q", type=float, nargs="+", required=True, metavar="Q",
                   help="behaviour factor q >= 1 (1 = elastic); two values for a 3D rack: "
                        "down-aisle then cross-aisle")
    p.add_argument("--importance", type=float, default=1.0, metavar="GAMMA_I",
                   help="importance factor (a_g = gamma_I a_gR, default 1)")
    p.add_argument("--elastic", action="store_true",
                   help="use the elastic spectrum S_e (EN 1998-1 §3.2.2.2, at each mode's "
                        "damping) instead of the design spectrum S_d; needs --q 1")
    p.add_argument("--damping", default=None, metavar="XI",
                   help="damping ratio for CQC and the elastic spectrum (default the factor "
                        "table's 0.05), or 'model' for the rack's own damping per mode")
    p.add_argument("--direction", choices=("down-aisle", "cross-aisle", "both"),
                   default="both", help="excitation direction(s) (3D racks; default both)")
    p.add_argument("--combination", choices=("auto", "srss", "cqc"), default="auto",
                   help="modal combination (default auto: SRSS if the relevant modes are "
                        "well separated, T_j <= 0.9 T_i, else CQC)")
    p.add_argument("--directions-rule", choices=("srss", "0.30"), default="srss",
                   help="combination of the two directions (EN 1998-1 §4.3.3.5.1)")
    p.add_argument("--modes", type=int, default=None, metavar="N",
                   help="modes to compute (default: enough for 90 %% of the mass)")
    p.add_argument("--factors", nargs="+", metavar="KEY=VALUE",
                   help="override factors, e.g. e_d1=1.0 e_d2_down_aisle=0.9")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from seisrack.cli._common import print_json
    from seisrack.design import design_analysis, parse_factor_overrides
    from seisrack.design.operators import directions_of
    from seisrack.design.spectrum import design_spectra
    from seisrack.model import compile_rack, load_rack

    factors = parse_factor_overrides(args.factors)
    damping = _damping(args.damping)
    typ, ground, ag = _ec8(args.ec8)
    spec = load_rack(args.rack)
    model = compile_rack(spec)
    have = directions_of(model)
    dirs = have if args.direction == "both" else (args.direction,)
    if args.direction != "both":
        _check_direction(args.direction, have)
    spectra = design_spectra((typ, ground, ag), tuple(args.q), dirs,
                             importance=args.importance, beta=factors.beta, elastic=args.elastic)
    res = design_analysis(model, spectra, factors=factors, directions=dirs, n_modes=args.modes,
                          modal_rule=args.combination, direction_rule=args.directions_rule,
                          damping=damping)
    if args.json:
        print_json({"rack": args.rack, "title": spec.title, "n_dof": model.n_dof,
                    "ec8": {"type": typ, "ground": ground, "ag_g": ag,
                            "importance": args.importance, "elastic": args.elastic},
                    **res.as_dict()})
        return 0
    print(format_design(res, title=spec.title or args.rack))
    return 0


def _ec8(ec8: list[str]) -> tuple[str, str, float]:
    from seisrack.errors import InputError

    typ, ground, ag = ec8
    try:
        ag_v = float(ag)
    except ValueError:
        raise InputError("--ec8 AG", ag, "a reference ground acceleration in g > 0") from None
    return typ, ground.upper(), ag_v


def _damping(text: str | None) -> float | str | None:
    from seisrack.errors import InputError

    if text is None or text == "model":
        return text
    try:
        return float(text)
    except ValueError:
        raise InputError("--damping", text, "a damping ratio in (0, 1) or 'model'") from None


def _check_direction(direction: str, have: tuple[str, ...]) -> None:
    from seisrack.errors import InputError

    if direction not in have:
        raise InputError("--direction", direction, " or ".join(have) + " (a 2D rack is "
                         "analysed down-aisle only)")


def format_design(res: Any, title: str = "") -> str:
    """A readable text summary of a :class:`~seisrack.design.DesignResult`."""
    from seisrack.design.operators import AXIS

    L = [f"{title}", "Design analysis (EN 16681 / EN 1998-1 modal response spectrum)"]
    for d in res.directions:
        name = res.spectra[d] + ("" if "q =" in res.spectra[d] else f", q = {res.q[d]:g}")
        L.append(f"  {d}: {name}; {res.modal_rule_reason[d]}")
    if len(res.directions) > 1:
        L.append(f"  directions combined: {res.direction_rule_text}")
    e_d2 = {"down-aisle": res.factors["e_d2_down_aisle"],
            "cross-aisle": res.factors["e_d2_cross_aisle"]}
    L.append(f"  unit loads: horizontal mass x E_D1·E_D3 = {res.mass_factor:g}; spectrum x "
             + ", ".join(f"E_D2 = {e_d2[d]:g} ({d})" for d in res.directions))
    head = f"{'mode':>4} {'T [s]':>8} {'zeta':>6}"
    for d in res.directions:
        head += f" {'Sa ' + AXIS[d] + ' [m/s2]':>13} {'m_eff ' + AXIS[d]:>9}"
    L.append(head)
    shown = min(res.n_modes, 12)
    for k in range(shown):
        row = f"{k + 1:>4} {res.periods[k]:>8.4f} {res.damping[k]:>6.3f}"
        for d in res.directions:
            row += (f" {res.sa[d][k]:>13.4g} "
                    f"{100 * res.effective_mass[d][k] / res.total_mass[d]:>8.2f}%")
        L.append(row)
    if res.n_modes > shown:
        L.append(f"  ... {res.n_modes - shown} more modes")
    L.append("  modes hold " + ", ".join(f"{100 * res.cumulative_mass(d):.1f} % of the mass "
                                         f"{d}" for d in res.directions))
    for d in res.directions:
        ax = AXIS[d]
        L.append(f"\n{d}: base shear {res.base_shear(d) / 1e3:.3f} kN")
        st = res.storeys.get(d)
        lf = res.quantities[f"level_force_{ax}"].seismic
        disp = res.quantities[f"level_displacement_{ax}"].seismic
        L.append(f"  {'storey':>6} {'F_level [kN]':>12} {'d_s [mm]':>9} {'drift_s [mm]':>12} "
                 f"{'V [kN]':>9} {'theta':>7} {'1/(1-θ)':>8}  verdict")
        for s in range(lf.size):
            if st is None:
                L.append(f"  {s + 1:>6} {lf[s] / 1e3:>12.3f} {1e3 * disp[s]:>9.2f}")
                continue
            L.append(f"  {s + 1:>6} {lf[s] / 1e3:>12.3f} {1e3 * st.q * disp[s]:>9.2f} "
                     f"{1e3 * st.drift_s[s]:>12.2f} {st.V_tot[s] / 1e3:>9.3f} "
                     f"{st.theta[s]:>7.3f} {st.amplification[s]:>8.3f}  {st.verdicts[s]}")
    members = [q for q in res.quantities.values() if q.kind == "member"]
    if members:
        L.append("\nmembers (largest |gravity| + seismic; seismic part combined over modes "
                 "and directions)")
        wn = max(len(q.name) for q in members)
        wl = max(len(q.governing[0]) for q in members)
        for q in members:
            lab, val = q.governing
            k = q.labels.index(lab)
            L.append(f"  {q.name:<{wn}} {val:>11.4g} {q.unit:<4} at {lab:<{wl}} (gravity "
                     f"{q.gravity[k]:.4g}, seismic {q.seismic[k]:.4g})")
    L.append("\nfactors (override with --factors KEY=VALUE):")
    for k, v in res.factors.items():
        L.append(f"  {k:<17} {v:<6g} {res.factor_sources.get(k, '')}")
    for n in res.notes:
        L.append(f"note: {n}")
    return "\n".join(L)


__all__ = ["format_design", "register", "run"]
