"""Export a compiled rack as a standalone OpenSeesPy script: :func:`opensees_script`.

The script rebuilds the :class:`~seisrack.model.FrameModel` node for node from ``model.mesh``
and the pallet arrays (never from the assembled K, M, C), whatever the rack's dimension (the
tables: :mod:`seisrack.export._opensees_tables`; the functions:
:mod:`seisrack.export._opensees_template`; ``benchmarks/opensees_rack.py`` builds its 2D peer
model by executing this script):

- every mesh node is an OpenSees node (``ndm 2, ndf 3`` or ``ndm 3, ndf 6``); nodes sharing
  DOF indices in ``mesh.node_dofs`` (a semi-rigid beam end shares the translations, and in 3D
  the rotations rx, ry, with its upright node) are tied by ``equalDOF`` to the first node
  holding the DOF;
- a plane member is a ``dispBeamColumn`` with an ``Elastic`` section, 3-point Gauss-Legendre
  integration, a ``Linear`` transformation and consistent mass: for a prismatic elastic member
  exactly seisrack's cubic-Hermite / linear-axial element. Not ``elasticBeamColumn``: in
  OpenSeesPy 3.7.1 its 2D element mass takes the ground-motion load twice under
  ``UniformExcitation`` (measured in ``benchmarks/opensees_rack.py``). A space member is an
  ``elasticBeamColumn`` (3D, consistent mass, ``Linear`` transformation with the member's
  ``vecxz``), written with J' = Ip and G' = G J / Ip so that its twist stiffness and inertia are
  seisrack's (OpenSees 3.7 takes the torsional inertia from J); its 3D mass is loaded once
  (measured against ``dispBeamColumn``, which has no twist inertia). Bracing bars are
  ``Truss`` elements with consistent mass;
- every spring of ``mesh.springs`` is a ``zeroLength`` with an ``Elastic`` material, to a
  fixed extra node for a spring to the ground, with ``-doRayleigh 1``. When the rack's
  ``[hysteresis]`` gives the connections a nonlinear law (``hysteresis=spec.hysteresis``), each
  spring's material is instead the law's OpenSees equivalent
  (:func:`~seisrack.export.opensees_materials.opensees_uniaxial`: ``ElasticPP``, ``Steel01``,
  ``Pinching4``). Each zeroLength runs from node i to node j so that its deformation
  u_j − u_i is seisrack's hinge rotation u[a] − u[b] (``model.hinge_dofs = (a, b)``: beam end
  minus upright for a connector, base rotation for a base plate): an asymmetric law acts with
  the same sign in both programs;
- 2D pallets: the vertical mass is nodal mass on the beam node's uy; the horizontal mass sits
  on the pallet's own node (uy, rz fixed), joined to the beam node by an ``ElasticPP``
  zeroLength (yield force mu m g, initial stiffness ``k_init``: a regularised Coulomb law with
  mu_s = mu_d) or, with ``pallets="rigid"``, by ``equalDOF`` in ux. 3D pallets: the mass is
  shared equally by the supports (front and rear beam node); ``rigid``: nodal masses there
  (seisrack's modal model); ``friction``: one own node per support on a
  ``flatSliderBearing`` with a ``Coulomb`` friction model (circular friction, normal force
  from gravity, the regularised peer of seisrack's planar sliders), the own nodes of a pallet
  tied in x and z;
- gravity (``gravity()``, before any time history): the members' and bars' weight as their
  consistent nodal loads (seisrack's −g·M·r_y, computed by the script from its tables), and
  the pallets' weights where their vertical masses are;
- damping C = a0 M + a1 K_initial, ``rayleigh(0, 0, a1, 0)`` (initial stiffness, as
  seisrack's C; the same as the current one for a linear rack) or, when a0 != 0, by regions
  (nodes, then elements), so that the pallets' horizontal masses and friction elements are
  undamped, as in seisrack.

The text depends only on the model and the arguments (no date, no paths other than
``source``): the same rack always gives the same script.
"""

from __future__ import annotations

import logging
from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np

from seisrack.errors import InputError
from seisrack.export._opensees_header import header
from seisrack.export._opensees_tables import script_tables
from seisrack.export._opensees_template import FUNCTIONS

log = logging.getLogger(__name__)

PALLET_MODES = ("friction", "rigid")
#: racks with at most this many DOFs use a dense eigen solver and a banded system
DENSE_MAX_DOF = 500
#: [N/m] axial stiffness of the 3D friction bearings (rigid against the beams' vertical
#: stiffness, ~1e6 N/m; its vertical modes, ~1 ms, are far below any analysis step)
K_AXIAL = 1e10
_WIDTH = 99


