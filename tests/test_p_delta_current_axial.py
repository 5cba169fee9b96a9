"""P-Δ with the current axial forces (``[second_order] axial = "current"``, issue 21: P-Δ on 3D
racks as OpenSees' ``geomTransf PDelta`` computes it).

References:
- the operators against :mod:`seisrack.fe.geometric`'s own assembly: the members' and bars'
  unit geometric stiffness written by its eigenpairs rebuilds ``geometric_stiffness(mesh, N,
  form, N_bar)`` for any axial forces, and the axial operator gives ``axial_forces(mesh, u)``;
- an independent full-DOF integrator written here: average-acceleration Newmark on every DOF
  of the 3D paper rack with the internal force K_E u + K_G(N(u_g + u)) (u_g + u) − K_G(N_g) u_g,
  where N(·) is :func:`seisrack.fe.geometric.axial_forces` of the total displacement and K_G
  is assembled anew at every iteration by :func:`seisrack.fe.geometric.geometric_stiffness`
  (Newton with that tangent to 1e-12), pallets rigid as masses on their supports. The engine
  (planar kernel, every mode of the rack, the fixed point of ``_planar_axial.py``) must give
  the same response, and the same change from the constant-axial-force run, to round-off of
  the iterations;
- the energy balance input = kinetic + strain + damping + friction + the P-Δ work (its own
  term, the force not being a gradient) closes to 1e-9;
- OpenSeesPy with ``geomTransf PDelta`` and ``corotTruss`` bars: the slow comparison in
  ``tests/test_opensees_hinges_3d.py`` (case "current axial").
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as sla

from seisrack.analysis import run_rack
from seisrack.analysis.hinges import rack_hinges
from seisrack.dynamics import _quasi_static, simulate
from seisrack.dynamics.sliders import PlanarSliders
from seisrack.errors import InputError
from seisrack.fe import geometric
from seisrack.fe.assembly import assemble_sparse
from seisrack.fe.stability import symmetric_lu
from seisrack.model import compile_rack, load_rack, rack_from_dict, with_friction
from seisrack.motion import Record, load_builtin_record
from seisrack.motion.components import combine

ROOT = Path(__file__).resolve().parents[1]
PAPER_3D = ROOT / "examples" / "paper_rack_3d.toml"
DT = 0.005
SECONDS = 3.0


def _spec(form: str, axial: str):
    spec = with_friction(load_rack(PAPER_3D), 1e6)
    return replace(spec, second_order=replace(spec.second_order, p_delta=True, form=form,
                                              axial=axial))


@pytest.mark.parametrize("form", ["p_delta_only", "consistent"])
def test_factors_rebuild_the_geometric_stiffness(form) -> None:
    mesh = compile_rack(_spec(form, "gravity")).mesh
    rng = np.random.default_rng(3)
    n = rng.standard_normal(mesh.n_el + mesh.trusses.shape[0]) * 1e4
    rows, owner, scale = geometric.unit_geometric_factors(mesh, form)
    rebuilt = rows.T @ sp.diags(n[owner] * scale) @ rows
    direct = geometric.geometric_stiffness(mesh, n[:mesh.n_el], form, n[mesh.n_el:])
    assert abs(rebuilt - direct).max() <= 1e-12 * abs(direct).max()
    # rank per member: one per bending plane (chord), three (consistent: all but the rigid
    # translation of the plane); bars: two
    per = np.bincount(owner, minlength=n.size)
    assert set(per[:mesh.n_el]) == {2 if form == "p_delta_only" else 6}
    assert set(per[mesh.n_el:]) == {2}
    u = rng.standard_normal(mesh.n_dof)
    N, N_bar = geometric.axial_forces(mesh, u)
    np.testing.assert_allclose(geometric.axial_operator(mesh) @ u, np.concatenate([N, N_bar]),
                               rtol=0, atol=1e-12 * np.abs(N).max())


def _record() -> np.ndarray:
    rec = load_builtin_record("elcentro_1940_ns")
    n = int(round(SECONDS / rec.dt)) + 1
    shift = int(round(2.0 / rec.dt))
    k = int(round(rec.dt / DT))
    t_rec = np.arange(n)
    t = np.arange((n - 1) * k + 1) / k
    ax = np.interp(t, t_rec, 3.0 * rec.accel[:n])
    az = np.interp(t, t_rec, 3.0 * rec.accel[shift:shift + n])
    return np.column_stack([ax, az])


def _split_pallets(model) -> tuple[PlanarSliders, sp.csr_matrix]:
    """Rigid pallets as masses on their supports: one never-sliding slider per support (the
    engine), and the same masses on the structure's DOFs (the reference)."""
    pd = model.pallet_dofs  # (m, k, 2)
    m, k = pd.shape[:2]
    share = np.repeat(model.pallet_mass / k, k)
    sl = PlanarSliders(pd[:, :, 0].reshape(-1, 1), pd[:, :, 1].reshape(-1, 1), share, 1e6, 1e6)
    dofs = np.concatenate([pd[:, :, 0].ravel(), pd[:, :, 1].ravel()])
    extra = sp.csr_matrix((np.tile(share, 2), (dofs, dofs)), shape=(model.n_dof,) * 2)
    return sl, extra


