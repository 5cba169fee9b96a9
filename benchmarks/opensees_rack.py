"""The paper rack (or any compiled seisrack rack) rebuilt in OpenSeesPy, node for node.

A peer model for ``benchmarks/rack_vs_opensees.py`` and ``tests/test_opensees_parity.py``.
openseespy is never a runtime dependency of seisrack; this module imports it lazily.

Mapping from the compiled :class:`seisrack.model.FrameModel` (``model.mesh``):

- every mesh node becomes an OpenSees node (``ndm=2, ndf=3``) at the same coordinates;
- nodes that share DOF indices in ``mesh.node_dofs`` (a semi-rigid beam end shares ux, uy with
  its upright node and owns its rotation) are tied with ``equalDOF`` (Transformation handler);
- every member is a ``dispBeamColumn`` with an ``Elastic`` section (same E, A, I), 3-point
  Gauss-Legendre integration, a ``Linear`` transformation and consistent mass
  (``-mass rho*A -cMass``). For a prismatic elastic member this is *exactly* seisrack's
  cubic-Hermite / linear-axial element: same 6x6 stiffness and consistent mass (checked: the
  eigenvalues of a 4-element cantilever agree to 1e-8).

  Why not ``elasticBeamColumn``: in OpenSeesPy 3.7.1, ``ElasticBeam2d`` with element mass
  (``-mass``, lumped or ``-cMass``) under ``UniformExcitation`` subtracts its ground-motion
  inertia load Q twice (``getResistingForce`` subtracts Q, and ``getResistingForceIncInertia``
  calls it and subtracts Q again), so its own mass is driven at 2·a_g. Measured here: the
  effective load M·ü of a 4-element cantilever after one tiny step from rest is exactly
  2.000 × (−M r a_g) with ``elasticBeamColumn -cMass`` and 1.000 × with ``dispBeamColumn
  -cMass``; nodal masses are correct. On the paper rack (40 kg of steel under 1600 kg of
  pallets) the bug inflates the peak displacement by ~1.8 %; with 10× the steel density, by
  ~15 %. ``element="elastic"`` keeps that variant for demonstration;
- every spring of ``mesh.springs`` (beam-to-upright and base rotational springs) is a
  ``zeroLength`` with an ``Elastic`` material of the same stiffness, between the two nodes
  owning the DOFs (a fixed extra node for a spring to the ground), with ``-doRayleigh 1`` since
  seisrack's K (and so C = a0 M + a1 K) contains them;
- a pallet's vertical mass is nodal mass on the uy of the node owning ``pallet_vdof`` (as in
  seisrack's M; several pallets on one node add up). Its horizontal mass sits on its own node
  (uy, rz fixed) at that place, joined to the node owning ``pallet_dof`` in one of two modes:

  * ``pallets="friction"`` (default): a ``zeroLength`` with ``ElasticPP(kInit, eps_y =
    mu m g / kInit)`` in direction 1 — a regularised Coulomb law with a constant normal force
    m g and equal static and dynamic coefficients. Why not ``flatSliderBearing`` with a
    ``Coulomb`` friction model: it reads N from the bearing's axial force, so it needs a
    vertical pallet DOF and a gravity pre-analysis, and it is regularised by the same
    elastic–perfectly-plastic kInit; without vertical excitation N = m g is constant and both
    give the same law. Neither can hold mu_s > mu_d (the static coefficient is used);
  * ``pallets="rigid"``: an ``equalDOF`` in ux (no element, no sliding, no extra stiffness):
    the pallet moves with its beam node, as seisrack's sliders that never slip.

  Either way the pallet mass has no Rayleigh damping (seisrack's sliders carry none, and its
  ``M`` in C = a0 M + a1 K excludes their horizontal masses);
- damping: ``rayleigh a0 a1 0 0`` (current-stiffness proportional; every member is elastic so
  current = initial). When a0 != 0 it is given by regions: the structural nodes get a0 for
  the pallets' vertical nodal masses, then the structural elements get (a0, a1) so their
  consistent mass is damped too (in this order: see ``build``); the pallet nodes and
  friction elements are in no region;
- ground motion: ``UniformExcitation`` in direction 1 with a ``Path`` time series at the
  record's dt (linear interpolation, as seisrack's analysis grid);
- Newmark average acceleration (gamma = 1/2, beta = 1/4), Newton, NormDispIncr test.

Two builders make this same model: :func:`build_from_export` executes the script written by
``seisrack export opensees`` (``seisrack.export.opensees_script``), so the benchmark and the
parity test check what users get, and :func:`run` and ``scale_opensees.py`` use it.
:func:`build` is the original hand-built model, kept for two things the export does not
write: the ``element="elastic"`` (elasticBeamColumn) demonstration of the OpenSees 3.7.1 bug,
and one friction coefficient per pallet given as an array. Both give the same tags and
commands (checked: identical histories, see ``tests/test_export_opensees.py``).

A step whose ``analyze`` fails is retried with 10 and 100 substeps, then with ModifiedNewton
(initial tangent) and KrylovNewton; if it still fails it is forced through with a fixed number
of iterations and counted in ``failed_steps``. Steps that needed any fallback are counted in
``retried_steps``.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

#: friction coefficient standing for "no sliding" in the OpenSees model
NO_SLIDING_MU = 100.0
#: how pallets are joined to their beam node (see the module docstring)
PALLET_MODES = ("friction", "rigid")


def _ops():
    import openseespy.opensees as ops  # lazy: optional peer

    return ops


def opensees_version() -> str:
    ops = _ops()
    try:
        return str(ops.version())
    except Exception:  # pragma: no cover - very old openseespy
        import importlib.metadata

        return importlib.metadata.version("openseespy")


@dataclass
class OpenSeesRack:
    """Tags of the OpenSees model built from a seisrack FrameModel."""

    node_tag: np.ndarray  # (n_node,) OpenSees tag of each mesh node
    level_nodes: list[np.ndarray]  # per level: one OpenSees node per distinct ux DOF
    pallet_beam_node: np.ndarray  # (m,) OpenSees tag of each pallet's beam node
    pallet_node: np.ndarray  # (m,) OpenSees tag of each pallet's own (sliding) node
    pallet_element: np.ndarray  # (m,) zeroLength friction element tags
    pallet_level: np.ndarray  # (m,) 0-based level of each pallet
    structure_elements: list[int]
    n_eq: int = 0


@dataclass
class OpenSeesResponse:
    """Time histories (relative to the ground unless stated) and run statistics."""

    t: np.ndarray  # (n_t,) [s]
    beam_displacement: np.ndarray  # (n_t, n_level) [m] mean ux of the level's nodes
    beam_acceleration: np.ndarray  # (n_t, n_level) [m/s2] absolute
    friction: np.ndarray  # (n_t, m) [N] force of the beam ON each pallet
    pallet_sliding: np.ndarray  # (n_t, m) [m] pallet node ux - beam node ux
    pallet_level: np.ndarray  # (m,)
    failed_steps: int
    retried_steps: int
    n_steps: int
    build_time_s: float
    analysis_time_s: float
    settings: dict[str, Any] = field(default_factory=dict)

    @property
    def wall_time_s(self) -> float:
        return self.build_time_s + self.analysis_time_s

    def peaks(self) -> dict[str, Any]:
        """Same keys and definitions as ``RackResponse.peaks()``."""
        return {
            "beam_displacement_m": float(np.max(np.abs(self.beam_displacement))),
            "beam_acceleration_m_s2": float(np.max(np.abs(self.beam_acceleration))),
            "total_friction_force_N": float(np.max(np.abs(self.friction.sum(axis=1)))),
            "pallet_sliding_m": np.max(np.abs(self.pallet_sliding), axis=0).tolist(),
            "pallet_residual_m": self.pallet_sliding[-1].tolist(),
        }


def build(model, mu: float | np.ndarray | None = None, k_init: float = 1e8,
          element: str = "disp", pallets: str = "friction") -> OpenSeesRack:
    """Wipe the OpenSees domain and build ``model`` in it (see the module docstring).

    Works from ``model.mesh`` and the pallet arrays only (never the assembled K, M, C), so any
    compiled rack (levels, bays, pallets, semi-rigid joints) maps node for node.

    mu: friction coefficient of every pallet (scalar or (m,)); default: ``model.pallet_mu_static``
        (ignored when ``pallets="rigid"``).
    k_init: initial stiffness of the ElasticPP friction springs [N/m].
    element: "disp" (dispBeamColumn + Elastic section, default) or "elastic"
        (elasticBeamColumn -cMass: element-mass ground load doubled in OpenSees 3.7.1).
    pallets: "friction" (ElasticPP zeroLength, default) or "rigid" (equalDOF in ux).
    """
    if element not in ("disp", "elastic"):
        raise ValueError(f"element must be 'disp' or 'elastic', not {element!r}")
    if pallets not in PALLET_MODES:
        raise ValueError(f"pallets must be one of {PALLET_MODES}, not {pallets!r}")
    ops = _ops()
    mesh = model.mesh
    ops.wipe()
    ops.model("basic", "-ndm", 2, "-ndf", 3)

    n_node = mesh.nodes.shape[0]
    tags = np.arange(1, n_node + 1)
    for i, (x, y) in enumerate(mesh.nodes):
        ops.node(int(tags[i]), float(x), float(y))
    next_node = n_node + 1

    # Owners: the first node holding each DOF index owns it; later holders are tied to it.
    owner: dict[int, tuple[int, int]] = {}  # dof -> (node index, direction 0..2)
    ties: dict[tuple[int, int], list[int]] = {}  # (master, slave) -> directions (1-based)
    for i in range(n_node):
        d = mesh.node_dofs[i]
        fixity = [int(v < 0) for v in d]
        if any(fixity):
            ops.fix(int(tags[i]), *fixity)
        for k in range(3):
            if d[k] < 0:
                continue
            if int(d[k]) in owner:
                m_node, m_dir = owner[int(d[k])]
                if m_dir != k:
                    raise ValueError("a DOF shared across directions cannot be mirrored")
                ties.setdefault((m_node, i), []).append(k + 1)
            else:
                owner[int(d[k])] = (i, k)
    n_eq = 0
    for (m_node, s_node), dirs in ties.items():
        ops.equalDOF(int(tags[m_node]), int(tags[s_node]), *dirs)
        n_eq += 1

    # Members
    ops.geomTransf("Linear", 1)
    struct_eles: list[int] = []
    ele = 0
    sections: dict[tuple[float, float, float], int] = {}
    for e, (i, j) in enumerate(mesh.elements):
        ele += 1
        E, A, I = float(mesh.E[e]), float(mesh.A[e]), float(mesh.I[e])
        rho_a = float(mesh.density[e] * mesh.A[e])
        if element == "elastic":
            ops.element("elasticBeamColumn", ele, int(tags[i]), int(tags[j]), A, E, I, 1,
                        "-mass", rho_a, "-cMass")
        else:
            sec = sections.get((E, A, I))
            if sec is None:
                sec = sections[(E, A, I)] = len(sections) + 1
                ops.section("Elastic", sec, E, A, I)
                ops.beamIntegration("Legendre", sec, sec, 3)
            ops.element("dispBeamColumn", ele, int(tags[i]), int(tags[j]), 1, sec,
                        "-mass", rho_a, "-cMass")
        struct_eles.append(ele)

    # Connection springs (rotational, or whatever direction the DOF pair has)
    mat = 0
    for (da, db), k in zip(mesh.springs, mesh.spring_k, strict=True):
        a = owner[int(da)] if da >= 0 else None
        b = owner[int(db)] if db >= 0 else None
        if a is None and b is None:
            continue
        if a is None or b is None:
            free = a if a is not None else b
            assert free is not None
            gx, gy = mesh.nodes[free[0]]
            ground = next_node
            next_node += 1
            ops.node(ground, float(gx), float(gy))
            ops.fix(ground, 1, 1, 1)
            ni, nj, direction = ground, int(tags[free[0]]), free[1] + 1
        else:
            if a[1] != b[1]:
                raise ValueError("spring between different directions")
            ni, nj, direction = int(tags[a[0]]), int(tags[b[0]]), a[1] + 1
        mat += 1
        ops.uniaxialMaterial("Elastic", mat, float(k))
        ele += 1
        ops.element("zeroLength", ele, ni, nj, "-mat", mat, "-dir", direction,
                    "-doRayleigh", 1)
        struct_eles.append(ele)

    # Pallets
    m = int(model.pallet_mass.size)
    mus = np.broadcast_to(
        np.asarray(model.pallet_mu_static if mu is None else mu, dtype=float), (m,))
    level_of_dof = {int(d): lv for lv, dofs in enumerate(model.level_dofs[0]) for d in dofs}
    vertical_mass: dict[int, float] = {}  # OpenSees node -> summed pallet vertical mass
    p_beam, p_node, p_ele, p_lev = [], [], [], []
    for j in range(m):
        mass = float(model.pallet_mass[j])
        v_owner = owner[int(model.pallet_vdof[j, 0])]
        vn = int(tags[v_owner[0]])
        vertical_mass[vn] = vertical_mass.get(vn, 0.0) + mass
        h_owner = owner[int(model.pallet_dofs[j, 0, 0])]
        bn = int(tags[h_owner[0]])
        x, y = mesh.nodes[h_owner[0]]
        pn = next_node
        next_node += 1
        ops.node(pn, float(x), float(y))
        ops.fix(pn, 0, 1, 1)
        ops.mass(pn, mass, 0.0, 0.0)
        if pallets == "rigid":
            ops.equalDOF(bn, pn, 1)
            n_eq += 1
            p_ele.append(-1)
        else:
            fy = float(mus[j]) * mass * float(model.g)
            mat += 1
            ops.uniaxialMaterial("ElasticPP", mat, float(k_init), fy / float(k_init))
            ele += 1
            ops.element("zeroLength", ele, bn, pn, "-mat", mat, "-dir", 1)
            p_ele.append(ele)
        p_beam.append(bn)
        p_node.append(pn)
        p_lev.append(level_of_dof[int(model.pallet_dofs[j, 0, 0])])
    for vn, mv in vertical_mass.items():  # once per node: ops.mass replaces, it does not add
        ops.mass(vn, 0.0, mv, 0.0)

    # Levels: one node per distinct horizontal DOF (as seisrack's level_dofs)
    levels = [np.array([int(tags[owner[int(d)][0]]) for d in dofs])
              for dofs in model.level_dofs[0]]

    a0, a1 = (float(c) for c in model.damping_coefficients)
    if a0 == 0.0:
        ops.rayleigh(0.0, a1, 0.0, 0.0)  # pallet springs have no -doRayleigh: undamped
    else:
        # Nodes first: a0 on the nodal (pallet vertical) masses of the structure only. A node
        # region also applies its factors to every element whose nodes all lie in it, so the
        # element region must come second, or the members would lose a1 (measured: the top
        # level of the 3 x 3 rack then peaks 1.6 % high). Elements carry (a0, a1): their
        # consistent mass is in seisrack's M.
        ops.region(1, "-node", *[int(t) for t in tags], "-rayleigh", a0, 0.0, 0.0, 0.0)
        ops.region(2, "-ele", *struct_eles, "-rayleigh", a0, a1, 0.0, 0.0)
    return OpenSeesRack(
        node_tag=tags, level_nodes=levels, pallet_beam_node=np.array(p_beam, dtype=int),
        pallet_node=np.array(p_node, dtype=int), pallet_element=np.array(p_ele, dtype=int),
        pallet_level=np.array(p_lev, dtype=int), structure_elements=struct_eles, n_eq=n_eq,
    )


def exported_namespace(model, mu: float | None = None, k_init: float = 1e8,
                       pallets: str = "friction") -> dict[str, Any]:
    """Execute the script of ``seisrack export opensees`` for ``model`` (it defines its tables
    and ``build``/``modal``/``run`` but builds nothing) and return its namespace."""
    from seisrack.export import opensees_script

    text = opensees_script(model, pallets=pallets, mu=mu, k_init=k_init)
    ns: dict[str, Any] = {"__name__": "seisrack_exported_rack"}
    exec(compile(text, "<seisrack export opensees>", "exec"), ns)  # noqa: S102 - our own text
    return ns


def build_from_export(model, mu: float | None = None, k_init: float = 1e8,
                      pallets: str = "friction") -> OpenSeesRack:
    """Wipe the OpenSees domain and build ``model`` with its exported script.

    The same model as :func:`build` with ``element="disp"`` (same tags, same commands; the
    exported script is what users get from ``seisrack export opensees``), so the benchmark and
    the parity test check the export. mu: one coefficient for every pallet or None (each
    pallet's ``mu_static``).
    """
    if pallets not in PALLET_MODES:
        raise ValueError(f"pallets must be one of {PALLET_MODES}, not {pallets!r}")
    ns = exported_namespace(model, mu=mu, k_init=k_init, pallets=pallets)
    ns["build"](pallets)
    n_node = len(ns["NODES"])
    rigid = pallets == "rigid"
    return OpenSeesRack(
        node_tag=np.arange(1, n_node + 1),
        level_nodes=[np.array(lv, dtype=int) for lv in ns["LEVEL_NODES"]],
        pallet_beam_node=np.array(ns["PALLET_BEAM_NODE"], dtype=int),
        pallet_node=np.array(ns["PALLET_NODE"], dtype=int),
        pallet_element=np.array([-1] * len(ns["PALLETS"]) if rigid else ns["PALLET_ELEMENT"],
                                dtype=int),
        pallet_level=np.array(ns["PALLET_LEVEL"], dtype=int),
        structure_elements=list(range(1, ns["N_STRUCTURE_ELEMENTS"] + 1)),
        n_eq=len(ns["EQUAL_DOF"]) + (len(ns["PALLETS"]) if rigid else 0),
    )


def periods(n_modes: int = 3) -> np.ndarray:
    """Periods [s] of the model currently built (pallets held by their elastic springs)."""
    ops = _ops()
    lam = np.asarray(ops.eigen("-fullGenLapack", n_modes), dtype=float)
    return 2.0 * np.pi / np.sqrt(lam)


def _set_solver(algorithm: str, tol: float, max_iter: int) -> None:
    ops = _ops()
    if algorithm == "FixedNumIter":
        ops.test("FixedNumIter", max_iter)
        ops.algorithm("Newton")
        return
    ops.test("NormDispIncr", tol, max_iter)
    if algorithm == "ModifiedNewton":
        ops.algorithm("ModifiedNewton", "-initial")
    else:
        ops.algorithm(algorithm)


def setup_analysis(ag: np.ndarray, ag_dt: float, *, system: str = "BandGeneral",
                   tol: float = 1e-10, max_iter: int = 25, linear: bool = False) -> None:
    """Ground motion, constraints, numbering, system and Newmark for the model just built.

    ag: (n,) [m/s²] horizontal ground acceleration sampled at ``ag_dt`` [s] (a Path series:
        linear interpolation, as seisrack's grid). linear: ``Linear -factorOnce`` instead of
        Newton (valid only for a linear model at a constant step: pallets="rigid").
    """
    ops = _ops()
    ops.timeSeries("Path", 1, "-dt", float(ag_dt), "-values", *np.asarray(ag, float).tolist())
    ops.pattern("UniformExcitation", 1, 1, "-accel", 1)
    ops.constraints("Transformation")
    ops.numberer("RCM")
    ops.system(system)
    ops.integrator("Newmark", 0.5, 0.25)
    if linear:
        ops.algorithm("Linear", "-factorOnce")
    else:
        _set_solver("Newton", tol, max_iter)
    ops.analysis("Transient")


#: outcome of :func:`advance`
STEP_OK, STEP_RETRIED, STEP_FAILED = 0, 1, 2


def advance(t_target: float, dt: float, tol: float = 1e-10, max_iter: int = 25) -> int:
    """One analysis step of ``dt`` ending at ``t_target``, with the fallbacks of the module
    docstring. Returns STEP_OK, STEP_RETRIED (converged after a fallback) or STEP_FAILED
    (forced through with a fixed number of iterations)."""
    ops = _ops()
    if ops.analyze(1, dt) == 0:
        return STEP_OK
    outcome = STEP_FAILED
    for n_sub, algo in ((10, "Newton"), (100, "Newton"), (10, "ModifiedNewton"),
                        (10, "KrylovNewton")):
        _set_solver(algo, tol, max_iter * 4)
        if _substeps(t_target, n_sub, dt) == 0:
            outcome = STEP_RETRIED
            break
    if outcome == STEP_FAILED:
        _set_solver("FixedNumIter", tol, max_iter)
        _substeps(t_target, 10, dt)
    _set_solver("Newton", tol, max_iter)
    return outcome


def run(
    model, record, *, mu: float | np.ndarray | None = None, k_init: float = 1e8,
    dt: float = 0.005, tol: float = 1e-10, max_iter: int = 25, element: str = "disp",
    pallets: str = "friction",
) -> OpenSeesResponse:
    """Time history of ``model`` under ``record`` (a seisrack Record) in OpenSees.

    The analysis runs on ``dt`` (record.dt must be a whole multiple of it, as in seisrack)
    for the record's duration; the outputs are on that grid. Records every history (one
    Python call per node and step): for speed on large racks see ``scale_opensees.py``.
    """
    ops = _ops()
    t0 = time.perf_counter()
    if element == "disp" and np.ndim(mu) == 0:
        rack = build_from_export(model, mu=None if mu is None else float(mu), k_init=k_init,
                                 pallets=pallets)
    else:  # the elasticBeamColumn demonstration, or one mu per pallet: the hand-built model
        rack = build(model, mu=mu, k_init=k_init, element=element, pallets=pallets)
    ag = np.asarray(record.accel, dtype=float)
    setup_analysis(ag, float(record.dt), tol=tol, max_iter=max_iter)
    build_time = time.perf_counter() - t0

    k = round(record.dt / dt)
    if k < 1 or abs(record.dt / dt - k) > 1e-9 * k:
        raise ValueError(f"record dt {record.dt} is not a whole multiple of dt {dt}")
    n_steps = (ag.size - 1) * k
    t_grid = np.arange(n_steps + 1) * dt
    ag_grid = np.interp(t_grid, np.arange(ag.size) * record.dt, ag)

    n_lev = len(rack.level_nodes)
    m = rack.pallet_node.size
    disp = np.zeros((n_steps + 1, n_lev))
    acc = np.zeros((n_steps + 1, n_lev))
    fric = np.zeros((n_steps + 1, m))
    slide = np.zeros((n_steps + 1, m))
    acc[0] = ag_grid[0]
    level_nodes = [[int(n) for n in lv] for lv in rack.level_nodes]
    pb = [int(n) for n in rack.pallet_beam_node]
    pn = [int(n) for n in rack.pallet_node]
    pe = [int(e) for e in rack.pallet_element]
    pm = [float(x) for x in model.pallet_mass]
    nodeDisp, nodeAccel, eleResponse = ops.nodeDisp, ops.nodeAccel, ops.eleResponse

    failed = retried = 0
    t1 = time.perf_counter()
    for step in range(1, n_steps + 1):
        outcome = advance(step * dt, dt, tol, max_iter)
        retried += outcome != STEP_OK
        failed += outcome == STEP_FAILED
        for lv, nodes in enumerate(level_nodes):
            disp[step, lv] = sum(nodeDisp(n, 1) for n in nodes) / len(nodes)
            acc[step, lv] = sum(nodeAccel(n, 1) for n in nodes) / len(nodes) + ag_grid[step]
        for j in range(m):
            slide[step, j] = nodeDisp(pn[j], 1) - nodeDisp(pb[j], 1)
            if pe[j] < 0:  # rigid: the force that accelerates the pallet with its node
                fric[step, j] = pm[j] * (nodeAccel(pn[j], 1) + ag_grid[step])
            else:
                # basic force of the zeroLength = k (u_pallet - u_beam) = force ON the beam;
                # the beam pushes the pallet with the opposite force.
                fric[step, j] = -eleResponse(pe[j], "basicForce")[0]
    analysis_time = time.perf_counter() - t1
    ops.wipe()
    return OpenSeesResponse(
        t=t_grid, beam_displacement=disp, beam_acceleration=acc, friction=fric,
        pallet_sliding=slide, pallet_level=rack.pallet_level, failed_steps=failed,
        retried_steps=retried, n_steps=n_steps, build_time_s=build_time,
        analysis_time_s=analysis_time,
        settings={
            "k_init_N_m": k_init, "mu": None if mu is None else np.asarray(mu).tolist(),
            "dt_s": dt, "integrator": "Newmark 0.5 0.25", "algorithm": "Newton",
            "test": f"NormDispIncr {tol:g} {max_iter}", "system": "BandGeneral",
            "constraints": "Transformation", "geomTransf": "Linear",
            "element": ("dispBeamColumn, Elastic section, Legendre 3, -cMass"
                        if element == "disp" else "elasticBeamColumn -cMass"),
            "friction": "zeroLength ElasticPP" if pallets == "friction" else "rigid (equalDOF)",
            "model": ("seisrack export opensees script"
                      if element == "disp" and np.ndim(mu) == 0 else "hand-built (build())"),
            "rayleigh": list(model.damping_coefficients),
        },
    )


def _substeps(t_target: float, n_sub: int, dt: float) -> int:
    """Advance from the last committed time to ``t_target`` in ``n_sub`` equal substeps."""
    ops = _ops()
    remaining = t_target - ops.getTime()
    if remaining <= 1e-12:
        return 0
    n = max(1, int(math.ceil(remaining / (dt / n_sub) - 1e-6)))
    h = remaining / n
    for _ in range(n):
        ok = ops.analyze(1, h)
        if ok != 0:
            return ok
    return 0
