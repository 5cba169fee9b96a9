"""Compile a :class:`RackSpec` into a :class:`FrameModel` (arrays only).

Steps: mesh (:mod:`seisrack.model.rack_mesh`) → vectorised sparse assembly of K and consistent
M (:mod:`seisrack.fe.assembly`) → stability check (sparse LDLᵀ pivots,
:func:`seisrack.fe.stability.is_positive_definite`) → pallets (vertical mass on their node's uy
DOF; horizontal mass kept apart as sliders) → optional P-Δ (``[second_order]``: K = K_E + K_G
with the axial forces of a linear static gravity solve, :mod:`seisrack.fe.geometric`, and the
critical load factor) → damping (:mod:`seisrack.fe.damping`, the first
period by sparse shift-invert Lanczos). Nothing here forms a dense (n_dof, n_dof) matrix
beyond 500 DOFs (the P-Δ buckling factor of a small rack is a dense LAPACK solve).
"""

from __future__ import annotations

import logging

import numpy as np
import scipy.sparse as sp

from seisrack.errors import InputError
from seisrack.fe import damping as fe_damping
from seisrack.fe import geometric
from seisrack.fe.assembly import assemble_sparse, symmetric_csr
from seisrack.fe.mesh import FloatArray, FrameMesh
from seisrack.fe.modal import modal_from_matrices
from seisrack.fe.stability import is_positive_definite
from seisrack.model.frame_model import FrameModel, read_only
from seisrack.model.rack_mesh import RackMesh, build_rack_mesh
from seisrack.model.spec import Connections, Pallet, RackSpec

log = logging.getLogger(__name__)


def compile_rack(spec: RackSpec) -> FrameModel:
    """Build the frame model of ``spec``; raises InputError if the frame is a mechanism.

    A 3D rack (``[geometry] depth`` given) compiles to a
    :class:`~seisrack.model.frame_model3d.FrameModel3D` instead
    (:func:`seisrack.model.compile3d.compile_rack_3d`).
    """
    if spec.is_3d:
        from seisrack.model.compile3d import compile_rack_3d

        return compile_rack_3d(spec)  # type: ignore[return-value]
    rm = build_rack_mesh(spec)
    mesh = rm.mesh
    K, M = assemble_sparse(mesh)
    _check_stable(K, spec)

    n_p = len(spec.pallets)
    p_node = np.array([_pallet_node(rm, p) for p in spec.pallets], dtype=np.int64)
    p_dof = mesh.node_dofs[p_node, 0] if n_p else np.zeros(0, dtype=np.int64)
    p_vdof = mesh.node_dofs[p_node, 1] if n_p else np.zeros(0, dtype=np.int64)
    p_mass = np.array([p.mass for p in spec.pallets], dtype=float)
    M = symmetric_csr(M + _diagonal(p_vdof, p_mass, mesh.n_dof))  # vertical pallet mass
    lim_neg, lim_pos = sliding_limits(spec)

    r_x = _influence(mesh.node_dofs[:, 0], mesh.n_dof)
    r_y = _influence(mesh.node_dofs[:, 1], mesh.n_dof)
    lam_cr = None
    if spec.second_order.p_delta:
        K, lam_cr = _p_delta(spec, mesh, K, M, r_y)
    Mt = M + _diagonal(p_dof, p_mass, mesh.n_dof)  # pallets rigidly attached
    a0, a1 = _damping(spec, K, Mt, r_x, r_y)
    C = symmetric_csr(a0 * M + a1 * K)

    level_dofs = []
    for lev in range(spec.geometry.n_levels):
        nodes = [rm.level_nodes[:, lev]] + [rm.beam_nodes[(lev, b)]
                                            for b in range(spec.geometry.n_bays)]
        level_dofs.append(np.unique(mesh.node_dofs[np.concatenate(nodes), 0]))

    member_mass = float(np.sum(mesh.density * mesh.A * mesh.lengths))
    log.info("compiled rack: %d nodes, %d elements, %d DOFs, %d pallets",
             mesh.nodes.shape[0], mesh.n_el, mesh.n_dof, n_p)
    return read_only(FrameModel(
        mesh=mesh, K_sparse=K, M_sparse=M, C_sparse=C, damping_coefficients=(a0, a1),
        r_x=r_x, r_y=r_y, pallet_dof=p_dof, pallet_vdof=p_vdof, pallet_node=p_node,
        pallet_mass=p_mass,
        pallet_mu_static=np.array([p.mu_static for p in spec.pallets], dtype=float),
        pallet_mu_dynamic=np.array([p.mu_dynamic for p in spec.pallets], dtype=float),
        pallet_limit_neg=lim_neg, pallet_limit_pos=lim_pos, level_dofs=tuple(level_dofs),
        level_y=np.array(spec.geometry.level_y), upright_x=np.array(spec.geometry.upright_x),
        element_kind=rm.element_kind, element_storey=rm.element_storey,
        element_line=rm.element_line, base_nodes=rm.base_nodes, level_nodes=rm.level_nodes,
        upright_base_elements=rm.upright_base_elements,
        upright_below_elements=rm.upright_below_elements,
        upright_above_elements=rm.upright_above_elements,
        member_mass=member_mass, g=spec.g, title=spec.title, critical_load_factor=lam_cr,
        **_hinges(spec, rm, K, M, r_y),
        pallet_friction_rate=np.array([p.friction_rate for p in spec.pallets], dtype=float),
    ))


