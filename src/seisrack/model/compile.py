"""Compile a :class:`RackSpec` into a :class:`FrameModel` (arrays only), 2D or 3D.

Steps, the same for both dimensions: the features the spec asks for are built for its dimension
(:mod:`seisrack.model.features`) → mesh (:mod:`seisrack.model.rack_mesh` for a plane rack,
:mod:`seisrack.model.rack_mesh3d` for a space rack, ``[geometry] depth``) → vectorised sparse
assembly of K and consistent M (:mod:`seisrack.fe.assembly`) → stability check (sparse LDLᵀ
pivots, :func:`seisrack.fe.stability.is_positive_definite`) → pallets (vertical mass on their
support nodes' uy DOFs, shared equally; horizontal mass kept apart as sliders) → optional P-Δ
(``[second_order]``: K = K_E + K_G with the axial forces of a linear static gravity solve,
:mod:`seisrack.fe.geometric`, and the critical load factor) → damping
(:mod:`seisrack.fe.damping`, the first period by sparse shift-invert Lanczos; C = a0·M +
a1·(K_E + K_G), or a0·M + a1·K_E with ``stiffness_term = "elastic"``) → hinges. Nothing
here forms a dense (n_dof, n_dof) matrix beyond 500 DOFs.
"""

from __future__ import annotations

import logging
import math

import numpy as np
import scipy.sparse as sp

from seisrack.dynamics.axial import AxialPDelta
from seisrack.errors import InputError
from seisrack.fe import damping as fe_damping
from seisrack.fe import geometric
from seisrack.fe.assembly import assemble_sparse, symmetric_csr
from seisrack.fe.mesh import FloatArray, FrameMesh
from seisrack.fe.modal import modal_from_matrices
from seisrack.fe.stability import is_positive_definite, symmetric_lu
from seisrack.model.features import check_features
from seisrack.model.frame_model import FrameModel, read_only
from seisrack.model.pallet_layout import pallet_layout
from seisrack.model.rack_mesh import RackMesh, build_rack_mesh
from seisrack.model.spec import STIFFNESS_TERMS, Connections, RackSpec

log = logging.getLogger(__name__)

#: the translation slot of each horizontal direction in ``node_dofs`` (x; then z in 3D)
_SLOTS = {2: (0,), 3: (0, 2)}