def _reference(model, ag: np.ndarray, form: str, current: bool) -> np.ndarray:
    """Full-DOF Newmark (β = 1/4, γ = 1/2) with the P-Δ of the total axial forces; returns
    the displacement history (n_t, n_dof) from the static state."""
    mesh = model.mesh
    K_E, _ = assemble_sparse(mesh)
    F_g = -model.g * (model.M_sparse @ model.r_y)
    u_g = symmetric_lu(K_E).solve(F_g)
    N_g, Nb_g = geometric.axial_forces(mesh, u_g)
    K_G0 = geometric.geometric_stiffness(mesh, N_g, form, Nb_g)
    _, extra = _split_pallets(model)
    M = (model.M_sparse + extra).tocsc()
    C = model.C_sparse.tocsc()

    def internal(u):
        if not current:
            return K_E @ u + K_G0 @ u, K_E + K_G0
        N, Nb = geometric.axial_forces(mesh, u_g + u)
        KG = geometric.geometric_stiffness(mesh, N, form, Nb)
        return K_E @ u + KG @ (u_g + u) - K_G0 @ u_g, K_E + KG

    n = model.n_dof
    infl = np.column_stack(model.influence)
    h = DT
    u, v = np.zeros(n), np.zeros(n)
    p = -(M @ (infl @ ag[0]))
    a = sla.spsolve(M, p - C @ v - internal(u)[0])
    out = np.zeros((ag.shape[0], n))
    for i in range(1, ag.shape[0]):
        p = -(M @ (infl @ ag[i]))
        u1 = u + h * v + 0.25 * h * h * a  # predictor; Newton on u1
        for _ in range(50):
            a1 = 4.0 / h**2 * (u1 - u) - 4.0 / h * v - a
            v1 = v + 0.5 * h * (a + a1)
            f, kt = internal(u1)
            r = p - M @ a1 - C @ v1 - f
            du = sla.spsolve((4.0 / h**2 * M + 2.0 / h * C + kt).tocsc(), r)
            u1 = u1 + du
            if np.abs(du).max() <= 1e-13 * max(np.abs(u1).max(), 1e-30):
                break
        a1 = 4.0 / h**2 * (u1 - u) - 4.0 / h * v - a
        v = v + 0.5 * h * (a + a1)
        u, a = u1, a1
        out[i] = u
    return out


def _engine(model, ag: np.ndarray):
    sl, _ = _split_pallets(model)
    return simulate(model.M_sparse, model.C_sparse, model.K_sparse, sl, dt=DT, ground_accel=ag,
                    influence=np.column_stack(model.influence), g=model.g,
                    hinges=rack_hinges(model), basis="full")


@pytest.mark.parametrize("form", ["p_delta_only", "consistent"])
def test_engine_matches_a_full_dof_integrator_with_current_axial_forces(form,
                                                                         monkeypatch) -> None:
    # parity with the trapezoidal rule on every DOF: the gravity run's stiff directions are
    # integrated too, not held quasi-statically (docs/theory/planar_friction.md §9; the
    # current-axial run couples its directions and integrates them all anyway)
    monkeypatch.setattr(_quasi_static, "QUASI_STATIC_OMEGA_DT", np.inf)
    ag = _record()
    cur = compile_rack(_spec(form, "current"))
    grav = compile_rack(_spec(form, "gravity"))
    assert cur.axial_p_delta is not None and grav.axial_p_delta is None
    h_cur, h_grav = _engine(cur, ag), _engine(grav, ag)
    u_cur = h_cur.q @ h_cur.phi.T
    u_grav = h_grav.q @ h_grav.phi.T
    ref_cur = _reference(cur, ag, form, current=True)
    ref_grav = _reference(grav, ag, form, current=False)
    peak = np.abs(ref_cur).max()
    change = np.abs(ref_cur - ref_grav).max()
    # the current axial forces change the response (the uprights' forces swing with the
    # cross-aisle overturning): well above the agreement asked below
    assert change > 1e-3 * peak
    assert np.abs(u_grav - ref_grav).max() <= 1e-7 * peak
    assert np.abs(u_cur - ref_cur).max() <= 1e-7 * peak
    np.testing.assert_allclose(u_cur - u_grav, ref_cur - ref_grav, rtol=0, atol=1e-4 * change)
    # the P-Δ force's work is its own energy term; the balance closes
    assert "p_delta" in h_cur.energy and "p_delta" not in h_grav.energy
    assert h_cur.energy_error() < 1e-9
    assert np.abs(h_cur.energy["p_delta"]).max() > 0.0