def _hinges(spec: RackSpec, rm: RackMesh, K: sp.csr_matrix, M: sp.csr_matrix,
            r_y: FloatArray) -> dict[str, np.ndarray]:
    """Every connection spring as a hinge, with its law (``[hysteresis]``, else elastic), and
    its rotation under gravity: a time history starts from the rack standing under its own
    and its pallets' weight, so a connector already carries its gravity moment. InputError
    when gravity alone takes a hinge past the elastic branch of its law."""
    from seisrack.model.hinge_law import HingeLaw

    mesh = rm.mesh
    springs, k = mesh.springs, mesh.spring_k
    base = springs[:, 1] < 0
    # a connector spring is (upright rz, beam-end rz): its rotation is beam end − upright
    dofs = np.where(base[:, None], springs, springs[:, ::-1])
    node_of = {}
    for node, d in enumerate(mesh.node_dofs):
        if d[2] >= 0:
            node_of.setdefault(int(d[2]), node)  # the upright's node owns its rotation first
    node = np.array([node_of[int(a)] for a in springs[:, 0]], dtype=np.int64)
    laws, pars, th_y = [], [], []
    for kk, is_base in zip(k, base, strict=True):
        law = spec.hysteresis.base if is_base else spec.hysteresis.beam_to_upright
        law = law if law is not None else HingeLaw("elastic", float(kk))
        code, par = law.pack()
        laws.append(code)
        pars.append(par)
        th_y.append(law.yield_rotation)
    from seisrack.dynamics._hysteresis import HYST_NPAR

    th_g = np.zeros(k.shape[0])
    if spec.hysteresis.nonlinear and k.size:
        import scipy.sparse.linalg as spla

        u_g = spla.spsolve(sp.csc_matrix(K), -spec.g * (M @ r_y))
        ug = np.append(u_g, 0.0)  # index -1: the ground
        th_g = ug[dofs[:, 0]] - ug[dofs[:, 1]]
        _check_gravity_elastic(spec, th_g, k, base, np.array(th_y))
    return {"hinge_dofs": dofs.astype(np.int64).reshape(-1, 2), "hinge_k": k.astype(float),
            "hinge_kind": base.astype(np.int64), "hinge_node": node,
            "hinge_law": np.array(laws, dtype=np.int64),
            "hinge_par": np.array(pars, dtype=float).reshape(-1, HYST_NPAR),
            "hinge_yield_rotation": np.array(th_y, dtype=float),
            "hinge_rotation_gravity": th_g}


def _check_gravity_elastic(spec: RackSpec, th_g: FloatArray, k: FloatArray, base: np.ndarray,
                           th_y: FloatArray) -> None:
    over = np.abs(th_g) >= th_y
    if np.any(over):
        i = int(np.argmax(np.abs(th_g) / th_y))
        which = "base" if base[i] else "beam_to_upright"
        raise InputError(
            f"hysteresis.{which}", f"elastic branch up to {th_y[i]:.4g} rad",
            f"a law whose elastic branch holds the gravity rotation {abs(th_g[i]):.4g} rad "
            f"(moment {abs(k[i] * th_g[i]):.4g} N·m)", source=spec.source,
            hint="The rack's own and its pallets' weight alone would yield this connection; "
                 "check the yield moment, the pallet masses and the beam section")