def compile_rack(spec: RackSpec) -> FrameModel:
    """Build the frame model of ``spec`` (2D, or 3D with ``[geometry] depth``); InputError for
    a feature not built for the rack's dimension, missing section properties or a mechanism."""
    check_features(spec)
    rm = _build_mesh(spec)
    mesh = rm.mesh
    K, M = assemble_sparse(mesh)
    _check_stable(K, spec)
    slots = _SLOTS[mesh.ndm]
    nd = mesh.node_dofs

    n_p = len(spec.pallets)
    k = rm.n_side // spec.geometry.rows  # supports of a pallet: the beams of its row
    p_node = np.array([[_support_node(rm, p.level - 1, p.bay - 1, k * (p.row - 1) + side,
                                      p.position) for side in range(k)]
                       for p in spec.pallets], dtype=np.int64).reshape(n_p, k)
    p_dofs = nd[p_node][:, :, list(slots)]
    p_vdof = nd[p_node, 1]
    p_mass = np.array([p.mass for p in spec.pallets], dtype=float)
    share = np.repeat(p_mass / k, k)
    M = symmetric_csr(M + _diagonal(p_vdof.ravel(), share, mesh.n_dof))  # vertical mass

    r_x, r_y = _influence(nd[:, 0], mesh.n_dof), _influence(nd[:, 1], mesh.n_dof)
    r_z = _influence(nd[:, 2], mesh.n_dof) if mesh.ndm == 3 else None
    lam_cr = None
    K_E = K
    axial = None
    if spec.second_order.p_delta:
        K, lam_cr, axial = _p_delta(spec, mesh, K, M, r_y)
    horizontal = np.concatenate([p_dofs[:, :, d].ravel() for d in range(len(slots))])
    Mt = M + _diagonal(horizontal, np.tile(share, len(slots)), mesh.n_dof)  # pallets attached
    a0, a1 = _damping(spec, K, Mt, r_x, r_y)
    K_C = K if spec.damping.stiffness_term == "with_p_delta" else K_E  # the a1 term's K
    plan = _torsion(mesh, Mt, r_x, r_z) if r_z is not None else (None, None)

    log.info("compiled %dD rack: %d nodes, %d members, %d bars, %d DOFs, %d pallets",
             mesh.ndm, mesh.nodes.shape[0], mesh.n_el, mesh.trusses.shape[0], mesh.n_dof, n_p)
    return read_only(FrameModel(
        mesh=mesh, K_sparse=K, M_sparse=M, C_sparse=symmetric_csr(a0 * M + a1 * K_C),
        damping_coefficients=(a0, a1), damping_stiffness_term=spec.damping.stiffness_term,
        r_x=r_x, r_y=r_y, r_z=r_z, r_theta=plan[1],
        plan_centre=plan[0], pallet_node=p_node, pallet_dofs=p_dofs, pallet_vdof=p_vdof,
        pallet_mass=p_mass,
        pallet_mu_static=np.array([p.mu_static for p in spec.pallets], dtype=float),
        pallet_mu_dynamic=np.array([p.mu_dynamic for p in spec.pallets], dtype=float),
        pallet_friction_rate=np.array([p.friction_rate for p in spec.pallets], dtype=float),
        pallet_level=np.array([p.level - 1 for p in spec.pallets], dtype=np.int64),
        pallet_bay=np.array([p.bay - 1 for p in spec.pallets], dtype=np.int64),
        pallet_slot=_slots(spec),
        pallet_row=np.array([p.row - 1 for p in spec.pallets], dtype=np.int64),
        pallet_x=np.asarray(mesh.nodes[p_node[:, 0], 0], dtype=float) if n_p else np.zeros(0),
        pallet_depth=_optional(spec, "depth"), pallet_overhang=_optional(spec, "overhang"),
        layout=pallet_layout(spec),
        level_dofs=tuple(_level_dofs(rm, spec, s) for s in slots),
        level_y=np.array(spec.geometry.level_y), upright_x=np.array(spec.geometry.upright_x),
        depth=float(spec.geometry.depth or 0.0), element_kind=rm.element_kind,
        element_storey=rm.element_storey, element_line=rm.element_line,
        element_side=rm.element_side, truss_kind=rm.truss_kind, truss_line=rm.truss_line,
        column_line=rm.column_line, column_side=rm.column_side, base_nodes=rm.base_nodes,
        level_nodes=rm.level_nodes, upright_base_elements=rm.upright_base_elements,
        upright_below_elements=rm.upright_below_elements,
        upright_above_elements=rm.upright_above_elements, member_mass=mesh.member_mass,
        g=spec.g, title=spec.title, critical_load_factor=lam_cr, n_rows=spec.geometry.rows,
        frame_z=np.array(spec.geometry.frame_z), axial_p_delta=axial,
        **_hinges(spec, mesh, K, M, r_y),
    ))


def _build_mesh(spec: RackSpec) -> RackMesh:
    if spec.geometry.depth is None:
        return build_rack_mesh(spec)
    from seisrack.model.rack_mesh3d import build_rack_mesh_3d

    return build_rack_mesh_3d(spec)


