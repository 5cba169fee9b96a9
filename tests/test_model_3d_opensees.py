"""3D rack periods against OpenSeesPy, built member by member here (issue 11 validation).

The peer model has the same nodes, OpenSees' own elements and constraints: ``elasticBeamColumn``
(3D, ``geomTransf Linear`` with vecxz = +z, ``-mass ρA -cMass``) for uprights and beams,
``Truss`` (``-rho ρA -cMass 1``) for the pin-ended bracing, coincident beam-end nodes tied to
the upright node by ``equalDOF`` (translations, rx, ry) plus a ``zeroLength`` rotational spring
about z (the connector), base nodes fixed in translation and twist with ``zeroLength`` springs
about x and z to a fixed ground node, pallets as nodal masses (half on the front and half on
the rear beam node, in x, y and z). The beam-to-upright ties and base springs are derived here
from the geometry (coincident nodes, y = 0) and the spec's stiffnesses, not from seisrack's DOF
map. OpenSees 3.7's ElasticBeam3d consistent mass gives the twist a rotary inertia ρ J L / 3,
so the sections here set ``Ip = J`` to model the same inertia.
"""

from __future__ import annotations

import importlib.util
import math

import numpy as np
import pytest

from seisrack.fe.assembly import assemble_sparse
from seisrack.fe.mesh import FrameMesh
from seisrack.fe.modal import modal_analysis, modal_from_matrices
from seisrack.model import compile_rack, rack_from_dict
from seisrack.model.bracing import _pattern_members

pytestmark = pytest.mark.skipif(importlib.util.find_spec("openseespy") is None,
                                reason="openseespy not installed (pip install '.[bench]')")

E, RHO, NU = 210e9, 7850.0, 0.3
G = E / (2 * (1 + NU))
TOL = 0.005  # 0.5 % on every period compared


def _sections(ip_equals_j: bool = True) -> dict:
    up = {"A": 488.9e-6, "I": 41.3e-8, "Iy": 25.0e-8, "J": 0.065e-8}
    bm = {"A": 605.8e-6, "I": 93.8e-8, "Iy": 22.0e-8, "J": 46.0e-8}
    if ip_equals_j:
        up["Ip"], bm["Ip"] = up["J"], bm["J"]
    return {"upright": up, "beam": bm, "brace": {"A": 120e-6}, "spine": {"A": 200e-6}}


def _rack(pattern="Z", *, levels=(2.0,), bays=(1.8, 1.8), base_cross=None, spine=False,
          joint=160e3, base=160e3, ip_equals_j=True, rows=1) -> dict:
    pallets = [{"mass": 400.0 - 100.0 * (r - 1), "bay": b, "level": lev, "position": x,
                "mu_static": 0.6, "mu_dynamic": 0.6, "depth": 1.2, "overhang": 0.05, "row": r}
               for r in range(1, rows + 1)
               for lev in range(1, len(levels) + 1) for b in range(1, len(bays) + 1)
               for x in (0.45, 1.35)]
    d = {"material": {"E": E, "density": RHO, "poisson": NU},
         "sections": _sections(ip_equals_j),
         "geometry": {"bays": list(bays), "levels": list(levels), "beam_section": "beam",
                      "upright_section": "upright", "subdivisions": 4, "depth": 1.1},
         "connections": {"beam_to_upright": joint, "base": base},
         "bracing": {"pattern": pattern, "panel": 0.5, "horizontal_section": "brace",
                     "diagonal_section": "brace"},
         "pallets": pallets}
    if base_cross is not None:
        d["connections"]["base_cross"] = base_cross
    if rows == 2:  # back to back: spacers 0.3 m long at 0.7 and 2.0 m
        d["sections"]["spacer"] = {"A": 304e-6}
        d["geometry"].update(rows=2, row_spacer={"length": 0.3, "section": "spacer",
                                                 "heights": [0.7, 2.0]})
    if spine:
        d["bracing"].update(spine=True, spine_section="spine", spine_bays=[1])
    return d


def _spring(ops, tag: int, k: float) -> None:
    ops.uniaxialMaterial("Elastic", tag, k)


