"""Compile a 3D :class:`RackSpec` (``[geometry] depth`` given) into a :class:`FrameModel3D`.

Steps, as for the 2D rack (:mod:`seisrack.model.compile`): check the sections the members need
→ mesh (:mod:`seisrack.model.rack_mesh3d`) → sparse assembly of K and consistent M
(:mod:`seisrack.fe.assembly3d`) → stability check (sparse LDLᵀ pivots,
:func:`seisrack.fe.stability.is_positive_definite`; a singular K is a mechanism, reported
against the bracing or the connections) → pallets (half of each pallet's mass on the front and
half on the rear beam node; vertical mass in M, horizontal masses kept apart as for the 2D
sliders) → influence vectors → damping. ``[second_order]`` and nonlinear ``[hysteresis]`` are
2D-only for now and refused here.
"""

from __future__ import annotations

import dataclasses
import logging
import math

import numpy as np
import scipy.sparse as sp

from seisrack.errors import InputError
from seisrack.fe import damping as fe_damping
from seisrack.fe.assembly import symmetric_csr
from seisrack.fe.assembly3d import assemble_sparse_3d
from seisrack.fe.modal import modal_from_matrices
from seisrack.fe.stability import is_positive_definite
from seisrack.model.dimension import RUN_3D_MESSAGE, require_2d  # noqa: F401  (re-exported)
from seisrack.model.frame_model import read_only
from seisrack.model.frame_model3d import FrameModel3D
from seisrack.model.pallet_layout3d import pallet_layout_3d
from seisrack.model.rack_mesh3d import RackMesh3D, build_rack_mesh_3d
from seisrack.model.spec import Connections, RackSpec

log = logging.getLogger(__name__)

def compile_rack_3d(spec: RackSpec) -> FrameModel3D:
    """Build the 3D model of ``spec``; InputError for missing section properties, a mechanism
    or 2D-only options."""
    _check_spec(spec)
    rm = build_rack_mesh_3d(spec)
    mesh = rm.mesh
    K, M = assemble_sparse_3d(mesh)
    _check_stable(K, spec)

    nd = mesh.node_dofs
    n_p = len(spec.pallets)
    p_node = np.array([_pallet_nodes(rm, p.level - 1, p.bay - 1, p.position)
                       for p in spec.pallets], dtype=np.int64).reshape(n_p, 2)
    p_mass = np.array([p.mass for p in spec.pallets], dtype=float)
    p_v = nd[p_node, 1]
    M = symmetric_csr(M + sp.csr_matrix((np.repeat(0.5 * p_mass, 2), (p_v.ravel(),
                                         p_v.ravel())), shape=K.shape))
    r_x, r_y, r_z = (_influence(nd[:, d], mesh.n_dof) for d in range(3))
    model = FrameModel3D(
        mesh=mesh, K_sparse=K, M_sparse=M, C_sparse=symmetric_csr(0.0 * K),
        damping_coefficients=(0.0, 0.0), r_x=r_x, r_y=r_y, r_z=r_z, r_theta=np.zeros(0),
        plan_centre=(0.0, 0.0), pallet_node=p_node, pallet_dof_x=nd[p_node, 0],
        pallet_dof_z=nd[p_node, 2], pallet_vdof=p_v, pallet_mass=p_mass,
        pallet_mu_static=np.array([p.mu_static for p in spec.pallets], dtype=float),
        pallet_mu_dynamic=np.array([p.mu_dynamic for p in spec.pallets], dtype=float),
        pallet_depth=np.array([math.nan if p.depth is None else p.depth
                               for p in spec.pallets], dtype=float),
        pallet_overhang=np.array([math.nan if p.overhang is None else p.overhang
                                  for p in spec.pallets], dtype=float),
        pallet_level=np.array([p.level for p in spec.pallets], dtype=np.int64),
        pallet_bay=np.array([p.bay for p in spec.pallets], dtype=np.int64),
        layout=pallet_layout_3d(spec),
        element_kind=rm.element_kind, element_storey=rm.element_storey,
        element_line=rm.element_line, element_side=rm.element_side, truss_kind=rm.truss_kind,
        truss_line=rm.truss_line, base_nodes=rm.base_nodes, level_nodes=rm.level_nodes,
        level_dofs_x=_level_dofs(rm, spec, 0), level_dofs_z=_level_dofs(rm, spec, 2),
        level_y=np.array(spec.geometry.level_y), upright_x=np.array(spec.geometry.upright_x),
        depth=float(spec.geometry.depth or 0.0),
        member_mass=float(np.sum(mesh.density * mesh.A * mesh.lengths) + np.sum(
            mesh.truss_density * mesh.truss_A * np.linalg.norm(
                mesh.nodes[mesh.trusses[:, 1]] - mesh.nodes[mesh.trusses[:, 0]], axis=1))),
        g=spec.g, title=spec.title)
    Mt = model.total_mass_sparse()
    centre, r_t = _torsion_vector(mesh, Mt, r_x, r_z)
    a0, a1 = _damping(spec, K, Mt, r_x, r_y)
    log.info("compiled 3D rack: %d nodes, %d beam-columns, %d bars, %d DOFs, %d pallets",
             mesh.nodes.shape[0], mesh.elements.shape[0], mesh.trusses.shape[0], mesh.n_dof,
             n_p)
    return read_only(dataclasses.replace(
        model, r_theta=r_t, plan_centre=centre, damping_coefficients=(a0, a1),
        C_sparse=symmetric_csr(a0 * M + a1 * K)))


