"""``seisrack export opensees RACK.toml [--pallets friction|rigid] [--mu MU] [--out FILE]
[--json]``.

Thin: load and compile the rack (2D or 3D), call :func:`seisrack.export.opensees_script`, write
the text to stdout or to ``--out`` (never over an existing file without ``--force``). With
``--json`` stdout gets one JSON object describing the export (and holding the script when there
is no ``--out``).
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import Any


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "export", help="write a rack for another program (OpenSeesPy)",
        description="Write the compiled rack for another program.")
    targets = p.add_subparsers(dest="target", metavar="FORMAT", required=True)
    o = targets.add_parser(
        "opensees", help="a standalone OpenSeesPy script of the rack",
        description="Write a standalone OpenSeesPy script of the rack, 2D or 3D: nodes, "
                    "members (2D dispBeamColumn, 3D elasticBeamColumn), bracing bars (3D "
                    "Truss), connector springs (with their [hysteresis] law: ElasticPP, "
                    "Steel01 or Pinching4), masses, Rayleigh damping, and pallets as "
                    "friction elements (2D: ElasticPP zeroLength; 3D: flatSliderBearing with "
                    "Coulomb friction; regularised, mu_s = mu_d) or rigidly attached. "
                    "`python rack_ops.py` prints its first periods; import it for build(), "
                    "modal(n) and run(ag, dt). See docs/user/export_opensees.md.")
    o.add_argument("rack", help="rack description (TOML)")
    o.add_argument("--pallets", choices=("friction", "rigid"), default="friction",
                   help="how the script joins the pallets to the beams (default friction)")
    o.add_argument("--mu", type=float, metavar="MU",
                   help="friction coefficient of every pallet (default: each pallet's "
                        "mu_static from the file)")
    o.add_argument("--k-init", type=float, default=1e8, metavar="K",
                   help="[N/m] initial stiffness of the friction springs (default 1e8)")
    o.add_argument("--out", metavar="FILE", help="write the script here instead of stdout")
    o.add_argument("--force", action="store_true", help="overwrite an existing --out file")
    o.add_argument("--json", action="store_true",
                   help="print one JSON object describing the export (with the script itself "
                        "under 'script' when there is no --out)")
    o.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from seisrack.errors import InputError
    from seisrack.export import opensees_script
    from seisrack.model import compile_rack, load_rack

    if args.mu is not None and not (math.isfinite(args.mu) and args.mu > 0.0):
        raise InputError("--mu", args.mu, "a finite friction coefficient > 0")
    if not (math.isfinite(args.k_init) and args.k_init > 0.0):
        raise InputError("--k-init", args.k_init, "a finite stiffness > 0 [N/m]")
    out = Path(args.out) if args.out else None
    if out is not None:
        if out.is_dir():
            raise InputError("--out", args.out, "a file path, not a folder")
        if out.exists() and not args.force:
            raise InputError("--out", args.out, "a file that does not exist yet",
                             hint="Pass --force to overwrite it")
    from seisrack.progress import busy

    spec = load_rack(args.rack)
    with busy(f"building the rack ({args.rack})"):
        model = compile_rack(spec)
    # [hysteresis] laws: each connection spring gets the law's OpenSees material
    text = opensees_script(model, pallets=args.pallets, mu=args.mu, k_init=args.k_init,
                           source=Path(args.rack).name, hysteresis=spec.hysteresis)
    if out is not None:
        from seisrack.atomic import write_text

        write_text(out, text)
    if args.json:
        from seisrack.cli._common import print_json

        print_json(_description(model, args, out, text))
    elif out is None:
        sys.stdout.write(text)
    else:
        print(f"OpenSeesPy script written to {out} (run: python {out})", file=sys.stderr)
    return 0


def _description(model: Any, args: argparse.Namespace, out: Path | None, text: str
                 ) -> dict[str, Any]:
    """What ``--json`` prints: the exported model's size and options, and where the script
    is (or the script itself)."""
    mesh = model.mesh
    d: dict[str, Any] = {
        "rack": args.rack, "title": model.title, "ndm": model.ndm, "ndf": mesh.ndf,
        "n_dof": model.n_dof, "nodes": int(mesh.nodes.shape[0]), "members": mesh.n_el,
        "bars": int(mesh.trusses.shape[0]), "springs": int(mesh.springs.shape[0]),
        "pallets": model.n_pallets, "pallet_mode": args.pallets, "mu": args.mu,
        "k_init": args.k_init, "lines": len(text.splitlines()),
        "out": None if out is None else str(out),
    }
    if out is None:
        d["script"] = text
    return d