def _ops_periods(mesh: FrameMesh, n: int, *, k_joint: float, k_base: float, k_cross: float,
                 lumped: dict[int, float]) -> np.ndarray:
    """First ``n`` periods [s] of the peer model (see the module docstring)."""
    import openseespy.opensees as ops

    ops.wipe()
    ops.model("basic", "-ndm", 3, "-ndf", 6)
    X = mesh.nodes
    for i, x in enumerate(X):
        ops.node(i + 1, *map(float, x))
    ops.geomTransf("Linear", 1, 0.0, 0.0, 1.0)
    mats = {}

    def mat(k: float) -> int:
        if k not in mats:
            mats[k] = len(mats) + 10
            _spring(ops, mats[k], k)
        return mats[k]

    ground = len(X) + 1
    first_at: dict[tuple, int] = {}
    zl = 10_000
    for i, x in enumerate(X):
        key = tuple(np.round(x, 9))
        if x[1] == 0.0:  # a base node
            fixed_rot = [int(math.isinf(k_cross)), int(math.isinf(k_base))]
            ops.fix(i + 1, 1, 1, 1, fixed_rot[0], 1, fixed_rot[1])
            springs = [(k, d) for k, d in ((k_cross, 4), (k_base, 6)) if 0 < k < math.inf]
            if springs:
                ops.node(ground, *map(float, x))
                ops.fix(ground, 1, 1, 1, 1, 1, 1)
                ops.element("zeroLength", zl, ground, i + 1,
                            "-mat", *[mat(k) for k, _ in springs],
                            "-dir", *[d for _, d in springs])
                ground += 1
                zl += 1
            continue
        if key in first_at:  # a beam end at its upright's node
            master = first_at[key]
            if math.isinf(k_joint):
                ops.equalDOF(master, i + 1, 1, 2, 3, 4, 5, 6)
            else:
                ops.equalDOF(master, i + 1, 1, 2, 3, 4, 5)
                if k_joint > 0:
                    ops.element("zeroLength", zl, master, i + 1, "-mat", mat(k_joint),
                                "-dir", 6)
                    zl += 1
        else:
            first_at[key] = i + 1
    for e, (a, b) in enumerate(mesh.elements):
        ops.element("elasticBeamColumn", e + 1, int(a) + 1, int(b) + 1, mesh.A[e], E, G,
                    mesh.J[e], mesh.Iy[e], mesh.Iz[e], 1, "-mass", RHO * mesh.A[e], "-cMass")
    ops.uniaxialMaterial("Elastic", 1, E)
    for t, (a, b) in enumerate(mesh.trusses):
        ops.element("Truss", 5000 + t, int(a) + 1, int(b) + 1, mesh.truss_A[t], 1,
                    "-rho", RHO * mesh.truss_A[t], "-cMass", 1)
    for node, m in lumped.items():
        ops.mass(node + 1, m, m, m, 0.0, 0.0, 0.0)
    ops.constraints("Transformation")
    ops.numberer("RCM")
    ops.system("FullGeneral")
    lam = np.array(ops.eigen("-fullGenLapack", n))
    ops.wipe()
    return 2 * np.pi / np.sqrt(lam)


def _pallet_masses(model) -> dict[int, float]:
    out: dict[int, float] = {}
    for nodes, m in zip(model.pallet_node, model.pallet_mass, strict=True):
        for node in nodes:
            out[int(node)] = out.get(int(node), 0.0) + 0.5 * m
    return out


CASES = {
    "paper_Z": {},
    "two_levels_K_spine": {"pattern": "K", "levels": (1.5, 1.5), "spine": True,
                           "base_cross": 40e3},
    "X_pinned_cross_rigid_joints": {"pattern": "X", "base_cross": "pinned", "joint": "rigid"},
    # seisrack's default twist inertia (Ip = Iy + Iz) against OpenSees' (ρ J L / 3):
    # the member twist inertia barely matters for the rack's modes (measured 5e-5)
    "paper_Z_default_Ip": {"ip_equals_j": False},
    # back-to-back rows (issue 21): the spacers are bars between the rows' inner uprights, the
    # second row carries lighter pallets (300 kg) so the rows are not twins
    "two_rows": {"rows": 2, "spine": True},
}