def _hinges(spec: RackSpec, mesh: FrameMesh, K: sp.csr_matrix, M: sp.csr_matrix,
            r_y: FloatArray) -> dict[str, np.ndarray]:
    """Every connection spring as a hinge, with its law (``[hysteresis]``, else elastic), and
    its rotation under gravity: a time history starts from the rack standing under its own
    and its pallets' weight, so a connector already carries its gravity moment. InputError
    when gravity alone takes a hinge past the elastic branch of its law."""
    from seisrack.dynamics._hysteresis import HYST_NPAR
    from seisrack.model.hinge_law import STIFFNESS_RTOL, HingeLaw

    springs, k = mesh.springs, mesh.spring_k
    base = springs[:, 1] < 0
    # a connector spring is (upright rotation, beam-end rotation): its rotation is beam end
    # minus upright
    dofs = np.where(base[:, None], springs, springs[:, ::-1])
    node_of: dict[int, int] = {}
    rot = mesh.node_dofs[:, mesh.ndm:]  # the rotation slots
    for node, row in enumerate(rot):
        for d in row[row >= 0]:
            node_of.setdefault(int(d), node)  # the upright's node owns its rotation first
    node = np.array([node_of[int(a)] for a in springs[:, 0]], dtype=np.int64)
    laws, pars, th_y = [], [], []
    for kk, is_base in zip(k, base, strict=True):
        law = spec.hysteresis.base if is_base else spec.hysteresis.beam_to_upright
        law = law if law is not None else HingeLaw("elastic", float(kk))
        if law.kind != "elastic" and abs(float(kk) / law.stiffness - 1.0) > STIFFNESS_RTOL:
            # a 3D rack's base plate bends about both axes with one law: its elastic stiffness
            # must be that of both springs (a cross-aisle base_cross of its own has no law)
            raise InputError(
                "connections.base_cross", float(kk),
                f"the stiffness of the [hysteresis.base] law ({law.stiffness:.6g} N·m/rad): "
                "the law acts about both axes of a base plate", source=spec.source,
                hint="Remove base_cross (the base plates are then equally stiff about both "
                     "axes), or leave [hysteresis.base] out")
        code, par = law.pack()
        laws.append(code)
        pars.append(par)
        th_y.append(law.yield_rotation)
    th_g = np.zeros(k.shape[0])
    if spec.hysteresis.nonlinear and k.size:
        u_g = symmetric_lu(K).solve(-spec.g * (M @ r_y))
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


def _slots(spec: RackSpec) -> np.ndarray:
    """(m,) 0-based position of each pallet within its (row, level, bay), left to right (ties
    in input order)."""
    slot = np.zeros(len(spec.pallets), dtype=np.int64)
    for j, p in enumerate(spec.pallets):
        slot[j] = sum(1 for i, q in enumerate(spec.pallets)
                      if q.level == p.level and q.bay == p.bay and q.row == p.row
                      and (q.position < p.position or (q.position == p.position and i < j)))
    return slot


def _optional(spec: RackSpec, name: str) -> FloatArray:
    return np.array([math.nan if getattr(p, name) is None else getattr(p, name)
                     for p in spec.pallets], dtype=float)


def _diagonal(dofs: np.ndarray, values: FloatArray, n_dof: int) -> sp.csr_matrix:
    """(n_dof, n_dof) CSR with ``values`` summed on the diagonal at ``dofs``."""
    return sp.csr_matrix((values, (dofs, dofs)), shape=(n_dof, n_dof))


def _support_node(rm: RackMesh, lev: int, bay: int, side: int, pos: float) -> int:
    """The beam node nearest a pallet's centre (the stations include every pallet centre)."""
    st = rm.beam_stations[(lev, bay)]
    return int(rm.beam_nodes[(lev, bay, side)][np.abs(st - pos).argmin()])


def _level_dofs(rm: RackMesh, spec: RackSpec, slot: int) -> tuple[np.ndarray, ...]:
    nd = rm.mesh.node_dofs
    out = []
    for lev in range(spec.geometry.n_levels):
        nodes = [rm.level_nodes[:, lev]] + [
            rm.beam_nodes[(lev, b, s)] for b in range(spec.geometry.n_bays)
            for s in range(rm.n_side)]
        dofs = nd[np.concatenate(nodes), slot]
        out.append(np.unique(dofs[dofs >= 0]))
    return tuple(out)


def _influence(dofs: np.ndarray, n_dof: int) -> FloatArray:
    r = np.zeros(n_dof)
    r[dofs[dofs >= 0]] = 1.0
    return r


