"""Export a compiled rack as a standalone OpenSeesPy script: :func:`opensees_script`.

The script rebuilds the :class:`~seisrack.model.FrameModel` node for node from ``model.mesh``
and the pallet arrays (never from the assembled K, M, C), with the mapping of
``benchmarks/opensees_rack.py`` (which now builds its peer model by executing this script):

- every mesh node is an OpenSees node (``ndm=2, ndf=3``); nodes sharing DOF indices in
  ``mesh.node_dofs`` (a semi-rigid beam end shares ux, uy with its upright node) are tied by
  ``equalDOF`` to the first node holding the DOF;
- every member is a ``dispBeamColumn`` with an ``Elastic`` section, 3-point Gauss-Legendre
  integration, a ``Linear`` transformation and consistent mass: for a prismatic elastic member
  exactly seisrack's cubic-Hermite / linear-axial element. Not ``elasticBeamColumn``: in
  OpenSeesPy 3.7.1 its element mass takes the ground-motion load twice under
  ``UniformExcitation`` (measured in ``benchmarks/opensees_rack.py``);
- every spring of ``mesh.springs`` is a ``zeroLength`` with an ``Elastic`` material, to a
  fixed extra node for a spring to the ground, with ``-doRayleigh 1``. When the rack's
  ``[hysteresis]`` gives the connections a nonlinear law (``hysteresis=spec.hysteresis``), each
  spring's material is instead the law's OpenSees equivalent
  (:func:`~seisrack.export.opensees_materials.opensees_uniaxial`: ``ElasticPP``, ``Steel01``,
  ``Pinching4``). Each zeroLength runs from node i to node j so that its deformation
  u_j − u_i is seisrack's hinge rotation u[a] − u[b] (``model.hinge_dofs = (a, b)``: beam end
  minus upright for a connector, base rotation for a base plate): an asymmetric law acts with
  the same sign in both programs;
- a pallet's vertical mass is nodal mass on its beam node's uy; its horizontal mass sits on its
  own node (uy, rz fixed), joined to the beam node by an ``ElasticPP`` zeroLength (yield force
  mu m g, initial stiffness ``k_init``: a regularised Coulomb law with mu_s = mu_d) or, with
  ``pallets="rigid"``, by ``equalDOF`` in ux;
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

from seisrack import __version__
from seisrack.errors import InputError
from seisrack.export._opensees_template import FUNCTIONS

log = logging.getLogger(__name__)

PALLET_MODES = ("friction", "rigid")
#: racks with at most this many DOFs use a dense eigen solver and a banded system
DENSE_MAX_DOF = 500
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
    from seisrack.model.features import require

    require("the OpenSees export (seisrack export opensees)", model.ndm, "model",
            f"a {model.ndm}D rack")
    if pallets not in PALLET_MODES:
        raise InputError("pallets", pallets, " or ".join(PALLET_MODES))
    if mu is not None and not (np.isfinite(mu) and mu > 0.0):
        raise InputError("mu", mu, "a finite friction coefficient > 0")
    if not (np.isfinite(k_init) and k_init > 0.0):
        raise InputError("k_init", k_init, "a finite stiffness > 0 [N/m]")
    t = _tables(model, mu)
    materials = _spring_materials(model, hysteresis)
    dense = model.n_dof <= DENSE_MAX_DOF
    mu_d_differs = bool(mu is None and np.any(model.pallet_mu_dynamic != model.pallet_mu_static))
    if mu_d_differs and pallets == "friction":
        log.warning("the OpenSees friction elements use mu_static; the rack's lower dynamic "
                    "coefficients are not represented")
    parts = [
        _header(model, pallets, mu, k_init, record, source, mu_d_differs, materials),
        "import math\n\nimport openseespy.opensees as ops\n",
        f"TITLE = {model.title or 'seisrack rack'!r}",
        f"PALLET_MODE = {pallets!r}  # 'friction' or 'rigid': how build() joins the pallets",
        f"G = {_f(model.g)}  # [m/s2]",
        f"K_INIT = {_f(k_init)}  # [N/m] initial stiffness of the friction springs",
        f"RAYLEIGH = ({_f(model.damping_coefficients[0])}, "
        f"{_f(model.damping_coefficients[1])})  # (a0, a1): C = a0 M + a1 K",
        f"EIGEN_SOLVER = {'-fullGenLapack' if dense else '-genBandArpack'!r}",
        f"SYSTEM = {'BandGeneral' if dense else 'SparseSYM'!r}  # of run()",
        "",
        _table("NODES", "(x, y) [m]; tag = position + 1", t["nodes"]),
        _table("FIX", "(node, fix ux, fix uy, fix rz) of the supports", t["fix"]),
        _table("EQUAL_DOF", "(retained node, constrained node, directions): shared DOFs",
               t["equal_dof"]),
        _table("SECTIONS", "(E [Pa], A [m2], I [m4], mass per length [kg/m]); tag = position "
               "+ 1", t["sections"]),
        _table("MEMBERS", "(node i, node j, section) of each dispBeamColumn; tag = position + 1",
               t["members"]),
        _table("GROUND_NODES", "(tag, x, y): fixed nodes for the springs to the ground",
               t["ground"]),
        _table("SPRINGS", "(node i, node j, direction, k [N m/rad or N/m]): zeroLength Elastic;"
               " tag = len(MEMBERS) + position + 1", t["springs"]),
        _table("SPRING_MATERIALS", "per spring, uniaxialMaterial (type, args...) of its "
               "[hysteresis] law; empty: Elastic k", materials),
        _table("VERTICAL_MASS", "(node, mass [kg]): the pallets' vertical masses",
               t["vertical_mass"]),
        _table("PALLETS", "(own node, beam node, mass [kg], mu, 0-based level), in input order",
               t["pallets"]),
        _table("LEVEL_NODES", "per level, bottom to top: one node per distinct ux DOF",
               t["levels"]),
        _record(record),
        FUNCTIONS.strip("\n"),
    ]
    return "\n".join(parts) + "\n"


def _tables(model: Any, mu: float | None) -> dict[str, list]:
    """The data tables of the script (OpenSees tags, 1-based) from the compiled model."""
    mesh = model.mesh
    n_node = int(mesh.nodes.shape[0])
    owner: dict[int, tuple[int, int]] = {}  # dof -> (node index, direction 0..2)
    ties: dict[tuple[int, int], list[int]] = {}
    fix = []
    for i in range(n_node):
        d = [int(v) for v in mesh.node_dofs[i]]
        if any(v < 0 for v in d):
            fix.append((i + 1, *(int(v < 0) for v in d)))
        for k in range(3):
            if d[k] < 0:
                continue
            if d[k] in owner:
                m_node, m_dir = owner[d[k]]
                if m_dir != k:
                    raise InputError("mesh.node_dofs", f"DOF {d[k]} in two directions",
                                     "a DOF shared by nodes in one direction")
                ties.setdefault((m_node, i), []).append(k + 1)
            else:
                owner[d[k]] = (i, k)
    equal_dof = [(a + 1, b + 1, tuple(dirs)) for (a, b), dirs in ties.items()]

    sections: dict[tuple[float, float, float, float], int] = {}
    members = []
    for e, (i, j) in enumerate(mesh.elements):
        key = (float(mesh.E[e]), float(mesh.A[e]), float(mesh.I[e]),
               float(mesh.density[e] * mesh.A[e]))
        sec = sections.setdefault(key, len(sections) + 1)
        members.append((int(i) + 1, int(j) + 1, sec))

    next_node = n_node + 1
    ground, springs = [], []
    for n, ((da, db), k) in enumerate(zip(mesh.springs, mesh.spring_k, strict=True)):
        da, db = _oriented(model, n, int(da), int(db))
        a = owner.get(int(da)) if da >= 0 else None
        b = owner.get(int(db)) if db >= 0 else None
        if a is None and b is None:
            continue
        if a is None or b is None:
            free = a if a is not None else b
            assert free is not None
            gx, gy = mesh.nodes[free[0]]
            ground.append((next_node, float(gx), float(gy)))
            springs.append((next_node, free[0] + 1, free[1] + 1, float(k)))
            next_node += 1
        else:
            if a[1] != b[1]:
                raise InputError("mesh.springs", f"DOFs {da}, {db}", "DOFs of one direction")
            springs.append((a[0] + 1, b[0] + 1, a[1] + 1, float(k)))

    m = int(model.pallet_mass.size)
    mus = np.broadcast_to(np.asarray(model.pallet_mu_static if mu is None else mu, float), (m,))
    level_of_dof = {int(d): lv for lv, dofs in enumerate(model.level_dofs[0]) for d in dofs}
    vertical: dict[int, float] = {}
    pallet_rows = []
    for j in range(m):
        mass = float(model.pallet_mass[j])
        vn = owner[int(model.pallet_vdof[j, 0])][0] + 1
        vertical[vn] = vertical.get(vn, 0.0) + mass  # ops.mass replaces: sum per node first
        bn = owner[int(model.pallet_dofs[j, 0, 0])][0] + 1
        pallet_rows.append((next_node, bn, mass, float(mus[j]),
                            level_of_dof[int(model.pallet_dofs[j, 0, 0])]))
        next_node += 1
    levels = [[owner[int(d)][0] + 1 for d in dofs] for dofs in model.level_dofs[0]]
    return {
        "nodes": [(float(x), float(y)) for x, y in mesh.nodes],
        "fix": fix, "equal_dof": equal_dof, "sections": list(sections), "members": members,
        "ground": ground, "springs": springs, "vertical_mass": list(vertical.items()),
        "pallets": pallet_rows, "levels": levels,
    }


def _oriented(model: Any, n: int, da: int, db: int) -> tuple[int, int]:
    """Spring ``n``'s DOFs ordered (b, a) after its hinge (``model.hinge_dofs[n] = (a, b)``), so
    that the zeroLength deformation u_j − u_i is the hinge rotation u[a] − u[b]."""
    hd = getattr(model, "hinge_dofs", None)
    if hd is None:
        return da, db
    a, b = (int(v) for v in hd[n])
    if {a, b} != {da, db}:
        raise InputError("model.hinge_dofs", f"hinge {n}: DOFs ({a}, {b})",
                         f"the DOFs ({da}, {db}) of spring {n} of mesh.springs (one hinge per "
                         "spring, in the same order)")
    return b, a


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


def _header(model: Any, pallets: str, mu: float | None, k_init: float, record: Any,
            source: str | None, mu_d_differs: bool, materials: Sequence[tuple] = ()) -> str:
    mu_text = (f"mu = {mu:g} for every pallet" if mu is not None
               else "each pallet's mu_static from the rack file")
    mu_note = ("\nNOTE: some pallets have mu_dynamic < mu_static; this model uses mu_static "
               "(it cannot\nhold two coefficients), so it slides later and less than seisrack "
               "there.\n" if mu_d_differs else "")
    kinds = sorted({m[0] for m in materials})
    hyst = (f"\n- connections: nonlinear ([hysteresis]): zeroLength with {', '.join(kinds)} "
            "(see\n  SPRING_MATERIALS); zeroLength deformation u_j - u_i = seisrack's hinge "
            "rotation." if materials else "")
    pd_note = ("\nNOTE: the rack has P-Delta ([second_order]) in seisrack; this script uses a "
               "Linear\ntransformation, so it leaves P-Delta out.\n"
               if getattr(model, "critical_load_factor", None) is not None else "")
    rec = f"\nGround motion: {record.name} (dt {record.dt:g} s), run by `python` this script.\n" \
        if record is not None else ""
    a0, a1 = model.damping_coefficients
    text = f'''"""OpenSeesPy model of: {model.title or "a seisrack rack"}