@pytest.mark.parametrize("case", list(CASES))
def test_rack_periods_match_opensees(case):
    d = _rack(**CASES[case])
    spec = rack_from_dict(d)
    model = compile_rack(spec)
    n = 10
    res = modal_analysis(model, n)
    c = spec.connections
    ref = _ops_periods(model.mesh, n, k_joint=c.beam_to_upright, k_base=c.base,
                       k_cross=c.base_cross_k, lumped=_pallet_masses(model))
    err = np.abs(res.periods / ref - 1.0)
    print(case, "\n".join(f"mode {k + 1}: {res.periods[k]:.6f} s vs OpenSees {ref[k]:.6f} s "
                          f"({res.direction[k]}), rel. diff {err[k]:.2e}" for k in range(n)))
    assert np.all(err < TOL), err
    # the comparison includes the first cross-aisle and the first torsional mode
    assert "cross-aisle" in res.direction and "torsional" in res.direction


@pytest.mark.parametrize("pattern", ["Z", "D", "K", "X"])
def test_braced_upright_frame_alone_matches_opensees(pattern):
    """One upright frame (two 3 m uprights 1.1 m apart, bracing every 0.6 m), a 300 kg mass
    at each upright top, semi-rigid bases: its periods (cross-aisle sway, out-of-plane and
    twist) against OpenSees."""
    depth, top, n_sub = 1.1, 3.0, 10
    panel = tuple(np.round(np.arange(0.0, top + 1e-9, 0.6), 9))
    members = _pattern_members(pattern, panel)
    ys = sorted(set(np.round(np.linspace(0, top, n_sub + 1), 9))
                | {round(m[1], 9) for m in members} | {round(m[3], 9) for m in members})
    nodes, dofs, el, n_dof = [], [], [], 0
    at = {}
    for side, z in enumerate((0.0, depth)):
        for k, y in enumerate(ys):
            at[(side, y)] = len(nodes)
            nodes.append((0.0, y, z))
            if k == 0:
                dofs.append([-1, -1, -1, n_dof, -1, n_dof + 1])
                n_dof += 2
            else:
                dofs.append(list(range(n_dof, n_dof + 6)))
                n_dof += 6
                el.append((len(nodes) - 2, len(nodes) - 1))
    tr = [(at[(a, round(ya, 9))], at[(b, round(yb, 9))]) for a, ya, b, yb in members]
    sec = _sections()
    up, br = sec["upright"], sec["brace"]
    ne, nt = len(el), len(tr)
    k_base = 160e3
    base_rot = [dofs[at[(s, 0.0)]][c] for s in (0, 1) for c in (3, 5)]
    mesh = FrameMesh(nodes=np.array(nodes), node_dofs=np.array(dofs), elements=np.array(el),
                  E=np.full(ne, E), G=np.full(ne, G), A=np.full(ne, up["A"]),
                  Iy=np.full(ne, up["Iy"]), I=np.full(ne, up["I"]), J=np.full(ne, up["J"]),
                  Ip=np.full(ne, up["J"]), density=np.full(ne, RHO),
                  vecxz=np.tile([0.0, 0.0, 1.0], (ne, 1)), trusses=np.array(tr),
                  truss_E=np.full(nt, E), truss_A=np.full(nt, br["A"]),
                  truss_density=np.full(nt, RHO),
                  springs=np.array([[d, -1] for d in base_rot]),
                  spring_k=np.full(4, k_base), n_dof=n_dof)
    K, M = assemble_sparse(mesh)
    tops = [at[(s, ys[-1])] for s in (0, 1)]
    Mt = M.tolil()
    for node in tops:
        for c in range(3):
            Mt[dofs[node][c], dofs[node][c]] += 300.0
    n = 8
    r = np.zeros(n_dof)
    res = modal_from_matrices(K, Mt.tocsr(), r + 1.0, r, n, method="dense")
    ref = _ops_periods(mesh, n, k_joint=math.inf, k_base=k_base, k_cross=k_base,
                       lumped={node: 300.0 for node in tops})
    err = np.abs(res.periods / ref - 1.0)
    print(pattern, res.periods, ref, err)
    assert np.all(err < TOL), err