def _check_spec(spec: RackSpec) -> None:
    src = spec.source
    if spec.second_order.p_delta:
        raise InputError("second_order.p_delta", True, "false for a 3D rack (P-Δ is 2D-only "
                         "for now)", source=src)
    if spec.hysteresis.nonlinear:
        raise InputError("hysteresis", "nonlinear law", "elastic connections for a 3D rack "
                         "(nonlinear hinges are 2D-only for now)", source=src)
    geo = spec.geometry
    needed = sorted(set(geo.beam_sections) | set(geo.upright_sections))
    for name in needed:
        s = spec.sections[name]
        for key, value in (("I", s.I), ("Iy", s.Iy), ("J", s.J)):
            if value is None or math.isnan(value):
                what = {"I": "I (or Iz): bending in the down-aisle plane",
                        "Iy": "Iy: bending in the other principal plane (cross-aisle for an "
                              "upright, horizontal for a beam)",
                        "J": "J: St Venant torsion constant"}[key]
                raise InputError(f"sections.{name}.{key}", None, f"a value > 0 [m⁴] ({what})",
                                 source=src, hint="A 3D rack needs I (or Iz), Iy and J for "
                                 "every beam and upright section")
    d = geo.depth or 0.0
    for i, p in enumerate(spec.pallets):
        if p.depth is not None and p.overhang is not None:
            if p.overhang >= p.depth:
                raise InputError(f"pallets[{i}].overhang", p.overhang,
                                 f"an overhang < the pallet depth {p.depth:g} m", source=src)
            if p.depth > d + 2 * p.overhang + 1e-9:
                raise InputError(f"pallets[{i}].depth", p.depth,
                                 f"a pallet depth <= frame depth + 2 x overhang = "
                                 f"{d + 2 * p.overhang:g} m", source=src)


def _check_stable(K: sp.csr_matrix, spec: RackSpec) -> None:
    if is_positive_definite(K):
        return
    c = spec.connections
    if c.beam_to_upright == 0.0 and c.base == 0.0:
        raise InputError(
            "connections", {"beam_to_upright": "pinned", "base": "pinned"},
            "connections that make the frame stable down-aisle (pinned bases need "
            "beam-to-upright joints with a stiffness > 0)", source=spec.source,
            hint="The stiffness matrix is singular: the frame is a sway mechanism")
    br = spec.bracing
    pattern = br.pattern if br is not None else None
    raise InputError(
        "bracing.pattern", pattern,
        "a bracing that makes every upright frame stable (triangulated panels, e.g. \"Z\", "
        "\"D\", \"K\" or \"X\", or a semi-rigid base_cross)", source=spec.source,
        hint="The stiffness matrix is singular: with this bracing and base "
             f"({Connections.describe_value(c.base_cross_k)} cross-aisle) an upright frame is "
             "a mechanism")


def _pallet_nodes(rm: RackMesh3D, lev: int, bay: int, pos: float) -> list[int]:
    i = int(np.abs(rm.beam_stations[(lev, bay)] - pos).argmin())
    return [int(rm.beam_nodes[(lev, bay, s)][i]) for s in (0, 1)]


def _influence(dofs: np.ndarray, n_dof: int) -> np.ndarray:
    r = np.zeros(n_dof)
    r[dofs[dofs >= 0]] = 1.0
    return r


def _level_dofs(rm: RackMesh3D, spec: RackSpec, d: int) -> tuple[np.ndarray, ...]:
    nd = rm.mesh.node_dofs
    out = []
    for lev in range(spec.geometry.n_levels):
        nodes = [rm.level_nodes[:, :, lev].ravel()] + [
            rm.beam_nodes[(lev, b, s)] for b in range(spec.geometry.n_bays) for s in (0, 1)]
        dofs = nd[np.concatenate(nodes), d]
        out.append(np.unique(dofs[dofs >= 0]))
    return tuple(out)


def _torsion_vector(mesh: object, Mt: sp.csr_matrix, r_x: np.ndarray, r_z: np.ndarray
                    ) -> tuple[tuple[float, float], np.ndarray]:
    """Plan mass centre (x_c, z_c) and the rigid plan rotation about the vertical through it."""
    nd, X = mesh.node_dofs, mesh.nodes  # type: ignore[attr-defined]
    n = r_x.shape[0]

    def coord_on(dof_col: int, coord_col: int) -> np.ndarray:
        v = np.zeros(n)
        free = nd[:, dof_col] >= 0
        v[nd[free, dof_col]] = X[free, coord_col]
        return v

    x_on_z, z_on_x = coord_on(2, 0), coord_on(0, 2)
    xc = float(r_z @ (Mt @ x_on_z) / (r_z @ (Mt @ r_z)))
    zc = float(r_x @ (Mt @ z_on_x) / (r_x @ (Mt @ r_x)))
    r = (z_on_x - zc * r_x) - (x_on_z - xc * r_z) + _influence(nd[:, 4], n)
    return (xc, zc), r


def _damping(spec: RackSpec, K: sp.csr_matrix, Mt: sp.csr_matrix, r_x: np.ndarray,
             r_y: np.ndarray) -> tuple[float, float]:
    d = spec.damping
    if d.kind == "stiffness":
        period = float(modal_from_matrices(K, Mt, r_x, r_y, n_modes=1).periods[0]) \
            if d.period == "first" else float(d.period)
        return fe_damping.stiffness_proportional(d.ratio, period)
    if d.kind == "rayleigh":
        return fe_damping.rayleigh(d.pairs)
    return 0.0, 0.0