def opensees_script(
    model: Any, *, pallets: str = "friction", mu: float | None = None, k_init: float = 1e8,
    record: Any = None, source: str | None = None, hysteresis: Any = None,
) -> str:
    """The text of a standalone OpenSeesPy script of ``model`` (a compiled FrameModel).

    Args:
        model: :class:`seisrack.model.FrameModel`.
        pallets: default pallet mode of the script, "friction" or "rigid" (the script's
            ``build(pallets=...)`` can switch it).
        mu: friction coefficient of every pallet; default each pallet's ``mu_static``.
        k_init: [N/m] initial stiffness of the ElasticPP friction springs (> 0).
        record: optional :class:`seisrack.motion.Record` written into the script, which then
            runs it when executed as a program.
        source: where the rack came from (e.g. the TOML path), for the header.
        hysteresis: the rack's moment–rotation laws, ``spec.hysteresis``
            (:class:`seisrack.model.spec.Hysteresis`) of the spec ``model`` was compiled from.
            Required when the model has nonlinear connections (``model.nonlinear_hinges``): the
            springs then get the laws' OpenSees materials. Checked against the model's law
            codes and parameters.

    Returns the script (str), ending with a newline. Run it (``python rack_ops.py`` prints the
    first periods) or import it (``build()``, ``modal(n)``, ``run(ag, dt)``).
    """
    if pallets not in PALLET_MODES:
        raise InputError("pallets", pallets, " or ".join(PALLET_MODES))
    if mu is not None and not (np.isfinite(mu) and mu > 0.0):
        raise InputError("mu", mu, "a finite friction coefficient > 0")
    if not (np.isfinite(k_init) and k_init > 0.0):
        raise InputError("k_init", k_init, "a finite stiffness > 0 [N/m]")
    t = script_tables(model, mu)
    materials = _spring_materials(model, hysteresis)
    dense = model.n_dof <= DENSE_MAX_DOF
    mu_d_differs = bool(mu is None and np.any(model.pallet_mu_dynamic != model.pallet_mu_static))
    if mu_d_differs and pallets == "friction":
        log.warning("the OpenSees friction elements use mu_static; the rack's lower dynamic "
                    "coefficients are not represented")
    three_d = model.ndm == 3
    xyz = "(x, y, z)" if three_d else "(x, y)"
    slots = "ux, uy, uz, rx, ry, rz" if three_d else "ux, uy, rz"
    parts = [
        header(model, pallets, mu, k_init, record, source, mu_d_differs, materials),
        "import math\n\nimport openseespy.opensees as ops\n",
        f"TITLE = {model.title or 'seisrack rack'!r}",
        f"NDM, NDF = {model.ndm}, {model.mesh.ndf}  # coordinates and DOFs per node",
        f"PALLET_MODE = {pallets!r}  # 'friction' or 'rigid': how build() joins the pallets",
        f"G = {_f(model.g)}  # [m/s2]",
        f"K_INIT = {_f(k_init)}  # [N/m] initial stiffness of the friction "
        + ("bearings" if three_d else "springs"),
        *([f"K_AXIAL = {_f(K_AXIAL)}  # [N/m] axial stiffness of the friction bearings"]
          if three_d else []),
        "GEOM_TRANSF = 'Linear'  # 'PDelta': OpenSees' P-Delta chord term (gravity() first)",
        f"RAYLEIGH = ({_f(model.damping_coefficients[0])}, "
        f"{_f(model.damping_coefficients[1])})  # (a0, a1): C = a0 M + a1 K",
        f"EIGEN_SOLVER = {'-fullGenLapack' if dense else '-genBandArpack'!r}",
        f"SYSTEM = {'BandGeneral' if dense else 'SparseSYM'!r}  # of run()",
        "",
        _table("NODES", f"{xyz} [m]; tag = position + 1", t["nodes"]),
        _table("FIX", f"(node, fix {slots}) of the supports", t["fix"]),
        _table("EQUAL_DOF", "(retained node, constrained node, directions): shared DOFs",
               t["equal_dof"]),
        _table("SECTIONS", ("(E [Pa], A [m2], Iz [m4], Iy [m4], G' [Pa], J' [m4], mass per "
                            "length [kg/m]),\n# J' = Ip, G' = G J / Ip" if three_d else
                            "(E [Pa], A [m2], I [m4], mass per length [kg/m])")
               + "; tag = position + 1", t["sections"]),
        _table("TRANSFORMS", "vecxz of each geometric transformation (() in 2D); tag = "
               "position + 1", t["transforms"]),
        _table("MEMBERS", ("(node i, node j, section, transformation) of each "
                           "elasticBeamColumn" if three_d else
                           "(node i, node j, section) of each dispBeamColumn")
               + "; tag = position + 1", t["members"]),
        _table("TRUSSES", "(node i, node j, E [Pa], A [m2], mass per length [kg/m]) of each "
               "bar;\n# tag = len(MEMBERS) + len(SPRINGS) + position + 1", t["trusses"]),
        _table("GROUND_NODES", f"(tag, {xyz[1:-1]}): fixed nodes for the springs to the ground",
               t["ground"]),
        _table("SPRINGS", "(node i, node j, direction, k [N m/rad or N/m]): zeroLength Elastic;"
               " tag = len(MEMBERS) + position + 1", t["springs"]),
        _table("SPRING_MATERIALS", "per spring, uniaxialMaterial (type, args...) of its "
               "[hysteresis] law; empty: Elastic k", materials),
        _table("VERTICAL_MASS", "(node, mass [kg]): the pallets' vertical masses on their "
               "supports", t["vertical_mass"]),
        _table("PALLETS", "(own node, " + ("(support nodes)" if three_d else "beam node")
               + ", mass [kg], mu, 0-based level), in input order", t["pallets"]),
        _table("LEVEL_NODES", "per level, bottom to top: one node per distinct ux DOF",
               t["levels"]),
        _table("LEVEL_NODES_Z", "per level, bottom to top: one node per distinct uz DOF (3D)",
               t["levels_z"]),
        _record(record),
        FUNCTIONS.strip("\n"),
    ]
    return "\n".join(parts) + "\n"