def test_rack_run_reports_the_p_delta_work_and_reduced_basis_agrees() -> None:
    """Through run_rack (the default reduced basis, pallets on friction): the run finishes,
    its energy closes with the P-Δ term, and the response is within 1 % of the full basis."""
    spec = replace(with_friction(load_rack(PAPER_3D), 0.3), second_order=replace(
        load_rack(PAPER_3D).second_order, p_delta=True, form="p_delta_only", axial="current"))
    model = compile_rack(spec)
    ag = _record()
    mot = combine(Record(ag[:, 0], DT, "x"), Record(ag[:, 1], DT, "z"))
    red = run_rack(model, mot, dt=DT)
    full = run_rack(model, mot, dt=DT, basis="full")
    # the sliding's event location leaves ~1e-7 (measured 1.07e-7; 1.06e-7 with the gravity
    # axial forces): the P-Δ work adds nothing to it
    assert red.history.energy_error() < 1e-6
    assert "p_delta" in red.history.energy
    pk = np.abs(full.beam_displacement).max()
    assert np.abs(red.beam_displacement - full.beam_displacement).max() < 0.01 * pk


def test_bad_input_names_the_field() -> None:
    import tomllib

    base = tomllib.loads(PAPER_3D.read_text())
    base["second_order"] = {"p_delta": False, "axial": "current"}
    with pytest.raises(InputError, match="second_order.axial"):
        rack_from_dict(base)
    base["second_order"] = {"p_delta": True, "axial": "now"}
    with pytest.raises(InputError, match="second_order.axial"):
        rack_from_dict(base)
    two_d = tomllib.loads((ROOT / "examples" / "paper_rack.toml").read_text())
    two_d["second_order"] = {"p_delta": True, "axial": "current"}
    with pytest.raises(InputError, match="not built for 2D"):
        compile_rack(rack_from_dict(two_d))
    model = compile_rack(_spec("p_delta_only", "current"))
    rec = Record(np.zeros(50), DT, "zero")
    with pytest.raises(InputError, match="not built in the local engine"):
        run_rack(model, rec, engine="local")


def test_pure_python_twin_agrees_with_numba() -> None:
    model = compile_rack(_spec("p_delta_only", "current"))
    ag = _record()[:101]
    mot = combine(Record(ag[:, 0], DT, "x"), Record(ag[:, 1], DT, "z"))
    a = run_rack(model, mot, dt=DT, backend="python")
    b = run_rack(model, mot, dt=DT, backend="numba")
    assert (a.history.backend, b.history.backend) == ("python", "numba")
    peak = np.abs(b.beam_displacement).max()
    assert np.abs(a.beam_displacement - b.beam_displacement).max() <= 1e-10 * peak


@pytest.mark.parametrize("form", ["p_delta_only", "consistent"])
def test_model_operators_give_the_geometric_force_of_the_axial_change(form) -> None:
    """The compiled model's AxialPDelta: f(u) = (K_G(N(u_g + u)) - K_G(N(u_g))) (u_g + u),
    both K_G assembled directly by fe.geometric from the axial forces of the total state."""
    model = compile_rack(_spec(form, "current"))
    mesh = model.mesh
    K_E, _ = assemble_sparse(mesh)
    u_g = symmetric_lu(K_E).solve(-model.g * (model.M_sparse @ model.r_y))
    u = np.random.default_rng(5).standard_normal(mesh.n_dof) * 1e-3
    N1, Nb1 = geometric.axial_forces(mesh, u_g + u)
    N0, Nb0 = geometric.axial_forces(mesh, u_g)
    dK = (geometric.geometric_stiffness(mesh, N1, form, Nb1)
          - geometric.geometric_stiffness(mesh, N0, form, Nb0))
    ref = dK @ (u_g + u)
    got = model.axial_p_delta.force(u)
    assert np.abs(ref).max() > 0.0
    np.testing.assert_allclose(got, ref, rtol=0, atol=1e-9 * np.abs(ref).max())