def sliding_limits(spec: RackSpec) -> tuple[FloatArray, FloatArray]:
    """Allowed sliding of each pallet towards -x and +x [m], both >= 0.

    An explicit ``sliding_limit`` applies to both sides. Otherwise each side is the free distance
    from the pallet's edge to the nearest obstacle on that side: the edge of the neighbouring
    pallet on the same beam, or the upright (taken at its centreline, i.e. the bay end).
    """
    n = len(spec.pallets)
    neg, pos = np.zeros(n), np.zeros(n)
    shelves: dict[tuple[int, int], list[Pallet]] = {}  # pallets sharing a bay and level
    for p in spec.pallets:
        shelves.setdefault((p.bay, p.level), []).append(p)
    for i, p in enumerate(spec.pallets):
        left, right = p.position - p.width / 2, p.position + p.width / 2
        wall_l, wall_r = 0.0, spec.geometry.bays[p.bay - 1]
        for q in shelves[(p.bay, p.level)]:
            if q is p:
                continue
            if q.position < p.position:
                wall_l = max(wall_l, q.position + q.width / 2)
            elif q.position > p.position:
                wall_r = min(wall_r, q.position - q.width / 2)
        neg[i], pos[i] = max(left - wall_l, 0.0), max(wall_r - right, 0.0)
        if p.sliding_limit is not None:
            neg[i] = pos[i] = p.sliding_limit
    return neg, pos


def _diagonal(dofs: np.ndarray, values: FloatArray, n_dof: int) -> sp.csr_matrix:
    """(n_dof, n_dof) CSR with ``values`` summed on the diagonal at ``dofs``."""
    return sp.csr_matrix((values, (dofs, dofs)), shape=(n_dof, n_dof))


def _pallet_node(rm: RackMesh, p: Pallet) -> int:
    st = rm.beam_stations[(p.level - 1, p.bay - 1)]
    return int(rm.beam_nodes[(p.level - 1, p.bay - 1)][np.abs(st - p.position).argmin()])


def _influence(dofs: np.ndarray, n_dof: int) -> FloatArray:
    r = np.zeros(n_dof)
    r[dofs[dofs >= 0]] = 1.0
    return r


def _check_stable(K: sp.csr_matrix, spec: RackSpec) -> None:
    if not is_positive_definite(K):
        c = spec.connections
        raise InputError(
            "connections", {"beam_to_upright": Connections.describe_value(c.beam_to_upright),
                            "base": Connections.describe_value(c.base)},
            "connections that make the frame stable (pinned bases need beam-to-upright "
            "joints with a stiffness > 0)", source=spec.source,
            hint="The stiffness matrix is singular: the frame is a sway mechanism")


def _p_delta(spec: RackSpec, mesh: FrameMesh, K_E: sp.csr_matrix, M: sp.csr_matrix,
             r_y: FloatArray) -> tuple[sp.csr_matrix, float]:
    """K_E + K_G and the critical load factor; InputError if the gravity load buckles the rack.

    Gravity load F = -g·M·r_y: with the consistent member mass this is the consistent load
    vector of the members' self weight (a rigid vertical translation is exact in the element's
    shape functions), plus each pallet's weight on its node's uy DOF.
    """
    form = spec.second_order.form
    N = geometric.gravity_axial_forces(mesh, K_E, -spec.g * (M @ r_y))
    K_G = geometric.geometric_stiffness(mesh, N, form)
    lam = geometric.critical_load_factor(K_E, K_G)
    if lam <= 1.0:
        raise InputError(
            "second_order.p_delta", True,
            "a rack that is stable under its own gravity load (critical load factor > 1)",
            source=spec.source,
            hint=f"The critical load factor of the gravity load is {lam:.4g} <= 1: the uprights "
                 "buckle under the members' and pallets' weight. Use stiffer uprights, base "
                 "plates or connectors, or lighter pallets")
    log.info("P-Δ (%s form): critical load factor %.4g", form, lam)
    return symmetric_csr(K_E + K_G), lam


def _damping(spec: RackSpec, K: sp.csr_matrix, Mt: sp.csr_matrix, r_x: FloatArray,
             r_y: FloatArray) -> tuple[float, float]:
    d = spec.damping
    if d.kind == "stiffness":
        if d.period == "first":
            period = float(modal_from_matrices(K, Mt, r_x, r_y, n_modes=1).periods[0])
        else:
            period = float(d.period)
        return fe_damping.stiffness_proportional(d.ratio, period)
    if d.kind == "rayleigh":
        return fe_damping.rayleigh(d.pairs)
    return 0.0, 0.0