def _spring_materials(model: Any, hysteresis: Any) -> list[tuple]:
    """Per spring, the ``uniaxialMaterial`` (type, args...) of its law; [] when all are elastic
    (the script then uses ``Elastic`` k, as for a linear rack)."""
    from seisrack.export.opensees_materials import opensees_uniaxial
    from seisrack.model.frame_model import BASE_PLATE
    from seisrack.model.hinge_law import HingeLaw

    nonlinear = bool(getattr(model, "nonlinear_hinges", False))
    if hysteresis is None:
        if nonlinear:
            raise InputError(
                "hysteresis", None, "the rack's [hysteresis] laws (spec.hysteresis)",
                hint="This model has nonlinear connections; pass hysteresis=spec.hysteresis "
                     "of the spec it was compiled from, or the springs would be exported "
                     "elastic")
        return []
    for name in ("beam_to_upright", "base"):
        law = getattr(hysteresis, name, None)
        if law is not None and not isinstance(law, HingeLaw):
            raise InputError(f"hysteresis.{name}", type(law).__name__,
                             "a seisrack.model.hinge_law.HingeLaw or None")
    if model.hinge_law is None:
        raise InputError("model", "a model without hinge arrays",
                         "a model compiled by seisrack.model.compile_rack")
    rows = []
    for n in range(model.hinge_law.shape[0]):
        is_base = int(model.hinge_kind[n]) == BASE_PLATE
        law = hysteresis.base if is_base else hysteresis.beam_to_upright
        if law is None:
            law = HingeLaw("elastic", float(model.hinge_k[n]))
        code, par = law.pack()
        if code != int(model.hinge_law[n]) or not np.array_equal(par, model.hinge_par[n]):
            raise InputError(
                f"hysteresis.{'base' if is_base else 'beam_to_upright'}", law.describe(),
                f"the law the model was compiled with (hinge {n}: law code "
                f"{int(model.hinge_law[n])}, k = {float(model.hinge_k[n]):.6g} N·m/rad)",
                hint="Pass spec.hysteresis of the spec given to compile_rack")
        args = opensees_uniaxial(law, 0)
        rows.append((args[0], *args[2:]))
    if not nonlinear:
        return []
    return rows


def _f(x: float) -> str:
    """Shortest text that reads back as the same float (deterministic, exact)."""
    return repr(float(x))


def _item(v: Any) -> str:
    if isinstance(v, tuple | list):
        inner = ", ".join(_item(x) for x in v)
        if isinstance(v, list):
            return f"[{inner}]"
        return f"({inner},)" if len(v) == 1 else f"({inner})"
    if isinstance(v, str):
        return repr(v)
    if isinstance(v, bool | int | np.integer):
        return str(int(v))
    return _f(v)


def _table(name: str, comment: str, rows: Sequence[Any]) -> str:
    """``NAME = [...]`` with its items packed into lines of at most ~_WIDTH characters."""
    lines = [f"# {comment}"]
    if not rows:
        return "\n".join([*lines, f"{name} = []", ""])
    lines.append(f"{name} = [")
    lines.extend(_pack(_item(r) for r in rows))
    lines += ["]", ""]
    return "\n".join(lines)


def _pack(items: Iterable[str]) -> list[str]:
    out, cur = [], "   "
    for it in items:
        if len(cur) + len(it) + 2 > _WIDTH and cur.strip():
            out.append(cur)
            cur = "   "
        cur += f" {it},"
    if cur.strip():
        out.append(cur)
    return out


def _record(record: Any) -> str:
    if record is None:
        return "RECORD = None  # or {'name': ..., 'dt': [s], 'accel': [m/s2, ...]}\n"
    accel = np.asarray(record.accel, dtype=float)
    lines = [f"# ground motion run by `python` this script: {len(accel)} samples",
             "RECORD = {", f"    'name': {str(record.name)!r},", f"    'dt': {_f(record.dt)},",
             "    'accel': ["]
    lines.extend("    " + s for s in _pack(_f(a) for a in accel))
    lines += ["    ],", "}", ""]
    return "\n".join(lines)