Exported by seisrack {__version__} (`seisrack export opensees`) from {source or "a compiled rack"}.
{model.n_dof} free DOFs in seisrack, {model.mesh.nodes.shape[0]} nodes, {model.mesh.n_el} members, \
{model.mesh.springs.shape[0]} connector springs, {model.n_pallets} pallets.
Units: SI (m, kg, s, N, Pa).

Use: `python {{this file}}` prints the first periods; `import` it for build(), modal(n),
gravity() and run(ag, dt) (gravity first, then the ground acceleration ag [m/s2] sampled at
dt [s]; returns the peak level displacements [m] from the gravity state).

Modelling choices (as seisrack's compiled model, node for node):
- members: dispBeamColumn, Elastic section, 3-point Gauss-Legendre, Linear transformation,
  consistent mass (-cMass): exactly seisrack's cubic-Hermite beam element. Not
  elasticBeamColumn: in OpenSeesPy 3.7.1 its element mass receives the ground-motion load
  twice under UniformExcitation (measured; see seisrack's benchmarks/opensees_rack.py).
- semi-rigid joints: the beam end is its own node, equalDOF 1 2 to the upright node, with a
  zeroLength Elastic rotational spring; base springs go to fixed extra nodes.{hyst}
- pallets (default mode here: {pallets}): vertical mass on the beam node; horizontal mass on
  the pallet's own node (uy, rz fixed), joined to the beam node by
  * "friction": a zeroLength with ElasticPP(K_INIT, mu m g / K_INIT), a regularised Coulomb
    law with a constant normal force m g and mu_s = mu_d; {mu_text};
    K_INIT = {k_init:g} N/m. Limits: no static/dynamic distinction, no vertical excitation, and the
    elastic stage needs sqrt(K_INIT / m) dt well below 1 (results move with K_INIT and dt);
  * "rigid": equalDOF in ux (no sliding): the pallets move with their beam node.
- damping: Rayleigh C = a0 M + a1 K_initial with a0 = {a0:.6g}, a1 = {a1:.6g} on the
  structure only (regions when a0 != 0); the pallets' horizontal masses and friction elements
  are undamped.
- analysis in run(): UniformExcitation (direction 1, Path time series), Newmark average
  acceleration, Newton + NormDispIncr, Transformation constraints.
{mu_note}{pd_note}{rec}"""
'''
    return text