def _torsion(mesh: FrameMesh, Mt: sp.spmatrix, r_x: FloatArray, r_z: FloatArray
             ) -> tuple[tuple[float, float], FloatArray]:
    """Plan mass centre (x_c, z_c) and the rigid plan rotation about the vertical through it
    (ux = z − z_c, uz = −(x − x_c), ry = 1: a unit rotation about +y)."""
    nd, X = mesh.node_dofs, mesh.nodes
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


def _check_stable(K: sp.csr_matrix, spec: RackSpec) -> None:
    if is_positive_definite(K):
        return
    c = spec.connections
    if spec.geometry.depth is None or (c.beam_to_upright == 0.0 and c.base == 0.0):
        raise InputError(
            "connections", {"beam_to_upright": Connections.describe_value(c.beam_to_upright),
                            "base": Connections.describe_value(c.base)},
            "connections that make the frame stable down-aisle (pinned bases need "
            "beam-to-upright joints with a stiffness > 0)", source=spec.source,
            hint="The stiffness matrix is singular: the frame is a sway mechanism")
    br = spec.bracing
    raise InputError(
        "bracing.pattern", br.pattern if br is not None else None,
        "a bracing that makes every upright frame stable (triangulated panels, e.g. \"Z\", "
        "\"D\", \"K\" or \"X\", or a semi-rigid base_cross)", source=spec.source,
        hint="The stiffness matrix is singular: with this bracing and base "
             f"({Connections.describe_value(c.base_cross_k)} cross-aisle) an upright frame is "
             "a mechanism")


def _p_delta(spec: RackSpec, mesh: FrameMesh, K_E: sp.csr_matrix, M: sp.csr_matrix,
             r_y: FloatArray) -> tuple[sp.csr_matrix, float, AxialPDelta | None]:
    """K_E + K_G, the critical load factor and, with ``axial = "current"``, the P-Δ of the
    axial forces' change (:mod:`seisrack.dynamics.axial`); InputError if the gravity load
    buckles the rack. A plane or a space rack (members in both bending planes, bracing bars
    included: :mod:`seisrack.fe.geometric`).

    Gravity load F = -g·M·r_y: with the consistent member mass this is the consistent load
    vector of the members' self weight (a rigid vertical translation is exact in the element's
    shape functions), plus each pallet's weight on its support nodes' uy DOFs.
    """
    form = spec.second_order.form
    u_g = symmetric_lu(K_E).solve(-spec.g * (M @ r_y))  # the static state under gravity
    N, N_bar = geometric.axial_forces(mesh, u_g)
    K_G = geometric.geometric_stiffness(mesh, N, form, N_bar)  # bars: their string stiffness
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
    axial = None
    if spec.second_order.axial == "current":
        rows, owner, scale = geometric.unit_geometric_factors(mesh, form)
        axial = AxialPDelta(geometric.axial_operator(mesh), rows, owner, scale, rows @ u_g)
    return symmetric_csr(K_E + K_G), lam, axial


def _damping(spec: RackSpec, K: sp.csr_matrix, Mt: sp.csr_matrix, r_x: FloatArray,
             r_y: FloatArray) -> tuple[float, float]:
    """(a0, a1) of ``[damping]``; ``period = "first"`` is the first period of K (with K_G under
    P-Δ), whichever stiffness the a1 term then multiplies (``stiffness_term``)."""
    d = spec.damping
    if d.stiffness_term not in STIFFNESS_TERMS:
        raise InputError("damping.stiffness_term", d.stiffness_term,
                         " or ".join(f'"{x}"' for x in STIFFNESS_TERMS), source=spec.source)
    if d.kind == "stiffness":
        if d.period == "first":
            period = float(modal_from_matrices(K, Mt, r_x, r_y, n_modes=1).periods[0])
        else:
            period = float(d.period)
        return fe_damping.stiffness_proportional(d.ratio, period)
    if d.kind == "rayleigh":
        return fe_damping.rayleigh(d.pairs)
    return 0.0, 0.0
